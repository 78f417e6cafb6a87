//! The render-ready world: geometry flattened into render-space arrays behind one BVH,
//! materials and lights, built once from a [`SceneDesc`](radiant_scene::SceneDesc).
//!
//! Queries are the two an accelerator provides — closest hit and any hit — and the
//! lazy expansion of a hit into a [`SurfaceHit`] with positions, normals and uvs.

mod build;
mod shapes;

use glam::{Vec2, Vec3};

pub use build::BuildError;
pub use shapes::ShapeSet;

use crate::camera::RaySpread;
use crate::geometry::{Aabb, Ray, SurfacePoint};
use crate::light::{Light, LightHit, LightSampleContext, LightSampler};
use crate::material::Material;
use crate::texture::{TextureEvalContext, TextureSet};
use radiant_scene::TexturedMaterialDesc;

/// No light attached (in per-primitive light indices).
pub const NO_LIGHT: u32 = u32::MAX;

/// A ray hit expanded into what shading needs.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Ray parameter of the hit.
    pub t: f32,
    pub p: Vec3,
    /// Conservative bound on the rounding error of `p`, per component: rays leaving the
    /// surface start outside this box.
    pub p_error: Vec3,
    /// Unit geometric normal, oriented as the shape's (emitting) front side.
    pub ng: Vec3,
    /// Unit shading normal, on the same side as `ng`.
    pub ns: Vec3,
    pub uv: Vec2,
    /// Partial derivatives of `p` with respect to (u, v); zero where the shape does not
    /// provide them (quadrics and bilinear patches: their textures are point-sampled).
    pub dpdu: Vec3,
    pub dpdv: Vec3,
    /// How `p` moves from one pixel to the next (x, y): the footprint that texture
    /// filters use. Zero until [`World::add_footprint`] sets it.
    pub dpdx: Vec3,
    pub dpdy: Vec3,
    pub material: u32,
    /// Index of the area light of this primitive, or [`NO_LIGHT`].
    pub light: u32,
}

impl SurfaceHit {
    /// The hit as a place rays start from: position, error bound, geometric normal.
    pub fn surface_point(&self) -> SurfacePoint {
        SurfacePoint::new(self.p, self.p_error, self.ng)
    }

    /// Origin for a ray leaving the surface towards `w`, moved off the surface past the
    /// hit point's error bound.
    pub fn spawn_origin(&self, w: Vec3) -> Vec3 {
        self.surface_point().spawn_origin(w)
    }

    pub fn spawn_ray(&self, w: Vec3) -> Ray {
        self.surface_point().spawn_ray(w)
    }

    /// This point as a receiver of light sampling.
    pub fn light_sample_context(&self) -> LightSampleContext {
        LightSampleContext {
            p: self.p,
            n: self.ng,
            ns: self.ns,
        }
    }

    /// This point as where a ray found an area light, for the light's `pdf_li`.
    pub fn light_hit(&self) -> LightHit {
        LightHit {
            p: self.p,
            n: self.ng,
            uv: self.uv,
        }
    }
}

/// Everything an integrator traces against.
pub struct World {
    pub(crate) geometry: ShapeSet,
    /// Object prototypes for instancing (in instance space).
    pub(crate) prototypes: Vec<ShapeSet>,
    /// The material of each id; for a textured one, its value at the textures' (u, v)
    /// averages (what queries about the kind of surface see).
    pub materials: Vec<Material>,
    /// The textured description of each material id that has one.
    pub(crate) textured: Vec<Option<TexturedMaterialDesc>>,
    pub textures: TextureSet,
    /// The camera's pixel footprint along paths, for texture filtering.
    pub ray_spread: RaySpread,
    pub lights: Vec<Light>,
    /// Chooses among `lights` for next-event estimation and photon emission.
    pub light_sampler: LightSampler,
    pub bounds: Aabb,
}

impl World {
    /// Closest hit in `(0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        self.geometry.intersect(ray, t_max, &self.prototypes)
    }

    /// True when anything blocks the ray in `(0, t_max)`.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.geometry.occluded(ray, t_max, &self.prototypes)
    }

    /// True when the segment between two points is free: each end is moved off its own
    /// surface (by its error bound, towards the other) and the far end is not counted.
    pub fn visible(&self, from: &SurfacePoint, to: &SurfacePoint) -> bool {
        let (ray, t_max) = from.spawn_ray_to(to);
        !self.occluded(&ray, t_max)
    }

    /// True when some material is textured: only then do integrators need footprints.
    pub fn has_textures(&self) -> bool {
        self.textured.iter().any(Option::is_some)
    }

    /// The concrete material at a hit: the table's entry, or for a textured material
    /// its textures evaluated at the hit with its footprint. `wo` (the direction
    /// towards the viewer) is for materials that depend on it; textures do not.
    pub fn material_at(&self, hit: &SurfaceHit, _wo: Vec3) -> Material {
        match self.textured.get(hit.material as usize) {
            Some(Some(desc)) => self
                .textures
                .material(desc, &TextureEvalContext::from_hit(hit)),
            _ => self.materials[hit.material as usize],
        }
    }

    /// Sets the hit's footprint for a ray of direction `d` that has travelled
    /// `distance` from the camera (only when textures need it).
    pub fn add_footprint(&self, hit: &mut SurfaceHit, d: Vec3, distance: f32) {
        if self.ray_spread != RaySpread::NONE && self.has_textures() {
            (hit.dpdx, hit.dpdy) = self.ray_spread.differentials(d, distance, hit.ng);
        }
    }

    /// Bounding spheres (centre, radius) of the specular geometry (mirrors, conductors,
    /// glass, rough glass): one per mesh, quadric or instance that has any.
    pub fn specular_bounds(&self) -> Vec<(Vec3, f32)> {
        let pick = |m: u32| {
            let m = &self.materials[m as usize];
            m.passes_photon_paths() && *m != Material::Interface
        };
        self.geometry
            .bounding_spheres_where(&self.prototypes, &pick)
    }

    /// Centre and radius of a sphere enclosing the scene (for distant and infinite lights).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        self.bounds.bounding_sphere()
    }

    /// Number of primitives (triangles, spheres, ... and instances) at the top level.
    pub fn primitive_count(&self) -> usize {
        self.geometry.len()
    }
}
