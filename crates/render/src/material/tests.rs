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

// Chi-square tests of the sampling routines, with the shared harness, are in
// tests/bsdf_sampling.rs.

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

/// Callers skip drawing the lobe-choice number of materials that say they do not read
/// it, and pass 0 instead: for those, no value of it may change a sample. The materials
/// that do read it must show it (else the flag costs draws for nothing).
#[test]
fn the_lobe_sample_flag_says_which_materials_read_it() {
    let grey = Rgb::splat(0.5);
    let descs = [
        MaterialDesc::Diffuse { reflectance: grey },
        MaterialDesc::Conductor(ConductorDesc::Reflectance(Rgb::splat(0.9))),
        MaterialDesc::Dielectric { eta: 1.5 },
        MaterialDesc::RoughConductor {
            conductor: ConductorDesc::Reflectance(Rgb::splat(0.9)),
            alpha_u: 0.3,
            alpha_v: 0.1,
        },
        MaterialDesc::RoughDielectric {
            eta: 1.5,
            alpha_u: 0.3,
            alpha_v: 0.3,
        },
        MaterialDesc::ThinDielectric { eta: 1.5 },
        MaterialDesc::DiffuseTransmission {
            reflectance: grey,
            transmittance: grey,
        },
    ];
    let mut materials: Vec<Material> = descs.iter().map(Material::from_desc).collect();
    materials.push(Material::Conductor {
        eta: Rgb::splat(0.2),
        k: Rgb::splat(3.9),
    });
    materials.push(Material::Interface);
    let mut rng = Pcg32::new(11, 0);
    for m in materials {
        let mut differs = false;
        for _ in 0..200 {
            let wo = random_dir(&mut rng);
            let u2 = Vec2::new(rng.uniform(), rng.uniform());
            let sample = |u1: f32| {
                m.sample(wo, u1, u2, TransportMode::Radiance)
                    .map(|s| (s.wi, s.f, s.pdf, s.specular))
            };
            let at_zero = sample(0.0);
            for u1 in [0.03f32, 0.5, 0.97] {
                if sample(u1) != at_zero {
                    differs = true;
                    assert!(m.uses_lobe_sample(), "{m:?} reads u1 but says it does not");
                }
            }
        }
        assert_eq!(differs, m.uses_lobe_sample(), "{m:?}");
    }
}
