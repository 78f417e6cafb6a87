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

use crate::geometry::{Aabb, Ray, SurfacePoint};
use crate::light::{Light, LightHit, LightSampleContext, LightSampler};
use crate::material::Material;

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
            mis_with_bsdf: false,
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
    pub materials: Vec<Material>,
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
