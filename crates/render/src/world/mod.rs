//! The render-ready world: geometry flattened into render-space arrays behind one BVH,
//! materials and lights, built once from a [`SceneDesc`](radiant_scene::SceneDesc).
//!
//! Queries are the two an accelerator provides — closest hit and any hit — and the
//! lazy expansion of a hit into a [`SurfaceHit`] with positions, normals and uvs.

mod build;
mod normals;
mod shapes;

use glam::{Vec2, Vec3};

pub use build::{BuildError, image_emission_factor, read_emission_image};
pub use normals::ShadingNormal;
pub use shapes::ShapeSet;

use crate::camera::RaySpread;
use crate::geometry::{Aabb, Ray, SurfacePoint};
use crate::light::{Light, LightHit, LightSampleContext, LightSampler};
use crate::material::Material;
use crate::texture::{TextureEvalContext, TextureSet};
use radiant_math::Frame;
use radiant_math::color::Rgb;
use radiant_math::hash::{hash_u64s, u32_to_unit_f32};
use radiant_scene::{FloatParam, TexturedMaterialDesc, TexturedParam};

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
    /// ∂p/∂u and ∂p/∂v in render space (pbrt's convention per shape); ∂p/∂u is the
    /// first tangent axis of anisotropic BSDFs. Not normalised; zero where the shape
    /// does not provide them (then uv-mapped textures are point-sampled).
    pub dpdu: Vec3,
    pub dpdv: Vec3,
    /// How `p` moves from one pixel to the next (x, y): the footprint that texture
    /// filters use. Zero unless [`World::intersect_with_footprint`] set it.
    pub dpdx: Vec3,
    pub dpdy: Vec3,
    pub material: u32,
    /// Index of the area light of this primitive, or [`NO_LIGHT`].
    pub light: u32,
    /// The shape's `alpha` cut-out, `None` when opaque.
    pub alpha: Option<FloatParam>,
}

impl SurfaceHit {
    /// The hit as a place rays start from: position, error bound, geometric normal.
    #[inline(always)]
    pub fn surface_point(&self) -> SurfacePoint {
        SurfacePoint::new(self.p, self.p_error, self.ng)
    }

    /// Origin for a ray leaving the surface towards `w`, moved off the surface past the
    /// hit point's error bound.
    #[inline(always)]
    pub fn spawn_origin(&self, w: Vec3) -> Vec3 {
        self.surface_point().spawn_origin(w)
    }

    #[inline(always)]
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

/// One entry of the world's material table (indexed by [`SurfaceHit::material`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialEntry {
    Bsdf(Material),
    /// pbrt-v4's `mix`: two other entries; at each hit the second with probability
    /// `amount`, chosen by a hash of the hit point and the outgoing direction. With
    /// `amount_texture` the probability is that float texture at the hit, and `amount`
    /// its mean over (u, v) (for uses without a hit: radiosity, weights).
    Mix {
        materials: [u32; 2],
        amount: f32,
        amount_texture: Option<u32>,
    },
}

/// Bound on the nesting of mixes, so that a cyclic table cannot loop (the builder
/// refuses cycles; this is the backstop).
pub(crate) const MAX_MIX_DEPTH: usize = 64;

/// Bound on the cut-out surfaces one ray passes, so that stacks of coplanar cut-outs
/// cannot loop.
const MAX_CUT_OUT_CROSSINGS: usize = 256;

/// Everything an integrator traces against.
pub struct World {
    pub(crate) geometry: ShapeSet,
    /// Object prototypes for instancing (in instance space).
    pub(crate) prototypes: Vec<ShapeSet>,
    /// Resolve an entry at a hit with [`World::material_at`]. A textured material's
    /// entry holds its value at the textures' (u, v) averages (what queries about the
    /// kind of surface see).
    pub materials: Vec<MaterialEntry>,
    /// The textured description of each material id that has one.
    pub(crate) textured: Vec<Option<TexturedMaterialDesc>>,
    pub textures: TextureSet,
    /// Bump or normal map by material id (empty when none has one); applied to every
    /// hit [`World::intersect`] returns.
    pub(crate) shading_normals: Vec<Option<ShadingNormal>>,
    /// Some shape has an `alpha` cut-out: rays then test each hit's alpha.
    pub(crate) cut_outs: bool,
    /// Some material has textures or a bump or normal map: hits then need their
    /// footprint (when the camera gives one).
    pub(crate) footprints_used: bool,
    /// The camera's pixel footprint along paths, for texture filtering.
    pub ray_spread: RaySpread,
    pub lights: Vec<Light>,
    /// Chooses among `lights` for next-event estimation and photon emission.
    pub light_sampler: LightSampler,
    pub bounds: Aabb,
}

impl World {
    /// Closest hit in `(0, t_max)`.
    /// The shading normal is that of the hit's material (bump or normal map applied).
    /// Hits that an alpha cut-out lets through are skipped.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        let hit = self.intersect_shape(ray, t_max)?;
        if !self.shading_normals.is_empty() {
            return Some(self.with_perturbed_normal(hit, -ray.d.normalize()));
        }
        Some(hit)
    }

    /// [`intersect`](Self::intersect) for a ray of a camera path that has travelled
    /// `travelled` before this segment: the hit also gets its pixel footprint, which
    /// texture filters and the bump map's finite-difference step use.
    #[inline(always)]
    pub fn intersect_with_footprint(
        &self,
        ray: &Ray,
        t_max: f32,
        travelled: f32,
    ) -> Option<SurfaceHit> {
        let hit = self.intersect_shape(ray, t_max)?;
        // Without textures or bump maps the hit goes straight back: with the footprint's
        // `&mut` on the same path, the hit stayed in memory and was copied out in wider
        // words than it was written (a store-forwarding stall, 2-3 % of a sample).
        if !self.footprints_used {
            return Some(hit);
        }
        let mut hit = hit;
        self.add_footprint(&mut hit, ray.d, travelled);
        if !self.shading_normals.is_empty() {
            return Some(self.with_perturbed_normal(hit, -ray.d.normalize()));
        }
        Some(hit)
    }

    /// The closest hit as the shape reports it (alpha cut-outs skipped).
    #[inline(always)]
    fn intersect_shape(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        crate::stats::add(crate::stats::Counter::ClosestHitTests, 1);
        let hit = if self.cut_outs {
            self.intersect_through_cut_outs(ray, t_max)?
        } else {
            self.geometry.intersect(ray, t_max, &self.prototypes)?
        };
        Some(hit)
    }

    /// `hit` with `ns` tilted by the bump or normal map of the material that shades it
    /// seen from `wo_world` (for a mix, the chosen material's). Taken and returned by
    /// value: a `&mut` to the caller's hit would keep that hit in memory on every path,
    /// and reading back its fields as wider words than they were written stalls
    /// store-to-load forwarding.
    #[inline(never)]
    fn with_perturbed_normal(&self, mut hit: SurfaceHit, wo_world: Vec3) -> SurfaceHit {
        let index = self.resolve_index(hit.material, hit.p, wo_world, Some(&hit));
        if let Some(Some(normal)) = self.shading_normals.get(index as usize) {
            normals::perturb(&mut hit, normal, &self.textures);
        }
        hit
    }

    /// True when anything blocks the ray in `(0, t_max)` (alpha cut-outs let it
    /// through where [`World::intersect`] would).
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        crate::stats::add(crate::stats::Counter::ShadowTests, 1);
        if self.cut_outs {
            self.intersect_through_cut_outs(ray, t_max).is_some()
        } else {
            self.geometry.occluded(ray, t_max, &self.prototypes)
        }
    }

    /// The closest hit whose alpha keeps it: after a hit the ray goes on from just past
    /// it (its error bound), `t` of the result measured along the original ray.
    fn intersect_through_cut_outs(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        let mut r = *ray;
        let mut t_base = 0.0f32;
        for _ in 0..MAX_CUT_OUT_CROSSINGS {
            let mut hit = self
                .geometry
                .intersect(&r, t_max - t_base, &self.prototypes)?;
            if !self.cut_out(&hit, ray.d) {
                hit.t += t_base;
                return Some(hit);
            }
            let o = hit.spawn_origin(ray.d);
            t_base += (o - r.o).dot(ray.d) / ray.d.length_squared();
            if t_base >= t_max || t_base.is_nan() {
                return None;
            }
            r = Ray::new(o, ray.d);
        }
        // So many layers of fractional alpha pass (almost) nothing: opaque.
        self.geometry
            .intersect(&r, t_max - t_base, &self.prototypes)
    }

    /// Whether the alpha of `hit` lets a ray of direction `d` through: always where
    /// alpha ≤ 0, never where it is ≥ 1, and in between when a hash of the point and
    /// direction, uniform in [0, 1), is at least alpha (so with probability 1 − alpha,
    /// the same for every ray that meets the same point from the same direction).
    pub fn cut_out(&self, hit: &SurfaceHit, d: Vec3) -> bool {
        let Some(alpha) = hit.alpha else {
            return false;
        };
        let a = self
            .textures
            .float(alpha, &TextureEvalContext::from_hit(hit));
        if a >= 1.0 {
            return false;
        }
        if a <= 0.0 || a.is_nan() {
            return true;
        }
        let d = d.normalize();
        let bits = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()].map(u64::from);
        let [px, py, pz] = bits(hit.p);
        let [dx, dy, dz] = bits(d);
        let h = hash_u64s(&[px, py, pz, dx, dy, dz, 0xa1fa]);
        u32_to_unit_f32((h >> 32) as u32) >= a
    }

    /// True when the segment between two points is free: each end is moved off its own
    /// surface (by its error bound, towards the other) and the far end is not counted.
    #[inline]
    pub fn visible(&self, from: &SurfacePoint, to: &SurfacePoint) -> bool {
        let (ray, t_max) = from.spawn_ray_to(to);
        !self.occluded(&ray, t_max)
    }

    /// The material shading `hit` seen from the unit direction `wo_world`: the
    /// table entry itself, or for a mix one of its materials (nested mixes resolved in
    /// turn). Deterministic: the choice is a pure function of the point, the direction
    /// and the entries, as in pbrt-v4's `MixMaterial::ChooseMaterial`.
    /// A textured material's textures are evaluated at the hit with its footprint.
    pub fn material_at(&self, hit: &SurfaceHit, wo_world: Vec3) -> Material {
        let index = self.resolve_index(hit.material, hit.p, wo_world, Some(hit));
        match self.textured.get(index as usize) {
            Some(Some(desc)) => self
                .textures
                .material(desc, &TextureEvalContext::from_hit(hit)),
            _ => self.entry_material(index),
        }
    }

    /// [`material_at`](Self::material_at) for an entry, point and direction, without
    /// textures (a textured material at its textures' averages).
    pub fn resolve_material(&self, index: u32, p: Vec3, wo_world: Vec3) -> Material {
        self.entry_material(self.resolve_index(index, p, wo_world, None))
    }

    /// The entry a mix chain starting at `index` chooses at `p` seen from `wo_world`;
    /// textured amounts are evaluated at `hit`, or at their mean without one.
    fn resolve_index(&self, index: u32, p: Vec3, wo_world: Vec3, hit: Option<&SurfaceHit>) -> u32 {
        match self.materials[index as usize] {
            MaterialEntry::Bsdf(_) => index,
            MaterialEntry::Mix { .. } => self.resolve_mix(index, p, wo_world, hit),
        }
    }

    /// [`resolve_index`](Self::resolve_index) for a mix. Apart and not inlined: the
    /// hash of (p, wo) does not change along the chain, and inlined the compiler
    /// hoists it ahead of the entry test, hashing at every hit of a plain material.
    #[inline(never)]
    fn resolve_mix(
        &self,
        mut index: u32,
        p: Vec3,
        wo_world: Vec3,
        hit: Option<&SurfaceHit>,
    ) -> u32 {
        for _ in 0..=MAX_MIX_DEPTH {
            match self.materials[index as usize] {
                MaterialEntry::Bsdf(_) => return index,
                MaterialEntry::Mix {
                    materials,
                    amount,
                    amount_texture,
                } => {
                    let amount = match (amount_texture, hit) {
                        (Some(id), Some(hit)) => self.textures.float(
                            TexturedParam::Texture(id),
                            &TextureEvalContext::from_hit(hit),
                        ),
                        _ => amount,
                    };
                    index = choose_mixed(materials, amount, p, wo_world);
                }
            }
        }
        unreachable!("the world builder refuses cyclic mixes")
    }

    fn entry_material(&self, index: u32) -> Material {
        match self.materials[index as usize] {
            MaterialEntry::Bsdf(m) => m,
            MaterialEntry::Mix { .. } => unreachable!("resolved above"),
        }
    }

    /// Every material an entry can resolve to, with its probability (mixes expanded).
    pub fn material_weights(&self, index: u32) -> Vec<(Material, f32)> {
        let mut out: Vec<(Material, f32)> = Vec::new();
        // Level by level, entries reached along several paths merged, so that shared
        // sub-mixes cost once per level.
        let mut level = vec![(index, 1.0f32)];
        for _ in 0..=MAX_MIX_DEPTH {
            let mut next: Vec<(u32, f32)> = Vec::new();
            for (i, w) in level {
                match self.materials[i as usize] {
                    MaterialEntry::Bsdf(m) => out.push((m, w)),
                    MaterialEntry::Mix {
                        materials, amount, ..
                    } => {
                        let a = amount.clamp(0.0, 1.0);
                        for (n, wn) in [(materials[0], w * (1.0 - a)), (materials[1], w * a)] {
                            match next.iter_mut().find(|(j, _)| *j == n) {
                                Some((_, acc)) => *acc += wn,
                                None => next.push((n, wn)),
                            }
                        }
                    }
                }
            }
            if next.is_empty() {
                break;
            }
            level = next;
        }
        out
    }

    /// The diffuse albedo of the material at `hit` with its textures (a textured
    /// mix amount included) evaluated there, a mix's the amount-weighted mean of its
    /// materials': what radiosity gives a patch at that point.
    pub fn diffuse_albedo_at(&self, hit: &SurfaceHit) -> Rgb {
        let ctx = TextureEvalContext::from_hit(hit);
        self.entry_albedo_at(hit.material, &ctx, 0)
    }

    fn entry_albedo_at(&self, index: u32, ctx: &TextureEvalContext, depth: usize) -> Rgb {
        match self.materials[index as usize] {
            MaterialEntry::Bsdf(m) => match self.textured.get(index as usize) {
                Some(Some(desc)) => self.textures.material(desc, ctx).diffuse_albedo(),
                _ => m.diffuse_albedo(),
            },
            MaterialEntry::Mix { .. } if depth > MAX_MIX_DEPTH => Rgb::BLACK,
            MaterialEntry::Mix {
                materials,
                amount,
                amount_texture,
            } => {
                let a = amount_texture
                    .map_or(amount, |id| {
                        self.textures.float(TexturedParam::Texture(id), ctx)
                    })
                    .clamp(0.0, 1.0);
                self.entry_albedo_at(materials[0], ctx, depth + 1) * (1.0 - a)
                    + self.entry_albedo_at(materials[1], ctx, depth + 1) * a
            }
        }
    }

    /// The diffuse albedo of an entry: a mix's is the amount-weighted mean of its
    /// materials' (what radiosity and final gathering use).
    pub fn diffuse_albedo(&self, index: u32) -> Rgb {
        self.material_weights(index)
            .iter()
            .fold(Rgb::BLACK, |acc, (m, w)| acc + m.diffuse_albedo() * *w)
    }

    /// The shading frame of `material` at `hit`: about the shading normal, with its
    /// first axis along ∂p/∂u for anisotropic BSDFs (pbrt's orientation of
    /// `uroughness`). Isotropic BSDFs do not depend on the tangent, and keep the
    /// branch-free frame of the normal alone.
    #[inline(always)]
    pub fn shading_frame(hit: &SurfaceHit, material: &Material) -> Frame {
        if material.is_anisotropic() {
            Frame::from_normal_tangent(hit.ns, hit.dpdu)
        } else {
            Frame::from_normal(hit.ns)
        }
    }

    /// Sets the hit's footprint for a ray of direction `d` that had travelled
    /// `travelled` from the camera before it started. Called only where textures or
    /// bump maps use footprints (`footprints_used`), so the distance to the hit is only
    /// measured then.
    fn add_footprint(&self, hit: &mut SurfaceHit, d: Vec3, travelled: f32) {
        if self.ray_spread != RaySpread::NONE {
            let distance = travelled + hit.t * d.length();
            (hit.dpdx, hit.dpdy) = self.ray_spread.differentials(d, distance, hit.ng);
        }
    }

    /// Bounding spheres (centre, radius) of the specular geometry (mirrors, conductors,
    /// glass, rough glass): one per mesh, quadric or instance that has any.
    pub fn specular_bounds(&self) -> Vec<(Vec3, f32)> {
        let pick = |m: u32| {
            self.material_weights(m)
                .iter()
                .any(|(m, w)| *w > 0.0 && m.passes_photon_paths() && *m != Material::Interface)
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

/// pbrt-v4's choice of a mix's material: u, a hash of the point, the direction and the
/// two entries, in [0, 1); the second material when u < amount, so that `amount` is the
/// probability of the second.
fn choose_mixed(materials: [u32; 2], amount: f32, p: Vec3, wo: Vec3) -> u32 {
    if amount <= 0.0 {
        return materials[0];
    }
    if amount >= 1.0 {
        return materials[1];
    }
    let bits = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()].map(u64::from);
    let [px, py, pz] = bits(p);
    let [wx, wy, wz] = bits(wo);
    let h = hash_u64s(&[
        px,
        py,
        pz,
        wx,
        wy,
        wz,
        u64::from(materials[0]),
        u64::from(materials[1]),
    ]);
    let u = u32_to_unit_f32((h >> 32) as u32);
    if u < amount {
        materials[1]
    } else {
        materials[0]
    }
}
