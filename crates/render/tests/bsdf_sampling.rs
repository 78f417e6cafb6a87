//! BSDF sampling against the BSDFs, by Pearson's chi-square test
//! (`radiant_testkit::chi2`): the diffuse lobe's sampled directions against its pdf
//! over the whole sphere (a sample on the wrong side fails), from several outgoing
//! directions including grazing ones on both sides; each sample's `f` and `pdf` against
//! `eval` and `pdf`. Delta lobes have no density: their directions are checked exactly
//! (mirror reflection, Snell's law), their weights f |cos| / pdf against Fresnel
//! reflectances computed here independently of `fresnel.rs` (the angle form of the
//! Fresnel equations for dielectrics, complex arithmetic for conductors; Born & Wolf,
//! *Principles of Optics*, §1.5.2 and §14.2), and the dielectric's choice between
//! reflection and refraction by a chi-square test of its frequencies against R and 1 - R.

use glam::{Vec2, Vec3};
use radiant_math::color::Rgb;
use radiant_math::hash::Pcg32;
use radiant_render::material::{BsdfSample, Material, TransportMode};
use radiant_testkit::chi2::{ChiSquareReport, ChiSquareTest, Domain};

/// Family-wise significance of the whole file (Šidák over CHI2_TESTS).
const ALPHA: f64 = 0.01;
/// Every chi-square test in this file: 5 of the diffuse lobe, 11 of the dielectric's choice.
const CHI2_TESTS: u32 = 16;
const SAMPLES: u64 = 200_000;

fn check(report: &ChiSquareReport) {
    report.check(ALPHA, CHI2_TESTS);
}

/// The unit direction with polar cosine `cos_theta` and azimuth `phi` in the shading
/// frame (normal +z).
fn direction(cos_theta: f32, phi: f32) -> Vec3 {
    let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
}

/// The path weight f |cos θi| / pdf of a sample, per channel.
fn weight(s: &BsdfSample) -> Rgb {
    s.f * (s.wi.z.abs() / s.pdf)
}

fn close(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() <= tolerance * a.abs().max(b.abs()).max(1.0)
}

fn close_rgb(a: Rgb, b: Rgb, tolerance: f32) -> bool {
    close(a.r, b.r, tolerance) && close(a.g, b.g, tolerance) && close(a.b, b.b, tolerance)
}

/// Lambertian sampling from outgoing directions above and below the surface, normal and
/// grazing: the directions follow `pdf` over the whole sphere (so a sample on the wrong
/// side fails), the claimed pdf is `pdf`'s, f is `eval`'s and the weight is the albedo.
#[test]
fn diffuse_sampling_follows_its_pdf_from_every_side() {
    let albedo = Rgb::new(0.8, 0.5, 0.2);
    let m = Material::Diffuse { albedo };
    let cases = [
        ("diffuse_normal", 1.0, 0.0),
        ("diffuse_oblique", 0.4, 2.0),
        ("diffuse_grazing", 1e-3, 4.0),
        ("diffuse_below", -0.6, 1.0),
        ("diffuse_below_grazing", -1e-3, 5.5),
    ];
    for (seed, (name, cos_o, phi)) in cases.into_iter().enumerate() {
        let wo = direction(cos_o, phi);
        let mut bad: Vec<String> = Vec::new();
        let report = ChiSquareTest::new(name, Domain::Sphere)
            .samples(SAMPLES)
            .seed(seed as u64 + 1)
            .run_with_pdf(
                |u| {
                    let mode = if u.u1 < 0.5 {
                        TransportMode::Radiance
                    } else {
                        TransportMode::Importance
                    };
                    let s = m.sample(wo, u.u1, u.u2, mode)?;
                    if s.specular || s.f != m.eval(wo, s.wi) || !close_rgb(weight(&s), albedo, 1e-5)
                    {
                        bad.push(format!("{s:?}"));
                    }
                    Some((s.wi, s.pdf))
                },
                |wi| m.pdf(wo, wi),
            );
        assert!(
            bad.is_empty(),
            "{name}: {} samples with f != eval or weight != albedo, e.g. {}",
            bad.len(),
            bad[0]
        );
        check(&report);
        // Lambertian sampling is exact: the pdf integrates to 1 over the sphere.
        assert!((report.pdf_integral - 1.0).abs() < 1e-3, "{name}");
    }
}

/// No material samples a direction for an outgoing direction in the surface's plane
/// (its cosine, and every weight, would be undefined).
#[test]
fn no_sample_for_an_outgoing_direction_in_the_plane() {
    let materials = [
        Material::Diffuse { albedo: Rgb::WHITE },
        Material::Mirror {
            reflectance: Rgb::WHITE,
        },
        Material::Conductor {
            eta: Rgb::splat(0.2),
            k: Rgb::splat(3.0),
        },
        Material::Dielectric { eta: 1.5 },
        Material::ThinDielectric { eta: 1.5 },
        Material::DiffuseTransmission {
            reflectance: Rgb::splat(0.5),
            transmittance: Rgb::splat(0.5),
        },
        Material::Interface,
    ];
    for m in materials {
        let s = m.sample(
            Vec3::new(0.6, 0.8, 0.0),
            0.3,
            Vec2::new(0.2, 0.7),
            TransportMode::Radiance,
        );
        assert!(s.is_none(), "{m:?}: {s:?}");
    }
}

/// Fresnel reflectance of a dielectric interface from the angle form of the Fresnel
/// equations (f64): R_s = sin²(θi − θt) / sin²(θi + θt), R_p = tan²(θi − θt) / tan²(θi + θt),
/// with Snell's law n_i sin θi = n_t sin θt; 1 beyond the critical angle.
fn fresnel_dielectric_reference(cos_i: f64, n_i: f64, n_t: f64) -> f64 {
    let theta_i = cos_i.abs().min(1.0).acos();
    let sin_t = n_i / n_t * theta_i.sin();
    if sin_t >= 1.0 {
        return 1.0;
    }
    if theta_i < 1e-6 {
        // Normal incidence, where both ratios are 0/0: ((n_i - n_t) / (n_i + n_t))².
        return ((n_i - n_t) / (n_i + n_t)).powi(2);
    }
    let theta_t = sin_t.asin();
    let rs = ((theta_i - theta_t).sin() / (theta_i + theta_t).sin()).powi(2);
    let rp = ((theta_i - theta_t).tan() / (theta_i + theta_t).tan()).powi(2);
    0.5 * (rs + rp)
}

/// Where a sample of a dielectric goes: the reflected and the refracted lobe, as points
/// 0.5 and 1.5 of the interval [0, 2], whose halves are tested against R and 1 - R.
const REFLECTED: f32 = 0.5;
const REFRACTED: f32 = 1.5;

/// Checks one dielectric sample exactly and says which lobe it took: the mirror
/// direction with weight 1 and pdf R, or Snell's direction, on the other side, with
/// pdf 1 - R and weight (n_o / n_t)² for radiance, 1 for importance (Veach 1997, §5.2).
fn dielectric_lobe(
    wo: Vec3,
    eta: f32,
    r: f64,
    s: &BsdfSample,
    mode: TransportMode,
) -> Result<f32, String> {
    let m = Material::Dielectric { eta };
    let fail = |why: &str| Err(format!("wo {wo}, eta {eta}, {mode:?}: {why}: {s:?}"));
    if !s.specular || m.eval(wo, s.wi) != Rgb::BLACK || m.pdf(wo, s.wi) != 0.0 {
        return fail("a delta lobe must be flagged specular and evaluate to zero");
    }
    if !s.f.r.is_finite() || s.f.r != s.f.g || s.f.g != s.f.b {
        return fail("a dielectric is grey");
    }
    let w = weight(s).g;
    if s.wi.z * wo.z > 0.0 {
        if s.wi != Vec3::new(-wo.x, -wo.y, wo.z) {
            return fail("not the mirror direction");
        }
        if !close(s.pdf, r as f32, 1e-4) || !close(w, 1.0, 1e-5) {
            return fail(&format!("reflection needs pdf R = {r} and weight 1"));
        }
        return Ok(REFLECTED);
    }
    let (n_o, n_t) = if wo.z > 0.0 { (1.0, eta) } else { (eta, 1.0) };
    // Snell: the tangential component shrinks by n_o / n_t and turns to the other side.
    let tangential = -Vec2::new(wo.x, wo.y) * (n_o / n_t);
    if (Vec2::new(s.wi.x, s.wi.y) - tangential).length() > 1e-5
        || (s.wi.length() - 1.0).abs() > 1e-5
        || s.wi.z * wo.z >= 0.0
    {
        return fail(&format!(
            "not the refracted direction (tangential part {tangential})"
        ));
    }
    let expected = match mode {
        TransportMode::Radiance => (n_o / n_t) * (n_o / n_t),
        TransportMode::Importance => 1.0,
    };
    if !close(s.pdf, (1.0 - r) as f32, 1e-4) || !close(w, expected, 1e-5) {
        return fail(&format!(
            "refraction needs pdf 1 - R = {} and weight {expected}",
            1.0 - r
        ));
    }
    Ok(REFRACTED)
}

/// The smooth dielectric from outside and inside, at normal, oblique and grazing
/// incidence, just below the critical angle, and with an index below 1 (a bubble): every
/// sample is exact ([`dielectric_lobe`]) and the lobes are chosen with frequencies R and
/// 1 - R (chi-square over the two outcomes).
#[test]
fn dielectric_chooses_reflection_and_refraction_by_fresnel() {
    // Cosines from the inside are negative; cos_c = sqrt(1 - 1/1.5²) = 0.7454 is the
    // critical cosine of glass, so -0.75 refracts within a degree of grazing.
    let cases: [(&str, f32, f32); 11] = [
        ("glass_normal", 1.5, 1.0),
        ("glass_oblique", 1.5, 0.7),
        ("glass_steep", 1.5, 0.2),
        ("glass_grazing", 1.5, 0.01),
        ("glass_inside_normal", 1.5, -1.0),
        ("glass_inside_oblique", 1.5, -0.9),
        ("glass_inside_near_critical", 1.5, -0.75),
        ("water_oblique", 1.33, 0.5),
        ("water_grazing", 1.33, 0.05),
        ("water_inside", 1.33, -0.8),
        ("bubble_oblique", 0.75, 0.9),
    ];
    for (seed, (name, eta, cos_o)) in cases.into_iter().enumerate() {
        let wo = direction(cos_o, 0.3 + seed as f32);
        let (n_o, n_t) = if cos_o > 0.0 { (1.0, eta) } else { (eta, 1.0) };
        let r = fresnel_dielectric_reference(cos_o as f64, n_o as f64, n_t as f64);
        assert!(r < 1.0, "{name}: a test case beyond the critical angle");
        let m = Material::Dielectric { eta };
        let mut bad: Vec<String> = Vec::new();
        let report = ChiSquareTest::new(name, Domain::Interval { min: 0.0, max: 2.0 })
            .resolution(2, 1)
            .samples(SAMPLES)
            .seed(100 + seed as u64)
            .run(
                |u| {
                    let mode = if u.u2.x < 0.5 {
                        TransportMode::Radiance
                    } else {
                        TransportMode::Importance
                    };
                    let Some(s) = m.sample(wo, u.u1, u.u2, mode) else {
                        bad.push("no sample".into());
                        return None;
                    };
                    dielectric_lobe(wo, eta, r, &s, mode)
                        .map_err(|e| bad.push(e))
                        .ok()
                },
                |x: f32| if x < 1.0 { r } else { 1.0 - r },
            );
        assert!(
            bad.is_empty(),
            "{name}: {} bad samples, e.g. {}",
            bad.len(),
            bad[0]
        );
        check(&report);
    }
}

/// Beyond the critical angle (from inside glass, or from outside a medium of lower
/// index) every sample is the mirror direction with pdf 1 and weight 1.
#[test]
fn dielectric_reflects_totally_beyond_the_critical_angle() {
    let cases = [
        (1.5f32, -0.74f32),
        (1.5, -0.3),
        (1.5, -1e-3),
        (1.0 / 1.5, 0.5),
    ];
    let mut rng = Pcg32::new(17, 3);
    for (eta, cos_o) in cases {
        let (n_o, n_t) = if cos_o > 0.0 { (1.0, eta) } else { (eta, 1.0) };
        assert_eq!(
            fresnel_dielectric_reference(cos_o as f64, n_o as f64, n_t as f64),
            1.0
        );
        let m = Material::Dielectric { eta };
        for i in 0..2000 {
            let wo = direction(cos_o, rng.uniform() * std::f32::consts::TAU);
            let mode = if i % 2 == 0 {
                TransportMode::Radiance
            } else {
                TransportMode::Importance
            };
            // u1 up to just below 1: even the last lobe number must reflect.
            let u1 = if i == 0 {
                radiant_math::ONE_MINUS_EPSILON
            } else {
                rng.uniform()
            };
            let s = m
                .sample(wo, u1, Vec2::new(rng.uniform(), rng.uniform()), mode)
                .expect("a dielectric always samples");
            let lobe = dielectric_lobe(wo, eta, 1.0, &s, mode).unwrap();
            assert_eq!(lobe, REFLECTED, "eta {eta}, cos {cos_o}: refracted");
        }
    }
}

/// A complex number, just enough for the conductor's Fresnel equations.
#[derive(Clone, Copy)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn new(re: f64, im: f64) -> Complex {
        Complex { re, im }
    }
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Complex) -> Complex {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// The principal square root (non-negative real part).
    fn sqrt(self) -> Complex {
        let m = self.norm2().sqrt();
        let re = (0.5 * (m + self.re)).max(0.0).sqrt();
        let im = (0.5 * (m - self.re)).max(0.0).sqrt().copysign(self.im);
        Complex::new(re, im)
    }
}

/// Unpolarised reflectance of a conductor of complex index n + ik from the complex
/// Fresnel amplitudes r_s = (cos θ - w) / (cos θ + w), r_p = (n̂² cos θ - w) / (n̂² cos θ + w),
/// w = sqrt(n̂² - sin² θ) (the transmitted cosine times n̂).
fn fresnel_conductor_reference(cos_i: f64, n: f64, k: f64) -> f64 {
    let c = Complex::new(cos_i.abs().min(1.0), 0.0);
    let n2 = Complex::new(n, k).mul(Complex::new(n, k));
    let w = n2.sub(Complex::new(1.0 - c.re * c.re, 0.0)).sqrt();
    let ratio = |a: Complex, b: Complex| a.norm2() / b.norm2();
    let rs = ratio(c.sub(w), c.add(w));
    let rp = ratio(n2.mul(c).sub(w), n2.mul(c).add(w));
    0.5 * (rs + rp)
}

/// Mirror and smooth conductors: from above and below, normal to grazing, every sample
/// is the mirror direction with pdf 1 and weight equal to the reflectance (fixed for the
/// mirror, the conductor's Fresnel reflectance per channel); `eval` and `pdf` are zero.
#[test]
fn mirror_and_conductors_reflect_exactly_with_fresnel_weight() {
    // Index data near 550 nm (gold, aluminium, copper) and a dielectric-like k = 0 case.
    let conductors = [
        (Rgb::new(0.143, 0.374, 1.442), Rgb::new(3.983, 2.385, 1.603)),
        (Rgb::new(1.66, 0.88, 0.52), Rgb::new(9.22, 6.27, 4.84)),
        (Rgb::new(0.2, 0.92, 1.1), Rgb::new(3.91, 2.45, 2.14)),
        (Rgb::splat(1.5), Rgb::BLACK),
    ];
    let mirror = Rgb::new(0.9, 0.6, 0.3);
    let cosines = [1.0f32, 0.8, 0.3, 0.05, 1e-3, -0.5, -1e-3];
    let mut rng = Pcg32::new(23, 1);
    for cos_o in cosines {
        for j in 0..50 {
            let wo = direction(cos_o, rng.uniform() * std::f32::consts::TAU);
            let u1 = rng.uniform();
            let u2 = Vec2::new(rng.uniform(), rng.uniform());
            let mode = if j % 2 == 0 {
                TransportMode::Radiance
            } else {
                TransportMode::Importance
            };
            let reflected = Vec3::new(-wo.x, -wo.y, wo.z);
            let cases = conductors
                .iter()
                .map(|&(eta, k)| {
                    let c = wo.z.abs() as f64;
                    let r = |n: f32, k: f32| fresnel_conductor_reference(c, n as f64, k as f64);
                    let expected = Rgb::new(
                        r(eta.r, k.r) as f32,
                        r(eta.g, k.g) as f32,
                        r(eta.b, k.b) as f32,
                    );
                    (Material::Conductor { eta, k }, expected)
                })
                .chain([(
                    Material::Mirror {
                        reflectance: mirror,
                    },
                    mirror,
                )]);
            for (m, expected) in cases {
                let s = m
                    .sample(wo, u1, u2, mode)
                    .expect("a mirror always reflects");
                assert_eq!(s.wi, reflected, "{m:?}, wo {wo}");
                assert!(s.specular && s.pdf == 1.0, "{m:?}: {s:?}");
                assert_eq!(m.eval(wo, s.wi), Rgb::BLACK);
                assert_eq!(m.pdf(wo, s.wi), 0.0);
                assert!(
                    close_rgb(weight(&s), expected, 2e-4),
                    "{m:?}, cos {cos_o}: weight {:?}, Fresnel {expected:?}",
                    weight(&s)
                );
            }
        }
    }
}

/// The interface (no surface) passes straight through with weight 1.
#[test]
fn interface_passes_straight_through() {
    let m = Material::Interface;
    let mut rng = Pcg32::new(29, 0);
    for _ in 0..1000 {
        let wo = radiant_math::sampling::uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        let s = m
            .sample(wo, rng.uniform(), Vec2::ZERO, TransportMode::Radiance)
            .unwrap();
        assert_eq!(s.wi, -wo);
        assert!(s.specular && s.pdf == 1.0);
        assert!(close(weight(&s).g, 1.0, 1e-6), "{s:?}");
    }
}
