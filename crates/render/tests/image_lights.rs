//! Goniometric and projection lights, and `power` / `illuminance` on every light that
//! takes them.
//!
//! - Photon directions (`sample_le`) are distributed in proportion to the intensity's
//!   luminance (chi-square against lum I(ω) / lum Φ, and against the light's own
//!   direction density), and their flux estimates average to `Light::power`.
//! - `sample_li` gives I(ω) / d² towards the receiver: checked against the image
//!   pixel the direction falls in, worked out by hand.
//! - Scenes with `power` (or `illuminance`) build lights whose luminance power is the
//!   number given times `scale` (pbrt-v4 multiplies the scale by power / k_e), an area
//!   light's image counted by its mean luminance; the direct irradiance on a sphere of receivers around a point-like
//!   light with `power` Φ is Φ / (4π d²) averaged over the sphere.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};
use radiant_image::Image;
use radiant_math::color::Rgb;
use radiant_math::hash::Pcg32;
use radiant_render::light::{
    EnvironmentMap, GoniometricLight, Light, LightSampleContext, ProjectionLight, SceneSphere,
};
use radiant_render::world::World;
use radiant_testkit::chi2::{ChiSquareTest, Domain};

const ALPHA: f64 = 0.01;
/// Chi-square tests in this file.
const CHI2_TESTS: u32 = 4;

fn scene() -> SceneSphere {
    SceneSphere {
        center: Vec3::ZERO,
        radius: 10.0,
    }
}

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

/// A square picture with a bright spot, a dark band and colour.
fn gonio_pixels(n: usize) -> Vec<Rgb> {
    (0..n * n)
        .map(|k| {
            let (x, y) = ((k % n) as f32 / n as f32, (k / n) as f32 / n as f32);
            let spot = if (x - 0.3).abs() < 0.1 && (y - 0.6).abs() < 0.08 {
                40.0
            } else {
                0.0
            };
            let band = if (0.45..0.55).contains(&y) { 0.0 } else { 1.0 };
            Rgb::new(0.5 + x, 1.0 - 0.5 * y, 0.3) * band + Rgb::splat(spot)
        })
        .collect()
}

fn gonio_light() -> GoniometricLight {
    let n = 32;
    let grey: Vec<Rgb> = gonio_pixels(n)
        .iter()
        .map(|p| Rgb::splat((p.r + p.g + p.b) / 3.0))
        .collect();
    let rotation = Mat3::from_rotation_x(0.4) * Mat3::from_cols(Vec3::X, Vec3::Z, Vec3::Y);
    let map = EnvironmentMap::new(n, &grey, Rgb::new(2.0, 1.0, 0.5), rotation);
    GoniometricLight::new(Vec3::new(0.5, -1.0, 2.0), Arc::new(map))
}

fn projection_light() -> ProjectionLight {
    let (w, h) = (24, 16);
    let pixels: Vec<Rgb> = (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let v = if (x / 4 + y / 4) % 2 == 0 { 3.0 } else { 0.2 };
            Rgb::new(v, v * 0.5, 1.0 + x as f32 * 0.1)
        })
        .collect();
    ProjectionLight::new(
        Vec3::new(-1.0, 0.5, 0.0),
        Mat3::from_rotation_y(0.7) * Mat3::from_rotation_z(0.2),
        50.0,
        w,
        h,
        Arc::new(pixels),
        Rgb::splat(1.5),
    )
}

/// Photon directions against lum I(ω) / lum Φ and against the light's density, and
/// the mean flux of a photon against the power.
fn check_emission(name: &str, light: &Light, seed: u64) {
    assert!(matches!(
        light,
        Light::Goniometric(_) | Light::Projection(_)
    ));
    let phi = light.power(scene());
    let intensity = |w: Vec3| match light {
        Light::Goniometric(g) => g.intensity(w),
        Light::Projection(p) => p.intensity(w),
        _ => unreachable!(),
    };
    let pdf_dir = |w: Vec3| match light {
        Light::Goniometric(g) => g.pdf_dir(w),
        Light::Projection(p) => p.pdf_dir(w),
        _ => unreachable!(),
    };
    let sample = |u: radiant_testkit::chi2::SampleInput| {
        let e = light.sample_le(u.u3, u.u2, scene())?;
        Some((e.ray.d, e.pdf_dir))
    };
    // Against the intensity the histogram alone is compared: a projection light
    // samples each pixel by its flux but uniformly over the image plane within it,
    // so its density differs from I / Φ inside a pixel by the cos³ of the plane.
    ChiSquareTest::new(format!("{name}_le_vs_intensity"), Domain::Sphere)
        .samples(400_000)
        .seed(seed)
        .run(
            |u| sample(u).map(|(w, _)| w),
            |w| intensity(w).luminance() / phi.luminance(),
        )
        .check(ALPHA, CHI2_TESTS);
    ChiSquareTest::new(format!("{name}_le_vs_pdf_dir"), Domain::Sphere)
        .samples(400_000)
        .seed(seed + 1)
        .run_with_pdf(sample, pdf_dir)
        .check(ALPHA, CHI2_TESTS);

    // Each photon's flux is I / pdf: its mean is Φ (the chi-square above makes the
    // density right; this checks the flux each photon carries).
    let mut rng = Pcg32::new(seed, 7);
    let n = 200_000;
    let mut sum = [0.0f64; 3];
    let mut sum2 = [0.0f64; 3];
    for _ in 0..n {
        if let Some(e) = light.sample_le(u2(&mut rng), u2(&mut rng), scene()) {
            let (le, p) = (e.le.to_array(), e.power.to_array());
            for c in 0..3 {
                assert!(
                    (p[c] - le[c] / e.pdf_dir).abs() <= 1e-4 * p[c].abs().max(1e-3),
                    "{name}: flux {p:?} vs le / pdf"
                );
                sum[c] += p[c] as f64;
                sum2[c] += (p[c] as f64).powi(2);
            }
        }
    }
    for (c, want) in phi.to_array().into_iter().enumerate() {
        let mean = sum[c] / n as f64;
        let se = ((sum2[c] / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        assert!(
            (mean - want as f64).abs() <= 5.0 * se + 1e-4 * want as f64,
            "{name} channel {c}: mean photon flux {mean} vs power {want} (se {se})"
        );
    }
}

#[test]
fn goniometric_emission_follows_its_image() {
    check_emission(
        "goniometric",
        &Light::Goniometric(Arc::new(gonio_light())),
        31,
    );
}

#[test]
fn projection_emission_follows_its_image() {
    check_emission(
        "projection",
        &Light::Projection(Arc::new(projection_light())),
        41,
    );
}

#[test]
fn goniometric_power_is_mean_intensity_times_four_pi() {
    let g = gonio_light();
    let grey: Vec<f64> = gonio_pixels(32)
        .iter()
        .map(|p| ((p.r + p.g + p.b) / 3.0) as f64)
        .collect();
    let mean = grey.iter().sum::<f64>() / grey.len() as f64;
    let want = 4.0 * std::f64::consts::PI * mean;
    let got = g.power().to_array();
    for (c, s) in [2.0, 1.0, 0.5].into_iter().enumerate() {
        assert!(
            ((got[c] as f64) - want * s).abs() < 1e-4 * want,
            "{got:?} vs {want}"
        );
    }
}

#[test]
fn projection_light_is_dark_outside_its_image_and_behind() {
    let p = projection_light();
    let (axis, cos_width) = p.cone();
    assert!(!p.intensity(axis).is_black());
    assert!(p.intensity(-axis).is_black());
    // Wider than the image's corners: no light.
    let side = axis.any_orthonormal_vector();
    let beyond = (axis * (cos_width * 0.9) + side).normalize();
    assert!(p.intensity(beyond).is_black());
    // sample_li: intensity over distance squared, towards the light.
    let at = p.position + axis * 3.0;
    let s = Light::Projection(Arc::new(p.clone()))
        .sample_li(&LightSampleContext::at_point(at), Vec2::ZERO, scene())
        .expect("on the axis the image shines");
    assert!(s.delta && (s.wi + axis).length() < 1e-5);
    let want = p.intensity(axis) / 9.0;
    assert!(
        (s.li.r - want.r).abs() < 1e-5 * want.r.max(1.0),
        "{:?} vs {want:?}",
        s.li
    );
}

/// The top-left pixel of a projected image lands up and to the left (the light's +y
/// and −x) as seen from behind the light looking along +z.
#[test]
fn projection_orientation_puts_the_top_row_up() {
    let (w, h) = (4, 2);
    let mut pixels = vec![Rgb::splat(1.0); w * h];
    pixels[0] = Rgb::splat(100.0); // row 0 (top), column 0 (left)
    let p = ProjectionLight::new(
        Vec3::ZERO,
        Mat3::IDENTITY,
        60.0,
        w,
        h,
        Arc::new(pixels),
        Rgb::WHITE,
    );
    let t = (30.0f32).to_radians().tan();
    // Centre of pixel (0, 0): x = -3/4 of the half width (2t), y = +1/2 of t.
    let d = Vec3::new(-0.75 * 2.0 * t, 0.5 * t, 1.0);
    assert_eq!(p.intensity(d).r, 100.0);
    assert_eq!(p.intensity(Vec3::new(0.75 * 2.0 * t, 0.5 * t, 1.0)).r, 1.0);
    assert_eq!(
        p.intensity(Vec3::new(-0.75 * 2.0 * t, -0.5 * t, 1.0)).r,
        1.0
    );
}

// --- scenes ---------------------------------------------------------------------

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "radiant-image-lights-{name}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_image(dir: &Path, file: &str, width: usize, height: usize, pixels: Vec<Rgb>) {
    let img = Image {
        width,
        height,
        pixels,
    };
    radiant_image::pfm::write_pfm(dir.join(file), &img).unwrap();
}

fn build(dir: &Path, world: &str) -> World {
    let text = format!(
        "Camera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n\
         WorldBegin\n{world}\n"
    );
    let desc = radiant_scene::parse_str(&text, "power.pbrt", dir).unwrap();
    World::build(&desc).unwrap().0
}

#[test]
fn power_and_illuminance_set_the_emission() {
    let dir = temp_dir("power");
    let n = 16;
    write_image(&dir, "gonio.pfm", n, n, gonio_pixels(n));
    let proj: Vec<Rgb> = (0..12 * 8)
        .map(|k| Rgb::new(1.0 + (k % 5) as f32, 0.5, 2.0))
        .collect();
    write_image(&dir, "proj.pfm", 12, 8, proj);
    let glow: Vec<Rgb> = (0..6 * 3)
        .map(|k| Rgb::new(0.2 + k as f32, 1.0, 0.1 * (k % 4) as f32))
        .collect();
    write_image(&dir, "glow.pfm", 6, 3, glow);
    let world = build(
        &dir,
        r#"
        LightSource "point" "blackbody I" 3000 "float scale" 7 "float power" 100
        LightSource "spot" "rgb I" [1 0.5 0.2] "float coneangle" 40 "float power" 250
        LightSource "goniometric" "string filename" "gonio.pfm" "rgb I" [0.2 1 0.4] "float scale" 3 "float power" 60
        LightSource "projection" "string filename" "proj.pfm" "float fov" 35 "float power" 45
        Rotate 30 1 0 0
        LightSource "projection" "string filename" "proj.pfm" "float fov" 120 "float scale" 0.1 "float power" 8
        LightSource "distant" "blackbody L" 5000 "float illuminance" 12 "float scale" 2
        AttributeBegin
          AreaLightSource "diffuse" "string filename" "glow.pfm" "float power" 5 "float scale" 2
          Translate 0 -3 0
          Shape "disk" "float radius" 0.7
        AttributeEnd
        AttributeBegin
          AreaLightSource "diffuse" "rgb L" [3 2 1] "float power" 20 "float scale" 1.5
          Translate 0 0 5
          Shape "sphere" "float radius" 0.5
        AttributeEnd
        AttributeBegin
          AreaLightSource "diffuse" "blackbody L" 4000 "float power" 9 "bool twosided" true
          Translate 2 0 0
          Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2]
        AttributeEnd
        "#,
    );
    let sphere = scene();
    let lum = |l: &Light| l.power(sphere).luminance();
    let point_like: Vec<f32> = world
        .lights
        .iter()
        .filter(|l| !matches!(l, Light::Area(_) | Light::Distant { .. }))
        .map(lum)
        .collect();
    let want = [100.0 * 7.0, 250.0, 60.0 * 3.0, 45.0, 8.0 * 0.1];
    assert_eq!(point_like.len(), want.len());
    for (got, want) in point_like.iter().zip(want) {
        assert!((got - want).abs() < 2e-4 * want, "power {got} vs {want}");
    }
    let area: f32 = world
        .lights
        .iter()
        .filter(|l| matches!(l, Light::Area(_)))
        .map(lum)
        .sum();
    // The image disk, a sphere and a triangle: 5 × 2 + 20 × 1.5 + 9.
    assert!((area - 49.0).abs() < 2e-4 * 49.0, "area power {area}");
    let distant = world
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Distant { radiance, .. } => Some(*radiance),
            _ => None,
        })
        .unwrap();
    assert!((distant.luminance() - 24.0).abs() < 1e-4 * 24.0);
    // The spectrum's shape is kept: the spot stays as red as its I.
    let spot = world
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Spot { intensity, .. } => Some(*intensity),
            _ => None,
        })
        .unwrap();
    assert!((spot.g / spot.r - 0.5).abs() < 1e-5 && (spot.b / spot.r - 0.2).abs() < 1e-5);
    std::fs::remove_dir_all(&dir).ok();
}

/// Receivers on a sphere of radius d around a goniometric light: the mean of the
/// light's irradiance over the sphere is Φ / (4π d²), whatever the image, since the
/// intensity integrates to the power.
#[test]
fn irradiance_over_a_receiving_sphere_is_power_over_its_area() {
    let dir = temp_dir("sphere");
    let n = 16;
    write_image(&dir, "gonio.pfm", n, n, gonio_pixels(n));
    write_image(
        &dir,
        "proj.pfm",
        6,
        4,
        (0..24).map(|k| Rgb::splat(1.0 + k as f32)).collect(),
    );
    let world = build(
        &dir,
        r#"
        Translate 1 2 3
        LightSource "goniometric" "string filename" "gonio.pfm" "float power" 50
        LightSource "projection" "string filename" "proj.pfm" "float fov" 70 "float power" 30
        "#,
    );
    let d = 2.5f32;
    let centre = Vec3::new(1.0, 2.0, 3.0);
    for (light, phi) in world.lights.iter().zip([50.0f64, 30.0]) {
        // Receivers at stratified directions: a 400 x 400 equal-area grid.
        let k = 400;
        let mut e = 0.0f64;
        for j in 0..k {
            for i in 0..k {
                let st = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                let w = radiant_math::equal_area::square_to_sphere(st);
                let p = centre + w * d;
                let ctx = LightSampleContext::on_surface(p, -w);
                if let Some(s) = light.sample_li(&ctx, Vec2::ZERO, scene()) {
                    e += (s.li.luminance() * s.wi.dot(-w).max(0.0)) as f64;
                }
            }
        }
        let mean = e / (k * k) as f64;
        let want = phi / (4.0 * std::f64::consts::PI * (d * d) as f64);
        assert!(
            (mean - want).abs() < 5e-3 * want,
            "mean irradiance {mean} vs Φ / 4πd² = {want}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Light images that cannot be used: each a `file:line:column` error at the light's
/// `filename` (or the light, when it names none), without a panic.
#[test]
fn malformed_light_images_are_located_errors() {
    let corpus = |name: &str| radiant_testkit::repo_path("tests/scenes/malformed/world").join(name);
    for (scene, line, column, words) in [
        (
            "missing_goniometric_image.pbrt",
            3,
            29,
            &["cannot read goniometric light image", "no-such-diagram.exr"][..],
        ),
        (
            "unreadable_projection_image.pbrt",
            4,
            3,
            &["cannot read projection light image", "unreadable.pfm"][..],
        ),
        (
            "nonsquare_goniometric.pbrt",
            2,
            27,
            &["nonsquare-sky.pfm", "4x2", "square"][..],
        ),
        (
            "projection_without_image.pbrt",
            3,
            1,
            &["\"projection\" needs a \"filename\""][..],
        ),
        (
            "missing_area_light_image.pbrt",
            3,
            29,
            &["cannot read area light image", "no-such-emission.exr"][..],
        ),
        (
            "unreadable_area_light_image.pbrt",
            4,
            5,
            &["cannot read area light image", "unreadable.pfm"][..],
        ),
    ] {
        let path = corpus(scene);
        let message = match radiant_scene::parse_file(&path) {
            Err(e) => e.to_string(),
            Ok(desc) => World::build(&desc).map(|_| ()).unwrap_err().to_string(),
        };
        let expected = format!("{}:{line}:{column}: error:", path.display());
        assert!(message.starts_with(&expected), "{scene}: {message}");
        for w in words {
            assert!(message.contains(w), "{scene}: lacks \"{w}\": {message}");
        }
    }
}
