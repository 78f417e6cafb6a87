//! White furnace for a rough dielectric sphere: a unit sphere of Trowbridge–Reitz glass
//! (η = 1.5, alpha 0.1, 0.3, 0.7) alone inside a uniform environment of radiance 1,
//! path traced with a deep path limit. A non-absorbing interface cannot add energy, so
//! no pixel may exceed 1 beyond noise; the microfacet model leaves out multiple
//! scattering between microfacets (Walter et al. 2007, "Microfacet models for
//! refraction through rough surfaces"), so the sphere loses exactly what its
//! single-scattering albedo deficit predicts over the interactions of each path.
//!
//! The prediction is an independent random walk written here: the sphere's geometry in
//! closed form (chords of the unit sphere), each interaction weighted by the BSDF's
//! own `eval` and `pdf` (not by the integrator's code), and the energy of one interaction
//! checked against a brute-force integral of f |cos| over the sphere of directions.

use std::path::PathBuf;

use glam::{Vec2, Vec3};
use radiant::Session;
use radiant::image::Image;
use radiant::math::Frame;
use radiant::math::hash::Pcg32;
use radiant::render::material::{Material, TransportMode};
use radiant::render::{Overrides, Progress};
use radiant::scene::{MaterialDesc, parse_file};

const RES: u32 = 32;
const HALF_WIDTH: f32 = 1.25;
const ETA: f32 = 1.5;
const MAX_DEPTH: u32 = 100;

fn scene(alpha: f32) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiant-rough-furnace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("furnace-{alpha}.pbrt"));
    std::fs::write(
        &path,
        format!(
            r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-{HALF_WIDTH} {HALF_WIDTH} -{HALF_WIDTH} {HALF_WIDTH}]
Film "rgb" "integer xresolution" {RES} "integer yresolution" {RES}
PixelFilter "box" "float xradius" 0.5 "float yradius" 0.5
Sampler "independent"
Integrator "path" "integer maxdepth" {MAX_DEPTH}
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "dielectric" "float eta" {ETA} "float roughness" {alpha} "bool remaproughness" false
Shape "sphere" "float radius" 1
"#
        ),
    )
    .unwrap();
    path
}

fn render(alpha: f32, spp: u32) -> Image {
    let desc = parse_file(&scene(alpha)).expect("scene parses");
    let session = Session::new(
        &desc,
        &Overrides {
            spp: Some(spp),
            ..Default::default()
        },
    )
    .expect("scene builds");
    session.render(&Progress::default()).film.image()
}

/// The pixels wholly on the sphere (all four corners inside its silhouette), as
/// (x, y) with their lower-left corner on the plane z = 0. The image is symmetric
/// under x → −x and y → −y, so the orientation of the raster does not matter.
fn pixels_on_sphere() -> Vec<(u32, u32, Vec2)> {
    let s = 2.0 * HALF_WIDTH / RES as f32;
    let mut out = Vec::new();
    for y in 0..RES {
        for x in 0..RES {
            let corner = Vec2::new(-HALF_WIDTH + s * x as f32, -HALF_WIDTH + s * y as f32);
            let inside = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .all(|&(dx, dy)| (corner + s * Vec2::new(dx, dy)).length() < 1.0);
            if inside {
                out.push((x, RES - 1 - y, corner));
            }
        }
    }
    out
}

/// One path of the reference walk from a camera ray that hits the unit sphere at
/// (x, y, z > 0) going down −z: the product of f_importance |cos| / pdf over its
/// interactions, where it escapes into the unit environment (0 where it is lost or
/// exceeds the path limit), and its number of interactions.
///
/// Importance-mode weights carry no η² factor; radiance-mode ones differ by
/// (η_i / η_o)² per interaction, a product that telescopes to 1 over any path that
/// enters and leaves the sphere, so both give the same pixel expectation.
fn walk(material: &Material, hit: Vec2, rng: &mut Pcg32) -> (f64, u32) {
    let mut p = Vec3::new(hit.x, hit.y, (1.0 - hit.length_squared()).max(0.0).sqrt());
    let mut d = Vec3::NEG_Z;
    let mut weight = 1.0f64;
    for depth in 1..=MAX_DEPTH {
        let n = p.normalize();
        let frame = Frame::from_normal(n);
        let wo = frame.to_local(-d);
        let u = Vec2::new(rng.uniform(), rng.uniform());
        let Some(bs) = material.sample(wo, rng.uniform(), u, TransportMode::Radiance) else {
            return (0.0, depth);
        };
        let pdf = material.pdf(wo, bs.wi);
        if pdf <= 0.0 {
            return (0.0, depth);
        }
        let f = material.eval_mode(wo, bs.wi, TransportMode::Importance).g;
        weight *= (f * bs.wi.z.abs() / pdf) as f64;
        d = frame.to_world(bs.wi).normalize();
        if d.dot(n) > 0.0 {
            // Outside a convex body every ray escapes to the environment.
            return (weight, depth);
        }
        // The chord of the unit sphere from p along d ends at p − 2 (p·d) d.
        p = (p - 2.0 * p.dot(d) * d).normalize();
    }
    (0.0, MAX_DEPTH)
}

/// ∫ f |cos θi| dωi over the whole sphere by the midpoint rule in (θ, φ), importance
/// transport (no η² factor): the single-scattering directional albedo.
fn albedo(material: &Material, wo: Vec3) -> f64 {
    let (nt, np) = (3000usize, 600usize);
    let (dt, dp) = (
        std::f64::consts::PI / nt as f64,
        std::f64::consts::TAU / np as f64,
    );
    let mut sum = 0.0;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) * dt;
        let (st, ct) = theta.sin_cos();
        for j in 0..np {
            let (sp, cp) = ((j as f64 + 0.5) * dp).sin_cos();
            let wi = Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32);
            sum +=
                (material.eval_mode(wo, wi, TransportMode::Importance).g * wi.z.abs()) as f64 * st;
        }
    }
    sum * dt * dp
}

fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn rough_glass_sphere_in_a_white_furnace_loses_only_single_scattering_energy() {
    let pixels = pixels_on_sphere();
    assert!(pixels.len() > 400, "{} pixels", pixels.len());
    let s = 2.0 * HALF_WIDTH / RES as f32;
    let mut previous_loss = 0.0;
    for alpha in [0.1f32, 0.3, 0.7] {
        let material = Material::from_desc(&MaterialDesc::RoughDielectric {
            eta: ETA,
            alpha_u: alpha,
            alpha_v: alpha,
        });
        assert!(matches!(material, Material::RoughDielectric { .. }));

        // One interaction at normal incidence from outside and from inside: the
        // walk's weights average to the brute-force albedo, which is at most 1. From
        // inside it is far lower at high roughness: microfacets tilted past the
        // critical angle reflect totally, mostly into directions below the macro
        // surface, which only multiple scattering would bring back.
        let mut rng = Pcg32::new(3, alpha.to_bits() as u64);
        for wo in [Vec3::Z, Vec3::NEG_Z] {
            let a0 = albedo(&material, wo);
            let first: Vec<f64> = (0..200_000)
                .map(|_| {
                    let u = Vec2::new(rng.uniform(), rng.uniform());
                    material
                        .sample(wo, rng.uniform(), u, TransportMode::Radiance)
                        .map_or(0.0, |bs| {
                            (material.eval_mode(wo, bs.wi, TransportMode::Importance).g
                                * bs.wi.z.abs()
                                / material.pdf(wo, bs.wi)) as f64
                        })
                })
                .collect();
            let (a_mc, a_se) = mean_se(&first);
            println!("alpha {alpha}, wo {wo}: albedo {a0:.5}, sampled {a_mc:.5} ± {a_se:.5}");
            assert!(a0 <= 1.0 + 2e-3, "alpha {alpha}: albedo {a0}");
            assert!(
                (a_mc - a0).abs() < 4.0 * a_se + 2e-3,
                "alpha {alpha} wo {wo}: {a_mc} ± {a_se} vs {a0}"
            );
        }

        // The reference walk over the same pixel footprints.
        let n_walk = 400_000;
        let mut interactions = 0u64;
        let walks: Vec<f64> = (0..n_walk)
            .map(|_| {
                let (_, _, corner) = pixels[(rng.next_u32() as usize) % pixels.len()];
                let hit = corner + s * Vec2::new(rng.uniform(), rng.uniform());
                let (w, k) = walk(&material, hit, &mut rng);
                interactions += k as u64;
                w
            })
            .collect();
        let (expected, expected_se) = mean_se(&walks);
        let mean_interactions = interactions as f64 / n_walk as f64;

        let img = render(alpha, 64);
        let values: Vec<f64> = pixels
            .iter()
            .map(|&(x, y, _)| img.get(x as usize, y as usize).g as f64)
            .collect();
        // The spread between pixels bounds the noise of one pixel from above (it also
        // holds the true variation over the sphere).
        let (mean, se) = mean_se(&values);
        let sd = se * (values.len() as f64).sqrt();
        let loss = 1.0 - mean;
        println!(
            "alpha {alpha}: image {mean:.5} ± {se:.5}, walk {expected:.5} ± {expected_se:.5}, \
             {mean_interactions:.2} interactions per path, loss {loss:.5}"
        );
        for v in &values {
            assert!(*v <= 1.0 + 5.0 * sd, "alpha {alpha}: pixel {v}, sd {sd}");
        }
        assert!(
            mean <= 1.0 + 3.0 * se,
            "alpha {alpha}: mean {mean} gains energy"
        );
        let tolerance = 4.0 * (se * se + expected_se * expected_se).sqrt();
        assert!(
            (mean - expected).abs() < tolerance,
            "alpha {alpha}: image {mean} vs walk {expected} (tolerance {tolerance})"
        );
        // The single-scattering loss grows with roughness and is far from noise at
        // the roughest setting.
        assert!(
            loss > previous_loss - 3.0 * se,
            "alpha {alpha}: loss {loss}"
        );
        previous_loss = loss;
        if alpha == 0.7 {
            assert!(loss > 10.0 * se, "alpha 0.7: loss {loss} ± {se}");
        }
    }
}
