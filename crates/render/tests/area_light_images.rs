//! Area lights with an image (`AreaLightSource "diffuse" "string filename"`).
//!
//! - Light samples and rays that hit the light see the same radiance at the same
//!   point: the irradiance at a receiver estimated by sampling the light
//!   (`sample_li`) equals the one estimated by tracing directions from the receiver
//!   and reading the radiance of the hit — on a uv-mapped quad, a triangle with the
//!   default (u, v), a sphere, a partial disk, a curved bilinear patch and the halves
//!   of a planar one. A mismatch of the two (u, v), such as an unflipped v, changes the
//!   irradiance by far more than the noise, since the image and the receiver are
//!   lopsided.
//! - The image is what a camera ray sees: row 0 of the file at v = 1.
//! - Photons carry the image: their mean flux is the light's power, l × mean × π A.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use radiant_image::Image;
use radiant_math::color::Rgb;
use radiant_math::hash::Pcg32;
use radiant_math::{Frame, PI, sampling};
use radiant_render::geometry::Ray;
use radiant_render::integrator::direct::surface_emission;
use radiant_render::light::{Light, LightSampleContext};
use radiant_render::world::World;

fn temp_dir(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("radiant-area-images-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// 8 × 4 texels: dark except a bright top-left block, a red right edge and a ramp.
fn glow_pixels() -> Vec<Rgb> {
    let (w, h) = (8, 4);
    (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let mut c = Rgb::splat(0.05 * x as f32);
            if x < 3 && y < 2 {
                c += Rgb::new(6.0, 5.0, 4.0);
            }
            if x == w - 1 {
                c += Rgb::new(2.0, 0.0, 0.0);
            }
            c
        })
        .collect()
}

fn write_glow(dir: &Path) {
    let img = Image {
        width: 8,
        height: 4,
        pixels: glow_pixels(),
    };
    radiant_image::pfm::write_pfm(dir.join("glow.pfm"), &img).unwrap();
}

fn build(dir: &Path, shape: &str) -> World {
    let text = format!(
        "Camera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n\
         WorldBegin\n\
         AttributeBegin\n\
           AreaLightSource \"diffuse\" \"string filename\" \"glow.pfm\" \"float scale\" 1.5 \
             \"bool twosided\" true\n\
           {shape}\n\
         AttributeEnd\n"
    );
    let desc = radiant_scene::parse_str(&text, "glow.pbrt", dir).unwrap();
    let (world, warnings) = World::build(&desc).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    world
}

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

/// Mean and standard error of per-channel-summed estimates.
fn mean_se(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Irradiance (r + 2g + b, to weigh every channel) at `p` with normal `n`, by light
/// sampling and by tracing directions over the hemisphere and reading the hit.
fn irradiance_both_ways(world: &World, p: Vec3, n: Vec3, seed: u64) -> ((f64, f64), (f64, f64)) {
    let weigh = |c: Rgb| (c.r + 2.0 * c.g + c.b) as f64;
    let [light] = &world.lights[..] else {
        panic!("one light")
    };
    let ctx = LightSampleContext {
        p,
        n,
        ns: n,
        mis_with_bsdf: false,
    };
    let mut rng = Pcg32::new(seed, 1);
    let count = 200_000;
    let by_light: Vec<f64> = (0..count)
        .map(
            |_| match light.sample_li(&ctx, u2(&mut rng), world.scene_sphere()) {
                Some(s) if s.pdf > 0.0 => weigh(s.li) * s.wi.dot(n).max(0.0) as f64 / s.pdf as f64,
                _ => 0.0,
            },
        )
        .collect();
    let frame = Frame::from_normal(n);
    let by_hits: Vec<f64> = (0..count)
        .map(|_| {
            let local = sampling::cosine_hemisphere(u2(&mut rng));
            let d = frame.to_world(local);
            match world.intersect(&Ray::new(p, d), f32::INFINITY) {
                // cos / pdf = π for cosine-distributed directions.
                Some(hit) => weigh(surface_emission(world, &hit, -d)) * PI as f64,
                None => 0.0,
            }
        })
        .collect();
    (mean_se(&by_light), mean_se(&by_hits))
}

#[test]
fn light_samples_and_hits_see_the_same_image() {
    let dir = temp_dir("both-ways");
    write_glow(&dir);
    let shapes = [
        (
            "uv quad",
            "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \
             \"point2 uv\" [ 0 0  1 0  1 1  0 1 ] \"integer indices\" [ 0 1 2  0 2 3 ]",
        ),
        (
            "default-uv triangles",
            "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \
             \"integer indices\" [ 0 1 2  0 2 3 ]",
        ),
        ("sphere", "Shape \"sphere\" \"float radius\" 0.8"),
        (
            "partial disk",
            "Shape \"disk\" \"float radius\" 1.2 \"float innerradius\" 0.3 \"float phimax\" 270",
        ),
        (
            "curved patch",
            "Shape \"bilinearmesh\" \"point3 P\" [ -1 -1 0  1 -1 0.6  -1 1 -0.4  1 1 0 ] \
             \"integer indices\" [ 0 1 2 3 ]",
        ),
        (
            "planar patch",
            "Shape \"bilinearmesh\" \"point3 P\" [ -1 -1 0  1 -1 0  -1 1 0  1 1 0 ] \
             \"integer indices\" [ 0 1 2 3 ]",
        ),
    ];
    for (k, (name, shape)) in shapes.into_iter().enumerate() {
        let world = build(&dir, shape);
        // Off centre and tilted, so that the image's parts weigh differently.
        let p = Vec3::new(0.5, -0.3, 1.6);
        let n = (Vec3::new(-0.2, 0.1, -1.0)).normalize();
        let ((a, sa), (b, sb)) = irradiance_both_ways(&world, p, n, 10 + k as u64);
        let se = (sa * sa + sb * sb).sqrt();
        assert!(a > 0.1, "{name}: no light {a}");
        assert!(
            (a - b).abs() < 5.0 * se,
            "{name}: light sampling {a} vs hits {b} (se {se})"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_camera_ray_sees_the_file_top_row_at_v_one() {
    let dir = temp_dir("orientation");
    write_glow(&dir);
    let world = build(
        &dir,
        "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  1 1 0  0 1 0 ] \
         \"point2 uv\" [ 0 0  1 0  1 1  0 1 ] \"integer indices\" [ 0 1 2  0 2 3 ]",
    );
    let glow = glow_pixels();
    // At texel centres (x + 1/2) / 8, v = 1 − (y + 1/2) / 4, the radiance is that
    // texel times the scale.
    for (x, y) in [(0usize, 0usize), (1, 1), (7, 2), (4, 3), (7, 0)] {
        let (u, v) = ((x as f32 + 0.5) / 8.0, 1.0 - (y as f32 + 0.5) / 4.0);
        let ray = Ray::new(Vec3::new(u, v, 1.0), -Vec3::Z);
        let hit = world.intersect(&ray, f32::INFINITY).unwrap();
        let le = surface_emission(&world, &hit, Vec3::Z);
        let want = glow[y * 8 + x] * 1.5;
        assert!(
            (le.r - want.r).abs() < 1e-4 && (le.g - want.g).abs() < 1e-4,
            "texel ({x}, {y}): {le:?} vs {want:?}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn photons_carry_the_image_and_average_to_the_power() {
    let dir = temp_dir("photons");
    write_glow(&dir);
    // A uniform parameterisation, over which the mean of the bilinear interpolant is
    // exactly the mean texel.
    let world = build(
        &dir,
        "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \
         \"point2 uv\" [ 0 0  1 0  1 1  0 1 ] \"integer indices\" [ 0 1 2  0 2 3 ]",
    );
    let [light @ Light::Area(area)] = &world.lights[..] else {
        panic!("one area light")
    };
    let mean: Rgb = glow_pixels().iter().fold(Rgb::BLACK, |a, &c| a + c) / 32.0;
    // Two-sided, area 4: 2 π A L̄.
    let want = mean * 1.5 * (2.0 * PI * 4.0);
    let power = light.power(world.scene_sphere());
    for c in 0..3 {
        let (g, w) = (power.to_array()[c], want.to_array()[c]);
        assert!(
            (g - w).abs() < 1e-4 * w.max(1.0),
            "power {power:?} vs {want:?}"
        );
    }
    assert!(area.image.is_some());
    let mut rng = Pcg32::new(3, 9);
    let n = 200_000;
    let fluxes: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            light
                .sample_le(u2(&mut rng), u2(&mut rng), world.scene_sphere())
                .map_or([0.0; 3], |e| e.power.to_array().map(|v| v as f64))
        })
        .collect();
    for c in 0..3 {
        let column: Vec<f64> = fluxes.iter().map(|f| f[c]).collect();
        let (m, se) = mean_se(&column);
        let w = want.to_array()[c] as f64;
        assert!(
            (m - w).abs() < 5.0 * se + 1e-6,
            "channel {c}: {m} vs {w} (se {se})"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
