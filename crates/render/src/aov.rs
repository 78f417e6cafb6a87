//! Arbitrary output variables: what the camera rays see first, beside the image — the
//! albedo, position, normals and depth that denoisers and compositors read (pbrt-v4's
//! `Film "gbuffer"` writes the same quantities).
//!
//! They are taken in a pass of their own after the render, with the render's camera
//! samples (same seed, pixel and sample index, hence the same filter offsets and lens
//! points), so any integrator gets them and the image is untouched. Each pixel's value
//! is the mean over its samples weighted by the pixel filter's weight f/pdf, as the
//! film weights radiance. Samples whose ray leaves the scene count as zero.
//!
//! The albedo is the directional albedo ρ(ωo) = ∫ f |cos θ| dω, estimated with one BSDF
//! sample per camera sample (f |cos θ| / pdf): exact for a diffuse surface (its
//! reflectance), the Fresnel-weighted colour for a specular one.

use glam::Vec3;
use radiant_math::Transform;
use rayon::prelude::*;

use crate::context::RenderContext;
use crate::material::TransportMode;
use crate::world::World;

/// Which variables to compute.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet {
    pub albedo: bool,
    pub position: bool,
    pub normal: bool,
    pub shading_normal: bool,
    pub depth: bool,
}

impl AovSet {
    /// Everything (pbrt-v4's G-buffer film).
    pub const ALL: AovSet = AovSet {
        albedo: true,
        position: true,
        normal: true,
        shading_normal: true,
        depth: true,
    };

    pub fn any(&self) -> bool {
        self.albedo || self.position || self.normal || self.shading_normal || self.depth
    }
}

/// The space positions and normals are given in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AovSpace {
    /// Render (world) space.
    World,
    /// The camera's space (+z forward), given by its camera-from-world transform.
    Camera(Transform),
}

/// One image channel: its EXR name (`Albedo.R`, `N.X`, `Z`) and `width * height` values.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub name: String,
    pub values: Vec<f32>,
}

/// Per-pixel weighted sums of one sample set's variables.
#[derive(Clone, Copy, Default)]
struct Sums {
    albedo: Vec3,
    p: Vec3,
    n: Vec3,
    ns: Vec3,
    z: f32,
    weight: f32,
}

/// Computes the variables of `set` from `samples` camera samples per pixel (the
/// render's first ones). `camera_from_world` gives the depth (camera-space z) and, with
/// [`AovSpace::Camera`], the space of positions and normals.
pub fn render_aovs(
    ctx: &RenderContext,
    set: AovSet,
    samples: u32,
    space: AovSpace,
    camera_from_world: &Transform,
) -> Vec<Channel> {
    let (w, h) = (ctx.resolution.0 as usize, ctx.resolution.1 as usize);
    let world = &ctx.world;
    let to_space = |p: Vec3, n: Vec3, ns: Vec3| match space {
        AovSpace::World => (p, n, ns),
        AovSpace::Camera(t) => (
            t.point(p),
            t.normal(n).normalize_or_zero(),
            t.normal(ns).normalize_or_zero(),
        ),
    };
    let sums: Vec<Sums> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % w) as u32, (i / w) as u32);
            let mut s = Sums::default();
            for index in 0..samples.max(1) {
                let mut sampler = ctx.pixel_sample(ctx.seed, x, y, index);
                let cs = ctx.camera_sample(&mut sampler, x, y);
                let wt = cs.filter_weight;
                s.weight += wt;
                let Some(cr) = cs.ray else { continue };
                let ray = cr.ray;
                let Some(hit) = world.intersect_with_footprint(&ray, f32::INFINITY, 0.0) else {
                    continue;
                };
                let wo_world = -ray.d.normalize();
                if set.albedo {
                    let material = world.material_at(&hit, wo_world);
                    let frame = World::shading_frame(&hit, &material);
                    let wo = frame.to_local(wo_world);
                    let (u1, u2) = (sampler.get_1d(), sampler.get_2d());
                    if let Some(bs) = material.sample(wo, u1, u2, TransportMode::Radiance)
                        && bs.pdf > 0.0
                    {
                        let a = bs.f * (bs.wi.z.abs() / bs.pdf);
                        if a.is_finite() {
                            s.albedo += Vec3::new(a.r, a.g, a.b) * wt;
                        }
                    }
                }
                let (p, n, ns) = to_space(hit.p, hit.ng, hit.ns);
                s.p += p * wt;
                s.n += n * wt;
                s.ns += ns * wt;
                s.z += camera_from_world.point(hit.p).z * wt;
            }
            s
        })
        .collect();
    let mean = |f: &dyn Fn(&Sums) -> f32| -> Vec<f32> {
        sums.iter()
            .map(|s| {
                if s.weight == 0.0 {
                    0.0
                } else {
                    f(s) / s.weight
                }
            })
            .collect()
    };
    let mut channels = Vec::new();
    let mut push3 = |prefix: &str, names: [&str; 3], get: &dyn Fn(&Sums) -> Vec3| {
        for (k, suffix) in names.iter().enumerate() {
            channels.push(Channel {
                name: format!("{prefix}.{suffix}"),
                values: mean(&|s| get(s)[k]),
            });
        }
    };
    if set.albedo {
        push3("Albedo", ["R", "G", "B"], &|s| s.albedo);
    }
    if set.position {
        push3("P", ["X", "Y", "Z"], &|s| s.p);
    }
    if set.normal {
        push3("N", ["X", "Y", "Z"], &|s| s.n);
    }
    if set.shading_normal {
        push3("Ns", ["X", "Y", "Z"], &|s| s.ns);
    }
    if set.depth {
        channels.push(Channel {
            name: "Z".into(),
            values: mean(&|s| s.z),
        });
    }
    channels
}
