//! Scene fixtures for tests and benchmarks: pbrt's analytic spheres, and the render
//! settings a test matrix varies (sampler, pixel filter, sensor, camera, integrator) as
//! functions of a [`SceneDesc`].
//!
//! Everything derives from the canonical scenes of [`radiant_scene::builtin`] (the
//! spheres from its furnace); nothing here redefines them. The kit depends on
//! `radiant-scene`, so `radiant-scene`'s own unit tests cannot use these fixtures (they
//! would see a second copy of the crate's types); its integration tests, and every crate
//! above it, can.

use glam::{Vec2, Vec3};

use radiant_math::color::Rgb;
use radiant_math::{PI, Transform};
use radiant_scene::builtin::{furnace, right_handed_camera};
use radiant_scene::params::ParamSet;
use radiant_scene::{
    AreaLightDesc, FileLoc, FilterKind, Geometry, IntegratorDesc, LightDesc, MaterialDesc,
    SamplerKind, SceneDesc,
};

/// Diffuse reflectance of the analytic spheres (the furnace's albedo).
pub const SPHERE_ALBEDO: f32 = 0.5;

/// Intensity of the point light at the centre of [`lit_sphere`] (W/sr per channel).
pub const LIT_SPHERE_INTENSITY: f32 = PI;

/// Radiance everywhere inside [`lit_sphere`].
pub const LIT_SPHERE_RADIANCE: f32 = 1.0;

/// The furnace shrunk to a closed unit sphere about the origin, reflectance
/// [`SPHERE_ALBEDO`], neither emitting nor lit, its front facing inwards; the camera
/// at the centre as in the furnace.
fn unit_sphere(name: &str) -> SceneDesc {
    let mut desc = furnace();
    let shape = &mut desc.shapes[0];
    shape.geometry = Geometry::Sphere {
        radius: 1.0,
        z_min: -1.0,
        z_max: 1.0,
        phi_max_deg: 360.0,
    };
    shape.render_from_object = Transform::IDENTITY;
    shape.area_light = None;
    shape.loc = FileLoc::builtin(name);
    desc.materials = vec![MaterialDesc::Diffuse {
        reflectance: Rgb::splat(SPHERE_ALBEDO),
    }];
    desc.film.filename = Some(format!("{name}.exr"));
    desc
}

/// pbrt-v4's analytic scene: inside a closed unit sphere of reflectance Kd = 1/2, lit
/// by an isotropic point light of intensity I = π at its centre, the radiance is 1 in
/// every direction at every point.
///
/// Every wall point lies at r = 1 facing the light, so its irradiance is I / r² = π and
/// the light it reflects directly is Kd/π · π = 1/2 everywhere. Light that is uniform
/// over a closed enclosure stays uniform: a wall of radiance L gives every point an
/// irradiance πL, reflected as Kd L. The bounces form the series 1/2 (1 + Kd + Kd² + …)
/// = (1/2) / (1 − Kd) = 1.
pub fn lit_sphere() -> SceneDesc {
    let name = "lit-sphere";
    let mut desc = unit_sphere(name);
    desc.lights = vec![LightDesc::Point {
        position: Vec3::ZERO,
        intensity: Rgb::splat(LIT_SPHERE_INTENSITY),
        loc: FileLoc::builtin(name),
    }];
    desc
}

/// The unit sphere of [`lit_sphere`] without the point light, emitting `le` (a
/// one-sided diffuse area light on the sphere itself, facing inwards). Emission and
/// every bounce are uniform, so the radiance is Le (1 + Kd + Kd² + …) = Le / (1 − Kd)
/// everywhere: [`glowing_sphere_radiance`].
pub fn glowing_sphere(le: Rgb) -> SceneDesc {
    let mut desc = unit_sphere("glowing-sphere");
    desc.shapes[0].area_light = Some(AreaLightDesc {
        l: le,
        two_sided: false,
        image: None,
    });
    desc
}

/// The radiance everywhere inside [`glowing_sphere`]`(le)`: Le / (1 − Kd).
pub fn glowing_sphere_radiance(le: Rgb) -> Rgb {
    le * (1.0 / (1.0 - SPHERE_ALBEDO))
}

/// The scene's sampler replaced by `kind` (its sample count and seed kept).
pub fn with_sampler(mut desc: SceneDesc, kind: SamplerKind) -> SceneDesc {
    desc.sampler.kind = kind;
    desc
}

/// `spp` samples per pixel (SPPM: iterations).
pub fn with_samples(mut desc: SceneDesc, spp: u32) -> SceneDesc {
    desc.sampler.pixel_samples = spp;
    desc
}

pub fn with_seed(mut desc: SceneDesc, seed: u64) -> SceneDesc {
    desc.sampler.seed = seed;
    desc
}

/// The pixel filters a test matrix runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelFilter {
    /// A box of exactly one pixel (radius 1/2), as the references use.
    Box,
    /// pbrt-v4's default Gaussian: radius 1.5 pixels, σ = 0.5.
    Gaussian,
}

impl PixelFilter {
    pub const ALL: [PixelFilter; 2] = [PixelFilter::Box, PixelFilter::Gaussian];

    /// The filter's kind and radius (pixels) as a scene describes them.
    pub fn kind_and_radius(self) -> (FilterKind, Vec2) {
        match self {
            PixelFilter::Box => (FilterKind::Box, Vec2::splat(0.5)),
            PixelFilter::Gaussian => (FilterKind::Gaussian { sigma: 0.5 }, Vec2::splat(1.5)),
        }
    }
}

/// The scene's pixel filter replaced by `filter`.
pub fn with_filter(mut desc: SceneDesc, filter: PixelFilter) -> SceneDesc {
    let (kind, radius) = filter.kind_and_radius();
    desc.filter.kind = kind;
    desc.filter.radius = radius;
    desc
}

/// The sensor's ISO (the image scales by `iso / 100`).
pub fn with_iso(mut desc: SceneDesc, iso: f32) -> SceneDesc {
    desc.film.iso = iso;
    desc
}

pub fn with_resolution(mut desc: SceneDesc, width: u32, height: u32) -> SceneDesc {
    desc.film.xresolution = width;
    desc.film.yresolution = height;
    desc
}

/// A pinhole camera at `eye` looking at `target` (+y up, world +x on the image's left,
/// as in the canonical scenes), full vertical field of view `vfov_deg`.
pub fn with_camera(mut desc: SceneDesc, eye: Vec3, target: Vec3, vfov_deg: f32) -> SceneDesc {
    desc.camera = right_handed_camera(eye, target, Vec3::Y, vfov_deg, "fixture");
    desc
}

/// The integrator `name` with `params`.
pub fn with_integrator(mut desc: SceneDesc, name: &str, params: ParamSet) -> SceneDesc {
    desc.integrator = IntegratorDesc {
        name: name.into(),
        params,
        loc: desc.integrator.loc.clone(),
    };
    desc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spheres_derive_from_the_furnace() {
        let lit = lit_sphere();
        let glow = glowing_sphere(Rgb::splat(0.5));
        let f = furnace();
        for d in [&lit, &glow] {
            assert_eq!(d.shapes.len(), 1);
            assert!(d.shapes[0].reverse_orientation);
            assert_eq!(d.camera.camera_from_world, f.camera.camera_from_world);
            assert_eq!(d.materials, f.materials);
        }
        assert!(lit.shapes[0].area_light.is_none() && lit.lights.len() == 1);
        assert!(glow.shapes[0].area_light.is_some() && glow.lights.is_empty());
        assert_eq!(glowing_sphere_radiance(Rgb::splat(0.5)), Rgb::splat(1.0));
    }

    #[test]
    fn variants_change_only_their_setting() {
        let d = with_filter(
            with_iso(with_sampler(lit_sphere(), SamplerKind::Independent), 400.0),
            PixelFilter::Gaussian,
        );
        assert_eq!(d.sampler.kind, SamplerKind::Independent);
        assert_eq!(d.film.iso, 400.0);
        assert_eq!(d.filter.kind, FilterKind::Gaussian { sigma: 0.5 });
        assert_eq!(d.sampler.pixel_samples, lit_sphere().sampler.pixel_samples);
        let moved = with_camera(lit_sphere(), Vec3::new(0.3, 0.0, 0.0), Vec3::Z, 60.0);
        // The eye maps to the camera's origin.
        let o = moved
            .camera
            .camera_from_world
            .point(Vec3::new(0.3, 0.0, 0.0));
        assert!(o.length() < 1e-6);
    }
}
