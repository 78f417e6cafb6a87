//! Physics checks of the BSDFs: reciprocity, energy conservation, and sampling
//! consistent with evaluation.

use super::*;
use radiant_math::hash::Pcg32;

fn random_dir(rng: &mut Pcg32) -> Vec3 {
    sampling::uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()))
}

#[test]
fn diffuse_is_reciprocal_and_two_sided() {
    let m = Material::Diffuse {
        albedo: Rgb::new(0.8, 0.5, 0.2),
    };
    let mut rng = Pcg32::new(3, 0);
    for _ in 0..1000 {
        let (a, b) = (random_dir(&mut rng), random_dir(&mut rng));
        assert_eq!(m.eval(a, b), m.eval(b, a));
        assert_eq!(m.pdf(a, b) > 0.0, a.z * b.z > 0.0);
    }
}

/// Directional albedo by Monte Carlo over the sampled directions: E[f cos / pdf] must
/// equal the known albedo, and never exceed 1.
#[test]
fn sampled_albedo_matches_and_conserves_energy() {
    let cases = [
        (
            Material::Diffuse {
                albedo: Rgb::splat(0.7),
            },
            0.7,
        ),
        (
            Material::Mirror {
                reflectance: Rgb::splat(0.9),
            },
            0.9,
        ),
        (Material::Dielectric { eta: 1.5 }, 1.0),
        (
            Material::Conductor {
                eta: Rgb::splat(0.2),
                k: Rgb::splat(3.9),
            },
            -1.0,
        ),
    ];
    let mut rng = Pcg32::new(5, 0);
    for (m, expected) in cases {
        for &cos_o in &[0.95f32, 0.5, 0.1, -0.6] {
            let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
            let n = 20_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let s = m
                    .sample(
                        wo,
                        rng.uniform(),
                        Vec2::new(rng.uniform(), rng.uniform()),
                        TransportMode::Importance,
                    )
                    .unwrap();
                sum += (s.f.g * s.wi.z.abs() / s.pdf) as f64;
            }
            let albedo = sum / n as f64;
            assert!(albedo <= 1.0 + 1e-3, "{m:?} cos {cos_o}: {albedo}");
            if expected >= 0.0 {
                // Diffuse sampling is exact importance sampling: zero variance.
                assert!(
                    (albedo - expected).abs() < 1e-3,
                    "{m:?} cos {cos_o}: {albedo}"
                );
            } else {
                let r = fresnel::conductor(cos_o, Rgb::splat(0.2), Rgb::splat(3.9)).g as f64;
                assert!((albedo - r).abs() < 1e-4);
            }
        }
    }
}

/// Lambertian sampling follows its pdf: a chi-square test over a 10x20 (theta, phi) grid.
#[test]
fn diffuse_sampling_passes_chi_square() {
    let m = Material::Diffuse { albedo: Rgb::WHITE };
    let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
    let (nt, np) = (10usize, 20usize);
    let n = 200_000;
    let mut hist = vec![0f64; nt * np];
    let mut rng = Pcg32::new(11, 0);
    for _ in 0..n {
        let s = m
            .sample(
                wo,
                rng.uniform(),
                Vec2::new(rng.uniform(), rng.uniform()),
                TransportMode::Radiance,
            )
            .unwrap();
        assert!((s.pdf - m.pdf(wo, s.wi)).abs() < 1e-4);
        let theta = s.wi.z.clamp(-1.0, 1.0).acos();
        let phi = s.wi.y.atan2(s.wi.x).rem_euclid(2.0 * std::f32::consts::PI);
        let it = ((theta / (std::f32::consts::PI / 2.0)) * nt as f32).min(nt as f32 - 1.0) as usize;
        let ip = ((phi / (2.0 * std::f32::consts::PI)) * np as f32).min(np as f32 - 1.0) as usize;
        hist[it * np + ip] += 1.0;
    }
    // Expected counts: integrate the pdf over each cell numerically (midpoint rule, 8x8 per cell).
    let mut chi2 = 0.0;
    for it in 0..nt {
        for ip in 0..np {
            let mut p = 0.0f64;
            let k = 8;
            for a in 0..k {
                for b in 0..k {
                    let t = (it as f64 + (a as f64 + 0.5) / k as f64) * std::f64::consts::FRAC_PI_2
                        / nt as f64;
                    let ph = (ip as f64 + (b as f64 + 0.5) / k as f64) * 2.0 * std::f64::consts::PI
                        / np as f64;
                    let wi = Vec3::new(
                        (t.sin() * ph.cos()) as f32,
                        (t.sin() * ph.sin()) as f32,
                        t.cos() as f32,
                    );
                    let dw = t.sin()
                        * (std::f64::consts::FRAC_PI_2 / nt as f64)
                        * (2.0 * std::f64::consts::PI / np as f64)
                        / (k * k) as f64;
                    p += m.pdf(wo, wi) as f64 * dw;
                }
            }
            let e = p * n as f64;
            chi2 += (hist[it * np + ip] - e).powi(2) / e;
        }
    }
    // 199 degrees of freedom: mean 199, sd 20; 300 is beyond 5 sd.
    assert!(chi2 < 300.0, "chi2 = {chi2}");
}

#[test]
fn dielectric_reflection_and_refraction_frequencies_follow_fresnel() {
    let m = Material::Dielectric { eta: 1.5 };
    let wo = Vec3::new(0.8, 0.0, 0.6);
    let r = fresnel::dielectric(0.6, 1.5);
    let mut rng = Pcg32::new(9, 0);
    let n = 50_000;
    let reflected = (0..n)
        .filter(|_| {
            m.sample(wo, rng.uniform(), Vec2::ZERO, TransportMode::Radiance)
                .unwrap()
                .wi
                .z
                > 0.0
        })
        .count();
    let sd = (r * (1.0 - r) / n as f32).sqrt();
    assert!((reflected as f32 / n as f32 - r).abs() < 5.0 * sd);
}

/// Radiance transport through a glass slab: entering scales by 1/eta^2, leaving by eta^2,
/// so the round trip carries weight T_in * T_out exactly (no net gain).
#[test]
fn refraction_radiance_scaling_cancels_on_a_round_trip() {
    let m = Material::Dielectric { eta: 1.5 };
    let wo = Vec3::new(0.0, 0.0, 1.0);
    let s_in = m
        .sample(wo, 0.99, Vec2::ZERO, TransportMode::Radiance)
        .unwrap();
    let w_in = s_in.f.r * s_in.wi.z.abs() / s_in.pdf;
    assert!((w_in - 1.0 / 2.25).abs() < 1e-5);
    let s_out = m.sample(-s_in.wi * -1.0, 0.99, Vec2::ZERO, TransportMode::Radiance);
    let s_out = s_out.unwrap();
    let w_out = s_out.f.r * s_out.wi.z.abs() / s_out.pdf;
    assert!((w_in * w_out - 1.0).abs() < 1e-5, "{w_in} {w_out}");
}
