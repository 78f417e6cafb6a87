//! The rough (Trowbridge–Reitz microfacet) conductor and dielectric: sampling against
//! their pdf by Pearson's chi-square test (`radiant_testkit::chi2`) at several
//! roughnesses, anisotropic ones included, and incidence angles down to grazing, from
//! both sides of the dielectric; the visible normals themselves in slope space, down
//! to near-mirror roughness; every sample's value and pdf against `eval` and `pdf`;
//! reciprocity (with the η² rule of refraction); energy: the directional albedo is at
//! most 1 and equals a brute-force integral of f |cos|, and a white rough conductor
//! loses exactly the single-scattering energy that the microfacet integral predicts.

use glam::{Vec2, Vec3};
use radiant_math::color::Rgb;
use radiant_math::hash::Pcg32;
use radiant_render::material::{
    ConductorFresnel, Material, TransportMode, TrowbridgeReitz, fresnel,
};
use radiant_scene::{ConductorDesc, MaterialDesc};
use radiant_testkit::chi2::{ChiSquareReport, ChiSquareTest, Domain};
use std::f64::consts::TAU;

/// Family-wise significance of the file's chi-square tests (Šidák-corrected per test).
const ALPHA: f64 = 0.01;
/// The BSDFs' chi-square tests: 4 roughnesses x 3 directions for the conductor, 4 x 5
/// for the dielectric (the visible normals' test counts its own).
const CHI2_TESTS: u32 = 32;
const SAMPLES: u64 = 200_000;

/// Roughnesses of the chi-square tests: (alpha_x, alpha_y).
const ALPHAS: [(f32, f32); 4] = [(0.1, 0.1), (0.5, 0.5), (0.05, 0.4), (0.8, 0.2)];

fn check(report: &ChiSquareReport) {
    report.check(ALPHA, CHI2_TESTS);
}

fn direction(cos_theta: f32, phi: f32) -> Vec3 {
    let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
}

fn conductor(ax: f32, ay: f32, fresnel: ConductorFresnel) -> Material {
    Material::RoughConductor {
        fresnel,
        distribution: TrowbridgeReitz::new(ax, ay),
    }
}

fn copper() -> ConductorFresnel {
    ConductorFresnel::Complex {
        eta: Rgb::new(0.200438, 0.924033, 1.10221),
        k: Rgb::new(3.91295, 2.45285, 2.14219),
    }
}

fn dielectric(ax: f32, ay: f32, eta: f32) -> Material {
    Material::RoughDielectric {
        eta,
        distribution: TrowbridgeReitz::new(ax, ay),
    }
}

fn rel_close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1e-6)
}

/// Chi-square of `material.sample` from `wo` against `material.pdf`; each sample's
/// value must also equal `eval_mode` there.
fn chi2_of(name: &str, material: Material, wo: Vec3, mode: TransportMode, seed: u64) {
    let report = ChiSquareTest::new(name, Domain::Sphere)
        .samples(SAMPLES)
        .seed(seed)
        .run_with_pdf(
            |u| {
                let bs = material.sample(wo, u.u1, u.u2, mode)?;
                let f = material.eval_mode(wo, bs.wi, mode);
                assert!(!bs.specular, "{name}: a rough lobe is not a delta");
                assert!(
                    rel_close(bs.f.r, f.r, 2e-3) && rel_close(bs.f.b, f.b, 2e-3),
                    "{name}: sample f {:?} vs eval {f:?} at {}",
                    bs.f,
                    bs.wi
                );
                Some((bs.wi, bs.pdf))
            },
            |wi| material.pdf(wo, wi),
        );
    check(&report);
    assert!(
        report.pdf_integral <= 1.0 + 2e-3,
        "{name}: pdf integral {}",
        report.pdf_integral
    );
    assert!(report.pdf_mismatches == 0, "{name}: {report:?}");
}

#[test]
fn rough_conductor_sampling_matches_its_pdf() {
    let wos = [
        ("near normal", direction(0.95, 0.4)),
        ("oblique", direction(0.5, 2.0)),
        ("grazing", direction(0.05, 4.0)),
    ];
    let mut seed = 0;
    for (ax, ay) in ALPHAS {
        for (which, wo) in wos {
            seed += 1;
            let m = conductor(ax, ay, copper());
            let name = format!("conductor {ax}/{ay} {which}");
            chi2_of(&name, m, wo, TransportMode::Radiance, seed);
        }
    }
}

#[test]
fn rough_dielectric_sampling_matches_its_pdf_from_both_sides() {
    // From inside, cos 0.6 lies beyond the critical angle of eta 1.5 (cos 0.745):
    // rough total internal reflection.
    let wos = [
        (
            "outside, near normal",
            direction(0.9, 0.4),
            TransportMode::Radiance,
        ),
        (
            "outside, grazing",
            direction(0.05, 1.0),
            TransportMode::Importance,
        ),
        (
            "inside, near normal",
            -direction(0.95, 2.5),
            TransportMode::Radiance,
        ),
        (
            "inside, beyond critical",
            -direction(0.6, 3.5),
            TransportMode::Importance,
        ),
        (
            "inside, grazing",
            -direction(0.08, 5.0),
            TransportMode::Radiance,
        ),
    ];
    let mut seed = 100;
    for (ax, ay) in ALPHAS {
        for (which, wo, mode) in wos {
            seed += 1;
            let name = format!("dielectric {ax}/{ay} {which}");
            chi2_of(&name, dielectric(ax, ay, 1.5), wo, mode, seed);
        }
    }
}

/// Midpoint quadrature of g over the sphere in (θ, φ) with the sin θ Jacobian:
/// uniform in angle, so a narrow lobe at the pole spans as many bins as elsewhere
/// (bins of π/(2n) ≈ 0.5 mrad for n = 3000, against lobes of alpha ≥ 0.05 rad).
fn sphere_integral(n: usize, g: impl Fn(Vec3) -> f64) -> f64 {
    let (nt, np) = (2 * n, n / 2);
    let (dt, dp) = (std::f64::consts::PI / nt as f64, TAU / np as f64);
    let mut sum = 0.0;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) * dt;
        let (st, ct) = theta.sin_cos();
        for j in 0..np {
            let (sp, cp) = ((j as f64 + 0.5) * dp).sin_cos();
            let w = Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32);
            sum += g(w) * st;
        }
    }
    sum * dt * dp
}

/// Mean and standard error of the sample weights f |cos| / pdf (one channel).
fn sampled_albedo(material: &Material, wo: Vec3, mode: TransportMode, n: u32) -> (f64, f64) {
    let mut rng = Pcg32::new(9, 17);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = Vec2::new(rng.uniform(), rng.uniform());
        if let Some(bs) = material.sample(wo, rng.uniform(), u, mode) {
            let w = (bs.f.g * bs.wi.z.abs() / bs.pdf) as f64;
            s += w;
            s2 += w * w;
        }
    }
    let mean = s / n as f64;
    (mean, ((s2 / n as f64 - mean * mean) / n as f64).sqrt())
}

#[test]
fn albedo_is_at_most_one_and_equals_the_integral_of_f_cos() {
    let cases = [
        (
            "conductor copper 0.3",
            conductor(0.3, 0.3, copper()),
            direction(0.7, 0.3),
        ),
        (
            "conductor white 0.5",
            conductor(0.5, 0.5, ConductorFresnel::Constant(Rgb::WHITE)),
            direction(0.2, 1.0),
        ),
        (
            "conductor white 0.05/0.4",
            conductor(0.05, 0.4, ConductorFresnel::Constant(Rgb::WHITE)),
            direction(0.6, 0.8),
        ),
        (
            "dielectric 0.3 outside",
            dielectric(0.3, 0.3, 1.5),
            direction(0.8, 0.2),
        ),
        (
            "dielectric 0.6 outside grazing",
            dielectric(0.6, 0.6, 1.5),
            direction(0.1, 2.2),
        ),
        (
            "dielectric 0.3 inside",
            dielectric(0.3, 0.3, 1.5),
            -direction(0.9, 1.2),
        ),
        (
            "dielectric 0.5/0.1 inside",
            dielectric(0.5, 0.1, 1.33),
            -direction(0.5, 4.0),
        ),
    ];
    for (name, m, wo) in cases {
        // Importance transport: the albedo is the fraction of power scattered, which
        // a passive surface keeps at or below 1 (radiance picks up η² on refraction).
        let mode = TransportMode::Importance;
        let integral =
            sphere_integral(1500, |wi| (m.eval_mode(wo, wi, mode).g * wi.z.abs()) as f64);
        let (mc, se) = sampled_albedo(&m, wo, mode, 400_000);
        println!("{name}: quadrature {integral:.5}, sampled {mc:.5} ± {se:.5}");
        assert!(mc <= 1.0 + 4.0 * se && integral <= 1.0 + 1e-3, "{name}");
        assert!(
            (integral - mc).abs() < 4.0 * se + 2e-3 * integral,
            "{name}: quadrature {integral} vs sampled {mc} ± {se}"
        );
    }
}

/// The single-scattering albedo of a white (F = 1) microfacet conductor written over
/// microfacet normals instead of incident directions: E(wo) = ∫ D_wo(m) G2 / G1(wo) dm,
/// with wi the reflection of wo about m. Quadrature over m checks the Jacobian of the
/// half-vector map and the masking independently of the BSDF code's integration over wi.
fn white_albedo_over_normals(d: &TrowbridgeReitz, wo: Vec3) -> f64 {
    sphere_integral(1500, |m| {
        if m.z <= 0.0 {
            return 0.0;
        }
        let wi = 2.0 * wo.dot(m) * m - wo;
        if wi.z <= 0.0 {
            return 0.0;
        }
        (d.d_visible(wo, m) * d.g(wo, wi) / d.g1(wo)) as f64
    })
}

#[test]
fn white_rough_conductor_loses_only_single_scattering_energy() {
    let white = ConductorFresnel::Constant(Rgb::WHITE);
    let mut previous_loss = 0.0;
    for alpha in [0.05f32, 0.2, 0.5, 1.0] {
        let d = TrowbridgeReitz::new(alpha, alpha);
        let m = conductor(alpha, alpha, white);
        for wo in [
            direction(1.0, 0.0),
            direction(0.5, 1.0),
            direction(0.15, 2.0),
        ] {
            let expected = white_albedo_over_normals(&d, wo);
            let integral = sphere_integral(1500, |wi| (m.eval(wo, wi).g * wi.z.max(0.0)) as f64);
            let (mc, se) = sampled_albedo(&m, wo, TransportMode::Radiance, 200_000);
            println!(
                "alpha {alpha}, cos {:.2}: over normals {expected:.5}, over wi {integral:.5}, sampled {mc:.5} ± {se:.5}",
                wo.z
            );
            assert!(expected <= 1.0 && expected > 0.3);
            assert!((integral - expected).abs() < 3e-3, "alpha {alpha} wo {wo}");
            assert!(
                (mc - expected).abs() < 4.0 * se + 1e-3,
                "alpha {alpha} wo {wo}"
            );
            if wo.z == 1.0 {
                // The loss (multiple scattering left out) grows with roughness and
                // vanishes for a smooth surface.
                let loss = 1.0 - expected;
                assert!(loss >= previous_loss, "alpha {alpha}: loss {loss}");
                if alpha == 0.05 {
                    assert!(loss < 5e-3, "loss {loss}");
                }
                previous_loss = loss;
            }
        }
    }
    // Closed form at alpha = 1, normal incidence: D(m) = 1/π, so m is cosine-
    // distributed; wi = reflect(z, m) has θi = 2θm and survives for θm < 45°, with
    // G2/G1 = 2 cos θi / (1 + cos θi). With u = cos 2θm the albedo is
    // ∫0^1 u / (1 + u) du = 1 − ln 2.
    let closed = 1.0 - std::f64::consts::LN_2;
    assert!(
        (1.0 - previous_loss - closed).abs() < 1e-4,
        "alpha 1: {} vs 1 - ln 2 = {closed}",
        1.0 - previous_loss
    );
}

#[test]
fn reciprocity_and_the_eta_squared_rule() {
    let mut rng = Pcg32::new(5, 11);
    let mut random_dir = || {
        let c = 2.0 * rng.uniform() - 1.0;
        direction(c, std::f32::consts::TAU * rng.uniform())
    };
    let c = conductor(0.3, 0.1, copper());
    let eta = 1.5f32;
    let g = dielectric(0.4, 0.2, eta);
    let (mut reflections, mut transmissions) = (0, 0);
    for _ in 0..20_000 {
        let (wo, wi) = (random_dir(), random_dir());
        // f32 cancellation at grazing angles (the half vector of nearly opposite
        // directions) is not what this test is about.
        if wo.z.abs() < 0.02 || wi.z.abs() < 0.02 {
            continue;
        }
        let (a, b) = (c.eval(wo, wi), c.eval(wi, wo));
        assert!(
            rel_close(a.r, b.r, 1e-4) && rel_close(a.b, b.b, 1e-4),
            "{wo} {wi}"
        );
        let fwd = g.eval_mode(wo, wi, TransportMode::Radiance).g;
        let rev = g.eval_mode(wi, wo, TransportMode::Radiance).g;
        // Adjoint: importance transport is radiance transport with the roles swapped.
        let adj = g.eval_mode(wo, wi, TransportMode::Importance).g;
        // 1 - F loses digits where a direction grazes the microfacet (the other one
        // then lies at the critical angle, where F has an infinite slope): 1 %, or
        // 1e-4 absolute against lobe peaks of order 1, is far below the factor
        // η² = 2.25 that a wrong rule would give.
        assert!(
            rel_close(adj, rev, 1e-2) || (adj - rev).abs() < 1e-4,
            "{wo} {wi}: {adj} vs {rev}"
        );
        if wo.z * wi.z > 0.0 {
            assert!(rel_close(fwd, rev, 1e-4), "{wo} {wi}");
            reflections += (fwd > 0.0) as u32;
        } else {
            // Veach 1997, eq. 5.14: f(wo, wi) / η_o² = f(wi, wo) / η_i², η the index
            // on each direction's side.
            let side = |w: Vec3| if w.z > 0.0 { 1.0 } else { eta };
            let (n_o, n_i) = (side(wo), side(wi));
            let (a, b) = (fwd / (n_o * n_o), rev / (n_i * n_i));
            assert!(
                rel_close(a, b, 1e-2) || (a - b).abs() < 1e-4,
                "{wo} {wi}: {fwd} {rev}"
            );
            transmissions += (fwd > 0.0) as u32;
        }
    }
    assert!(
        reflections > 1000 && transmissions > 1000,
        "{reflections} {transmissions}"
    );
}

#[test]
fn tiny_alpha_stays_a_delta_and_approaches_the_smooth_bsdf() {
    let desc = |a: f32| MaterialDesc::RoughDielectric {
        eta: 1.5,
        alpha_u: a,
        alpha_v: a,
    };
    assert_eq!(
        Material::from_desc(&desc(5e-4)),
        Material::Dielectric { eta: 1.5 }
    );
    let cond = MaterialDesc::RoughConductor {
        conductor: ConductorDesc::Reflectance(Rgb::splat(0.8)),
        alpha_u: 9e-4,
        alpha_v: 1e-4,
    };
    assert!(Material::from_desc(&cond).is_specular());
    let rough = Material::from_desc(&desc(0.01));
    assert!(!rough.is_specular());
    // alpha 0.01: a very narrow lobe; the reflected fraction of the samples equals
    // the smooth Fresnel reflectance, and all weights stay finite.
    let wo = direction(0.6, 0.0);
    let mut rng = Pcg32::new(1, 2);
    let (mut reflected, mut lost, n) = (0u32, 0u32, 100_000);
    for _ in 0..n {
        let u = Vec2::new(rng.uniform(), rng.uniform());
        // GGX's long tails send a few samples below the horizon (no sample).
        let Some(bs) = rough.sample(wo, rng.uniform(), u, TransportMode::Radiance) else {
            lost += 1;
            continue;
        };
        let w = bs.f.g * bs.wi.z.abs() / bs.pdf;
        assert!(w.is_finite() && w > 0.0 && w < 1.5, "{w}");
        reflected += (bs.wi.z > 0.0) as u32;
    }
    assert!(lost < 20, "{lost} of {n} samples lost");
    let r = fresnel::dielectric(0.6, 1.5) as f64;
    let p = reflected as f64 / n as f64;
    assert!(
        (p - r).abs() < 4.0 * (r * (1.0 - r) / n as f64).sqrt() + 2e-3,
        "{p} vs {r}"
    );
}

#[test]
fn reflectance_conductor_has_that_reflectance_at_normal_incidence() {
    let fr = ConductorFresnel::from_reflectance(Rgb::new(0.1, 0.5, 0.95));
    let r = fr.eval(1.0);
    assert!((r.r - 0.1).abs() < 1e-4 && (r.g - 0.5).abs() < 1e-4 && (r.b - 0.95).abs() < 1e-4);
    assert!(fr.eval(0.05).r > r.r);
}

/// Visible normals against their density in slope space, where even a lobe of
/// α = 0.002 spreads over the grid: the point p of the unit square stands for the
/// normal m = normalize(αx sx, αy sy, 1) of slopes (sx, sy) = tan(π (p − ½)), so that
/// the density of p is D_w(m) · αx αy cos³θm · π² (1 + sx²)(1 + sy²). Roughnesses from
/// near-mirror to anisotropic, incidence from normal to grazing and from below.
#[test]
fn visible_normals_follow_their_density_in_slope_space() {
    use std::f64::consts::PI;
    let alphas = [(0.002, 0.002), (0.01, 0.01), (0.01, 0.3), (0.5, 0.5)];
    let ws = [
        direction(0.95, 0.4),
        direction(0.5, 2.0),
        direction(0.05, 4.0),
        -direction(0.7, 5.0),
    ];
    let tests = (alphas.len() * ws.len()) as u32;
    let mut seed = 100;
    for (ax, ay) in alphas {
        let d = TrowbridgeReitz::new(ax, ay);
        let (ax, ay) = (ax as f64, ay as f64);
        let to_square = |s: f64| (0.5 + s.atan() / PI) as f32;
        let to_slope = |x: f32| (PI * (x as f64 - 0.5)).tan();
        for w in ws {
            seed += 1;
            let square = Domain::Rectangle {
                min: Vec2::ZERO,
                max: Vec2::ONE,
            };
            let report = ChiSquareTest::new(format!("visible normals {ax}/{ay} from {w}"), square)
                .samples(1_000_000)
                .seed(seed)
                .resolution(64, 64)
                .run(
                    |u| {
                        let m = d.sample_visible(w, u.u2).as_dvec3();
                        Some(Vec2::new(
                            to_square(m.x / (ax * m.z)),
                            to_square(m.y / (ay * m.z)),
                        ))
                    },
                    |p: Vec2| {
                        let (sx, sy) = (to_slope(p.x), to_slope(p.y));
                        if !(sx.is_finite() && sy.is_finite()) {
                            return 0.0;
                        }
                        let v = glam::DVec3::new(ax * sx, ay * sy, 1.0);
                        let cos = 1.0 / v.length();
                        let jacobian =
                            ax * ay * cos.powi(3) * PI * PI * (1.0 + sx * sx) * (1.0 + sy * sy);
                        d.d_visible(w, (v * cos).as_vec3()) as f64 * jacobian
                    },
                );
            report.check(ALPHA, tests);
        }
    }
}
