//! The image-based infinite light: its sampling against the image's luminance by
//! Pearson's chi-square test, irradiance against closed forms for a sky with a sun,
//! the variance gain of importance sampling over uniform sampling, photon power, and
//! the orientation given by the light's transform.
//!
//! The test sky: uniform radiance `SKY` above the horizon (z > 0), `GROUND` below, and
//! a sun of radiance `SUN` filling the cone of half-angle `SUN_HALF_ANGLE` about
//! `sun_direction()`. For a surface with unit normal n, the hemisphere sky gives the
//! view-factor result E = π L_sky (1 + n_z) / 2 + π L_ground (1 - n_z) / 2, and a cap of
//! half-angle α wholly above the surface's horizon gives ∫ n·ω dω = n · ∫ ω dω =
//! π sin²α (n · s). Pixels hold the mean of the continuous sky over their cell (8 x 8
//! points), so the image's irradiance differs from the closed form only by the
//! variation of cos within the pixels that straddle an edge.

use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};
use radiant_math::color::Rgb;
use radiant_math::equal_area::square_to_sphere;
use radiant_math::hash::Pcg32;
use radiant_math::sampling;
use radiant_math::{Frame, PI};
use radiant_render::light::{EnvironmentMap, Light, LightSampleContext, SceneSphere};
use radiant_testkit::chi2::{ChiSquareReport, ChiSquareTest, Domain};

const ALPHA: f64 = 0.01;
/// Chi-square tests in this file: plain and compensated densities, each against the
/// luminance and against `pdf_li`.
const CHI2_TESTS: u32 = 4;

const SKY: f32 = 0.6;
const GROUND: f32 = 0.15;
const SUN: f32 = 2000.0;
const SUN_HALF_ANGLE: f32 = 0.06;

fn check(report: &ChiSquareReport) {
    report.check(ALPHA, CHI2_TESTS);
}

fn sun_direction() -> Vec3 {
    Vec3::new(0.45, -0.3, 0.84).normalize()
}

fn scene() -> SceneSphere {
    SceneSphere {
        center: Vec3::new(0.5, 0.0, -1.0),
        radius: 2.0,
    }
}

/// The continuous test sky.
fn sky(w: Vec3) -> f32 {
    if w.dot(sun_direction()) >= SUN_HALF_ANGLE.cos() {
        SUN
    } else if w.z > 0.0 {
        SKY
    } else {
        GROUND
    }
}

/// The sky as a `size`² equal-area image, each pixel the mean over 8 x 8 points of
/// its cell; tinted so that channels differ.
fn sky_image(size: usize) -> Vec<Rgb> {
    let k = 8;
    (0..size * size)
        .map(|i| {
            let (x, y) = ((i % size) as f32, (i / size) as f32);
            let mut s = 0.0;
            for a in 0..k {
                for b in 0..k {
                    let st = Vec2::new(
                        (x + (a as f32 + 0.5) / k as f32) / size as f32,
                        (y + (b as f32 + 0.5) / k as f32) / size as f32,
                    );
                    s += sky(square_to_sphere(st));
                }
            }
            let v = s / (k * k) as f32;
            Rgb::new(v, 0.9 * v, 1.1 * v)
        })
        .collect()
}

fn env_light(size: usize, rotation: Mat3) -> Light {
    Light::Infinite {
        radiance: Rgb::WHITE,
        map: Some(Arc::new(EnvironmentMap::new(
            size,
            &sky_image(size),
            Rgb::WHITE,
            rotation,
        ))),
    }
}

/// The closed-form irradiance (green channel: factor 0.9) for a unit normal whose
/// horizon the sun's disk does not straddle.
fn closed_form_irradiance(n: Vec3) -> f64 {
    let s = sun_direction();
    let cos_ns = n.dot(s) as f64;
    let sin_a = (SUN_HALF_ANGLE as f64).sin();
    assert!(cos_ns.abs() > sin_a, "the sun straddles the horizon of {n}");
    let pi = std::f64::consts::PI;
    let sky =
        pi * SKY as f64 * (1.0 + n.z as f64) / 2.0 + pi * GROUND as f64 * (1.0 - n.z as f64) / 2.0;
    // The sun replaces the sky (or ground) in its cap.
    let cap_axis = pi * sin_a * sin_a * cos_ns.max(0.0);
    let under_sun = if s.z > 0.0 { SKY } else { GROUND } as f64;
    0.9 * (sky + (SUN as f64 - under_sun) * cap_axis)
}

/// Mean and standard error of `n` values of `f(i)`.
fn mean_se(n: usize, mut f: impl FnMut(usize) -> f64) -> (f64, f64) {
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for i in 0..n {
        let v = f(i);
        s += v;
        s2 += v * v;
    }
    let mean = s / n as f64;
    (
        mean,
        ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

/// Light-sampled irradiance estimate at normal `n` (one sample).
fn light_estimate(light: &Light, ctx: &LightSampleContext, n: Vec3, u: Vec2) -> f64 {
    light
        .sample_li(ctx, u, scene())
        .map_or(0.0, |s| (s.li.g * s.wi.dot(n).max(0.0) / s.pdf) as f64)
}

#[test]
fn sampling_follows_the_image_luminance() {
    let light = env_light(32, Mat3::IDENTITY);
    let Light::Infinite { map: Some(map), .. } = &light else {
        unreachable!()
    };
    let p = Vec3::new(0.1, 0.2, 0.3);
    let image = sky_image(32);
    let lum: Vec<f64> = image.iter().map(|c| c.luminance() as f64).collect();
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    let excess_mean = lum.iter().map(|y| (y - mean).max(0.0)).sum::<f64>() / lum.len() as f64;
    for (name, ctx) in [
        ("environment_plain", LightSampleContext::at_point(p)),
        (
            "environment_compensated",
            LightSampleContext::at_point(p).with_mis(),
        ),
    ] {
        // The density the image's luminance asks for, from the radiance lookup alone:
        // Y / (4π mean Y), or for MIS max(0, Y - mean Y) / (4π mean max(0, Y - mean Y)).
        let from_luminance = |wi: Vec3| -> f64 {
            let y = map.radiance(wi).luminance() as f64;
            let w = if ctx.mis_with_bsdf {
                (y - mean).max(0.0) / excess_mean
            } else {
                y / mean
            };
            w / (4.0 * std::f64::consts::PI)
        };
        let sample = |u: radiant_testkit::chi2::SampleInput| {
            let s = light.sample_li(&ctx, u.u2, scene())?;
            assert!(s.at_infinity && !s.delta);
            Some((s.wi, s.pdf))
        };
        check(
            &ChiSquareTest::new(format!("{name}_vs_luminance"), Domain::Sphere)
                .samples(400_000)
                .seed(3)
                .run_with_pdf(sample, from_luminance),
        );
        check(
            &ChiSquareTest::new(format!("{name}_vs_pdf_li"), Domain::Sphere)
                .samples(400_000)
                .seed(5)
                .run_with_pdf(sample, |wi| light.pdf_li(&ctx, wi, None)),
        );
    }
}

/// Normals all round, none with the sun on its horizon.
fn normals() -> Vec<Vec3> {
    vec![
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::new(-0.3, 0.8, 0.2).normalize(),
        sun_direction(),
        Vec3::new(0.2, 0.9, -0.4).normalize(),
    ]
}

#[test]
fn irradiance_matches_the_closed_form_at_several_normals() {
    let light = env_light(256, Mat3::IDENTITY);
    let p = Vec3::new(0.4, -0.1, 0.2);
    let samples = 200_000;
    for (k, n) in normals().into_iter().enumerate() {
        let exact = closed_form_irradiance(n);
        let mut rng = Pcg32::new(11, k as u64);
        let ctx = LightSampleContext::at_point(p);
        let (e, se) = mean_se(samples, |_| light_estimate(&light, &ctx, n, u2(&mut rng)));
        // Pixelisation of the edges (see the file comment): well under 0.5 %.
        let tolerance = 4.0 * se + 5e-3 * exact;
        println!("normal {n}: E {e:.5} ± {se:.5}, closed form {exact:.5}");
        assert!(
            (e - exact).abs() < tolerance,
            "normal {n}: {e} vs {exact} (se {se})"
        );

        // The path tracer's pairing: the compensated light density and cosine BSDF
        // sampling, each weighted by the power heuristic, sum to the same irradiance.
        let mis_ctx = ctx.with_mis();
        let frame = Frame::from_normal(n);
        let (e_mis, se_mis) = mean_se(samples, |_| {
            let mut v = 0.0;
            if let Some(s) = light.sample_li(&mis_ctx, u2(&mut rng), scene()) {
                let cos = s.wi.dot(n);
                if cos > 0.0 {
                    let bsdf_pdf = cos / PI;
                    v += (s.li.g * cos / s.pdf * sampling::power_heuristic(s.pdf, bsdf_pdf)) as f64;
                }
            }
            let local = sampling::cosine_hemisphere(u2(&mut rng));
            let wi = frame.to_world(local);
            let bsdf_pdf = sampling::cosine_hemisphere_pdf(local.z);
            if bsdf_pdf > 0.0 {
                let light_pdf = light.pdf_li(&mis_ctx, wi, None);
                let li = light.environment(wi).g;
                v += (li * local.z / bsdf_pdf * sampling::power_heuristic(bsdf_pdf, light_pdf))
                    as f64;
            }
            v
        });
        assert!(
            (e_mis - exact).abs() < 4.0 * se_mis + 5e-3 * exact,
            "MIS, normal {n}: {e_mis} vs {exact} (se {se_mis})"
        );
    }
}

/// At equal sample counts, sampling by the image has at least 5x lower variance than
/// sampling the sphere uniformly, for a surface the sun shines on.
#[test]
fn importance_sampling_beats_uniform_sampling_fivefold() {
    let light = env_light(128, Mat3::IDENTITY);
    let constant = Light::Infinite {
        radiance: Rgb::WHITE,
        map: None,
    };
    let n = Vec3::new(0.1, 0.2, 1.0).normalize();
    let ctx = LightSampleContext::at_point(Vec3::ZERO);
    let samples = 100_000;
    let mut rng = Pcg32::new(5, 5);
    let (e_is, se_is) = mean_se(samples, |_| light_estimate(&light, &ctx, n, u2(&mut rng)));
    let (e_u, se_u) = mean_se(samples, |_| {
        // Uniform directions (the constant light's sampler) weighted by the image.
        constant
            .sample_li(&ctx, u2(&mut rng), scene())
            .map_or(0.0, |s| {
                (light.environment(s.wi).g * s.wi.dot(n).max(0.0) / s.pdf) as f64
            })
    });
    assert!((e_is - e_u).abs() < 4.0 * (se_is * se_is + se_u * se_u).sqrt());
    let ratio = (se_u / se_is).powi(2);
    println!("variance ratio uniform / importance at {samples} samples: {ratio:.1}");
    assert!(ratio >= 5.0, "variance ratio {ratio}");
}

#[test]
fn photons_carry_the_lights_power() {
    let light = env_light(64, Mat3::IDENTITY);
    let mut rng = Pcg32::new(8, 1);
    let (mean, se) = mean_se(400_000, |_| {
        light
            .sample_le(u2(&mut rng), u2(&mut rng), scene())
            .map_or(0.0, |e| {
                // Every photon starts on the disk in front of the scene sphere, heading in.
                let to_centre = scene().center - e.ray.o;
                assert!(to_centre.length() <= scene().radius * 1.001 * 2f32.sqrt());
                assert!(e.ray.d.dot(to_centre) > 0.0);
                e.power.g as f64
            })
    });
    let power = light.power(scene()).g as f64;
    assert!(
        (mean - power).abs() < 4.0 * se + 1e-5 * power,
        "{mean} vs {power} (se {se})"
    );
}

#[test]
fn the_transform_turns_the_image() {
    let size = 32;
    let turn = Mat3::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
    let upright = env_light(size, Mat3::IDENTITY);
    let turned = env_light(size, turn);
    let ctx = LightSampleContext::at_point(Vec3::ZERO);
    let mut rng = Pcg32::new(2, 9);
    for _ in 0..2000 {
        let w = sampling::uniform_sphere(u2(&mut rng));
        assert_eq!(turned.environment(turn * w), upright.environment(w));
        let (a, b) = (
            turned.pdf_li(&ctx, turn * w, None),
            upright.pdf_li(&ctx, w, None),
        );
        assert!((a - b).abs() <= 1e-4 * b, "{a} vs {b}");
    }
    // The sun is where the rotation puts it.
    let s = turned
        .sample_li(&ctx, Vec2::new(0.5, 0.5), scene())
        .map(|s| s.wi);
    let mut in_sun = 0;
    for _ in 0..1000 {
        let s = turned.sample_li(&ctx, u2(&mut rng), scene()).unwrap();
        // Within the sun's pixels (32² pixels are about 0.11 rad across).
        if s.wi.dot(turn * sun_direction()) > 0.25f32.cos() {
            in_sun += 1;
        }
    }
    assert!(s.is_some());
    // The sun holds about 2000·0.011 / (0.6·2π + 0.15·2π + 2000·0.011) ≈ 82 % of the
    // luminance.
    assert!(in_sun > 750, "{in_sun} of 1000 samples in the sun");
}
