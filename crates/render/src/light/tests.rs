//! Light sampling checks: irradiance from closed forms, pdf consistency, and emitted
//! power of photon sampling equal to the light's power.

use super::*;
use crate::geometry::sphere::Sphere;
use radiant_math::Transform;
use radiant_math::hash::Pcg32;

fn scene() -> SceneSphere {
    SceneSphere {
        center: Vec3::ZERO,
        radius: 10.0,
    }
}

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

/// The sampled point as a ray would find it (shapes whose density ignores uv).
fn hit_at(q: LightPoint) -> LightHit {
    LightHit {
        p: q.p,
        n: q.n,
        uv: Vec2::ZERO,
    }
}

/// Irradiance E = mean(Li cos / pdf) at `p` with normal `n`, with its standard error.
fn irradiance(light: &Light, p: Vec3, n: Vec3, samples: usize) -> (f64, f64) {
    let mut rng = Pcg32::new(17, 4);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..samples {
        let v = light
            .sample_li(&LightSampleContext::at_point(p), u2(&mut rng), scene())
            .map_or(0.0, |ls| (ls.li.g * ls.wi.dot(n).max(0.0) / ls.pdf) as f64);
        s += v;
        s2 += v * v;
    }
    let mean = s / samples as f64;
    let var = (s2 / samples as f64 - mean * mean).max(0.0);
    (mean, (var / samples as f64).sqrt())
}

fn square_light(side: f32, height: f32, l: f32) -> Vec<Light> {
    // Corner at the origin's vertical, facing down (-z); triangles wound for -z normals.
    let p = [
        Vec3::new(0.0, 0.0, height),
        Vec3::new(0.0, side, height),
        Vec3::new(side, side, height),
        Vec3::new(side, 0.0, height),
    ];
    [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
        .into_iter()
        .map(|t| {
            Light::Area(AreaLight {
                shape: LightShape::Triangle {
                    p: t,
                    n: -Vec3::Z,
                    area: 0.5 * side * side,
                },
                l: Rgb::splat(l),
                two_sided: false,
                image: None,
            })
        })
        .collect()
}

#[test]
fn rectangle_light_irradiance_matches_the_corner_form_factor() {
    // Point below the corner of an a x b rectangle at distance c (Howell's catalogue, C-11):
    // F = 1/(2 pi) [A/sqrt(1+A^2) atan(B/sqrt(1+A^2)) + B/sqrt(1+B^2) atan(A/sqrt(1+B^2))].
    let (a, c) = (1.0f64, 1.0f64);
    let (aa, bb) = (a / c, a / c);
    let f = (aa / (1.0 + aa * aa).sqrt() * (bb / (1.0 + aa * aa).sqrt()).atan()
        + bb / (1.0 + bb * bb).sqrt() * (aa / (1.0 + bb * bb).sqrt()).atan())
        / (2.0 * std::f64::consts::PI);
    let exact = std::f64::consts::PI * f; // E = pi L F with L = 1
    let (mut e, mut var) = (0.0, 0.0);
    for light in square_light(1.0, 1.0, 1.0) {
        let (m, se) = irradiance(&light, Vec3::ZERO, Vec3::Z, 100_000);
        e += m;
        var += se * se;
    }
    assert!(
        (e - exact).abs() < 4.0 * var.sqrt() + 1e-6,
        "{e} vs {exact} (se {})",
        var.sqrt()
    );
}

#[test]
fn sphere_light_irradiance_is_pi_l_sin2() {
    let light = Light::Area(AreaLight {
        shape: LightShape::Sphere {
            sphere: Sphere::full(1.0).unwrap(),
            render_from_object: Transform::translate(Vec3::new(0.0, 0.0, 4.0)),
            reverse: false,
        },
        l: Rgb::splat(2.0),
        two_sided: false,
        image: None,
    });
    let exact = std::f64::consts::PI * 2.0 / 16.0;
    let (e, se) = irradiance(&light, Vec3::ZERO, Vec3::Z, 50_000);
    assert!((e - exact).abs() < 4.0 * se + 1e-6, "{e} vs {exact} ({se})");
    // The density reported for a sample equals pdf_li for its point.
    let mut rng = Pcg32::new(1, 1);
    let ctx = LightSampleContext::at_point(Vec3::ZERO);
    for _ in 0..100 {
        let s = light.sample_li(&ctx, u2(&mut rng), scene()).unwrap();
        let pdf = light.pdf_li(&ctx, s.wi, Some(&hit_at(s.p_light)));
        assert!((pdf - s.pdf).abs() < 1e-3 * s.pdf, "{pdf} vs {}", s.pdf);
    }
}

#[test]
fn triangle_light_pdf_li_matches_its_samples() {
    let light = &square_light(2.0, 3.0, 1.0)[0];
    let ctx = LightSampleContext::at_point(Vec3::new(0.3, -0.2, 0.0));
    let mut rng = Pcg32::new(2, 2);
    for _ in 0..100 {
        let s = light.sample_li(&ctx, u2(&mut rng), scene()).unwrap();
        let pdf = light.pdf_li(&ctx, s.wi, Some(&hit_at(s.p_light)));
        assert!((pdf - s.pdf).abs() < 1e-3 * s.pdf);
    }
}

/// Photon emission: the mean power of emitted samples is the light's power.
#[test]
fn emitted_power_equals_light_power() {
    let lights = vec![
        square_light(2.0, 3.0, 1.5).remove(0),
        Light::Point {
            position: Vec3::ONE,
            intensity: Rgb::splat(3.0),
        },
        Light::Spot {
            position: Vec3::ZERO,
            direction: Vec3::Y,
            intensity: Rgb::splat(5.0),
            cos_falloff_start: 30f32.to_radians().cos(),
            cos_total_width: 40f32.to_radians().cos(),
        },
        Light::Distant {
            direction: -Vec3::Y,
            radiance: Rgb::splat(2.0),
        },
        Light::Infinite {
            radiance: Rgb::splat(0.5),
            map: None,
        },
    ];
    let mut rng = Pcg32::new(8, 8);
    for light in &lights {
        let n = 200_000;
        let (mut s, mut s2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let v = light
                .sample_le(u2(&mut rng), u2(&mut rng), scene())
                .map_or(0.0, |e| e.power.g as f64);
            s += v;
            s2 += v * v;
        }
        let mean = s / n as f64;
        let se = ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        let power = light.power(scene()).g as f64;
        assert!(
            (mean - power).abs() < 4.0 * se + 1e-6 * power,
            "{light:?}: {mean} vs {power}"
        );
    }
}

/// The corner form factor of the unit square at distance 1 (Howell, C-11), times π.
fn unit_square_corner_irradiance() -> f64 {
    let a = 1.0f64;
    let f = 2.0 * (a / (1.0 + a * a).sqrt() * (a / (1.0 + a * a).sqrt()).atan())
        / (2.0 * std::f64::consts::PI);
    std::f64::consts::PI * f
}

#[test]
fn parallelogram_and_mesh_lights_match_the_corner_form_factor() {
    let Light::Area(AreaLight {
        shape: LightShape::Triangle { p: a, .. },
        ..
    }) = square_light(1.0, 1.0, 1.0)[0].clone()
    else {
        unreachable!()
    };
    let Light::Area(AreaLight {
        shape: LightShape::Triangle { p: b, .. },
        ..
    }) = square_light(1.0, 1.0, 1.0)[1].clone()
    else {
        unreachable!()
    };
    let (corner, e1, e2) = parallelogram_of(a, b).expect("the square's halves");
    let light = |shape| {
        Light::Area(AreaLight {
            shape,
            l: Rgb::splat(1.0),
            two_sided: false,
            image: None,
        })
    };
    let parallelogram = light(LightShape::Parallelogram {
        p: corner,
        e1,
        e2,
        n: -Vec3::Z,
        area: e1.cross(e2).length(),
    });
    let mesh = light(LightShape::Mesh(Box::new(EmittingMesh::new(
        vec![a, b],
        vec![-Vec3::Z; 2],
        Vec::new(),
    ))));
    let exact = unit_square_corner_irradiance();
    for (name, l) in [("parallelogram", parallelogram), ("mesh", mesh)] {
        let (e, se) = irradiance(&l, Vec3::ZERO, Vec3::Z, 100_000);
        assert!(
            (e - exact).abs() < 4.0 * se + 1e-6,
            "{name}: {e} vs {exact} (se {se})"
        );
    }
}

#[test]
fn only_two_triangles_that_mirror_through_a_shared_diagonal_are_a_parallelogram() {
    let [o, x, y, xy] = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.3, 1.0, 0.0)];
    // A parallelogram (o, x, x + y', y') with y' = (0.3, 1, 0), in either winding.
    let y2 = xy - x;
    let (c, e1, e2) = parallelogram_of([o, x, xy], [o, xy, y2]).expect("a parallelogram");
    // Corner at the unshared vertex x, the opposite corner y2, area |x × y2| = 1.
    assert!((c + e1 + e2 - y2).length() < 1e-6 && (e1.cross(e2).length() - 1.0).abs() < 1e-6);
    assert!(parallelogram_of([x, xy, o], [y2, o, xy]).is_some());
    // The same diagonal but the fourth corner off the mirror point: no parallelogram.
    assert_eq!(parallelogram_of([o, x, xy], [o, xy, y]), None);
    // Sharing one vertex only.
    assert_eq!(parallelogram_of([o, x, y], [o, xy, y2 + Vec3::Z]), None);
}
