//! The camera pass of an SPPM iteration: one camera ray per pixel, followed through
//! specular chains to the first diffuse point, where a visible point is left for the
//! photons (Hachisuka & Jensen 2009: a new random visible point per iteration makes
//! the method stochastic and the pixel estimate converge to the pixel's integral, not
//! to one point's radiance). Under a narrow coat the path either follows the coat's
//! reflection or leaves the point for the light under the coat ([`coat_step`]).
//!
//! Direct light is computed here, by next-event estimation at the visible point (as
//! pbrt-v4 does; weighted against a BSDF sample where the point is glossy, see
//! [`chain_end_direct`]), together with emission seen through the specular chain;
//! photons then only carry indirect light (they are not deposited at their first hit).

use glam::Vec3;

use crate::context::RenderContext;
use crate::integrator::specular::{
    ChainVertex, CoatStep, chain_bounce, chain_end_direct, coat_step, glossy_direct,
};
use crate::material::{BsdfPart, Material, TransportMode};
use crate::world::World;
use radiant_math::color::Rgb;
use radiant_math::{Frame, INV_PI};

/// A camera path's first diffuse point this iteration.
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    pub p: Vec3,
    /// Geometric normal turned towards the camera path.
    pub n: Vec3,
    /// The BSDF's shading frame.
    pub frame: Frame,
    /// Direction to the camera, in the shading frame.
    pub wo: Vec3,
    /// Camera path throughput (camera weight, filter weight, specular chain).
    pub beta: Rgb,
    /// The material at the point (a mix already resolved).
    pub material: Material,
    /// Lambertian with the shading normal on the geometric normal's line: the BSDF is
    /// then albedo/π exactly where a photon arrives on the side of `n`, and zero
    /// elsewhere, so photons are summed first and weighted once (`weigh`).
    pub lambertian: bool,
    /// The point gathers only the light under a narrow coat, whose own reflection
    /// the camera path follows instead ([`coat_step`]).
    pub part: BsdfPart,
    /// Chooses the photons whose BSDF value is evaluated where that value is a random
    /// walk ([`Material::eval_is_estimated`]).
    pub u_evals: f32,
    pub valid: bool,
}

impl VisiblePoint {
    /// The gathered sum's contribution: for a Lambertian point the sum of photon
    /// powers times albedo/π, otherwise the sum already weighted by the BSDF.
    pub fn weigh(&self, sum: Rgb) -> Rgb {
        match self.material {
            Material::Diffuse { albedo } if self.lambertian => sum * albedo * INV_PI,
            _ => sum,
        }
    }

    /// The BSDF that weighs a photon arriving from `wi` (world direction).
    pub fn bsdf(&self, wi: Vec3) -> Rgb {
        self.material.eval_part(
            self.part,
            self.wo,
            self.frame.to_local(wi),
            TransportMode::Radiance,
        )
    }
}

impl Default for VisiblePoint {
    fn default() -> VisiblePoint {
        VisiblePoint {
            p: Vec3::ZERO,
            n: Vec3::Z,
            frame: Frame::from_normal(Vec3::Z),
            wo: Vec3::Z,
            beta: Rgb::BLACK,
            material: Material::Interface,
            lambertian: false,
            part: BsdfPart::Whole,
            u_evals: 0.0,
            valid: false,
        }
    }
}

/// What a pixel's camera sample found: direct light and a visible point.
#[derive(Clone, Copy, Debug, Default)]
pub struct CameraSample {
    pub ld: Rgb,
    pub vp: VisiblePoint,
    pub rays: u32,
}

/// Traces the camera sample of pixel `(x, y)` for `iteration`.
pub fn camera_sample(
    ctx: &RenderContext,
    seed: u64,
    max_depth: u32,
    x: u32,
    y: u32,
    iteration: u32,
) -> CameraSample {
    let world = &ctx.world;
    let scene = world.scene_sphere();
    let mut out = CameraSample::default();
    let mut sampler = ctx.pixel_sample(seed, x, y, iteration);
    let cs = ctx.camera_sample(&mut sampler, x, y);
    let Some(cr) = cs.ray else {
        return out;
    };
    let mut ray = cr.ray;
    // The sensor is the film's; the camera path starts with the camera's weight.
    let mut beta = Rgb::splat(cr.weight * cs.filter_weight);
    let mut travelled = 0.0f32;
    let mut prev = ChainVertex::camera(ray.o);
    for depth in 0..=max_depth {
        out.rays += 1;
        let Some(hit) = world.intersect_with_footprint(&ray, f32::INFINITY, travelled) else {
            out.ld += beta * prev.environment(world, ray.d);
            break;
        };
        travelled += hit.t * ray.d.length();
        let wo_world = -ray.d.normalize();
        // Specular and rough-glass vertices precede this one: emission counts in full
        // after a delta bounce, weighted against the light sample after a glossy one.
        out.ld += beta * prev.emission(world, &hit, wo_world);
        let material = world.material_at(&hit, wo_world);
        let frame = World::shading_frame(&hit, &material);
        let wo = frame.to_local(wo_world);
        if material.passes_photon_paths() {
            if depth == max_depth {
                break;
            }
            if !material.is_specular() {
                let (direct, shadow_rays) =
                    glossy_direct(world, scene, &hit, material, wo_world, &mut sampler);
                out.rays += shadow_rays;
                out.ld += beta * direct;
            }
            let Some((wi, vertex)) =
                chain_bounce(&hit, &material, &frame, wo_world, &mut sampler, &mut beta)
            else {
                break;
            };
            prev = vertex;
            ray = hit.spawn_ray(wi);
            continue;
        }
        let (direct, rays) =
            chain_end_direct(world, scene, &hit, material, &frame, wo_world, &mut sampler);
        out.rays += rays;
        out.ld += beta * direct;
        let mut part = BsdfPart::Whole;
        if let Some(layers) = material.narrow_coat() {
            match coat_step(&hit, layers, &frame, wo_world, &mut sampler, &mut beta) {
                None => break,
                Some(CoatStep::Reflect(wi, vertex)) => {
                    if depth == max_depth {
                        break;
                    }
                    prev = vertex;
                    ray = hit.spawn_ray(wi);
                    continue;
                }
                Some(CoatStep::Under) => part = BsdfPart::UnderCoat,
            }
        }
        out.vp = VisiblePoint {
            p: hit.p,
            n: if hit.ng.dot(wo_world) >= 0.0 {
                hit.ng
            } else {
                -hit.ng
            },
            frame,
            wo,
            beta,
            material,
            lambertian: material.is_diffuse()
                && (hit.ns == hit.ng || hit.ns == -hit.ng)
                && wo.z != 0.0,
            part,
            u_evals: sampler.get_1d_if(material.eval_is_estimated()),
            valid: true,
        };
        break;
    }
    out
}

/// True when one of nine camera rays through pixel `(x, y)` (its centre, corners and
/// edge midpoints, through the lens centre) first meets a surface that photons pass
/// (a mirror, glass) or an emitter: pixels whose direct light — a light seen in a
/// mirror, through glass, or at its edge — varies sharply within the pixel and
/// converges slowly from one camera sample per iteration. The answer depends on no
/// random number, so taking more direct-light samples where it holds leaves the
/// estimate unbiased.
pub fn sees_sharp_direct_light(ctx: &RenderContext, x: u32, y: u32) -> bool {
    let world = &ctx.world;
    let centre = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
    (0..9).any(|k| {
        let offset = glam::Vec2::new((k % 3) as f32 - 1.0, (k / 3) as f32 - 1.0) * 0.5;
        let Some(cr) = ctx
            .camera
            .generate_ray(centre + offset, glam::Vec2::splat(0.5))
        else {
            return false;
        };
        world.intersect(&cr.ray, f32::INFINITY).is_some_and(|hit| {
            hit.light != crate::world::NO_LIGHT
                || world
                    .material_at(&hit, -cr.ray.d.normalize())
                    .passes_photon_paths()
        })
    })
}
