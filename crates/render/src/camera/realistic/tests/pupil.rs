//! Exit-pupil bounds: conservative (no light outside) and tight (little wasted area).

use super::super::{ApertureClipping, ExitPupilBounds, LensRay, LensSystem};
use super::{LENSES, lens, lens_record, num};
use radiant_math::hash::Pcg32;
use radiant_math::{DVec2, DVec3};

const BUCKETS: usize = ExitPupilBounds::DEFAULT_BUCKETS;
const HALF_DIAGONAL: f64 = 17.5;

fn passes(system: &LensSystem, gap: f64, film_radius: f64, p: DVec2) -> bool {
    let origin = DVec3::new(film_radius, 0.0, -gap);
    let dir = (DVec3::new(p.x, p.y, 0.0) - origin).normalize();
    system
        .trace_to_scene(LensRay { origin, dir }, ApertureClipping::Clip)
        .is_ok()
}

/// The lens with its film at the paraxial BFD (infinity focus), or at pbrt's gap for 0.5 m.
fn setup(name: &str, close_focus: bool) -> (LensSystem, f64, ExitPupilBounds) {
    let system = LensSystem::new(&lens(name)).unwrap();
    let record = lens_record(name);
    let gap = if close_focus {
        num(&record["pbrt_focus_film_gap_mm_by_focusdistance_m"]["0.5"])
    } else {
        num(&record["paraxial"]["bfd"])
    };
    let bounds = ExitPupilBounds::compute(&system, gap, HALF_DIAGONAL, BUCKETS).unwrap();
    (system, gap, bounds)
}

/// Random film radii and random rear-plane points in a band around each bucket's rectangle
/// (up to 30 % of its size outside it, where a too-tight bound would show): none may pass.
/// 20 000 probes per lens; the band is where misses would be, so this is a sharp test. Infinity
/// focus for all four lenses, and 0.5 m for the two that reach it with a large film shift.
#[test]
fn bounds_contain_every_passing_ray() {
    let mut rng = Pcg32::new(7, 11);
    let cases = LENSES
        .iter()
        .map(|name| (*name, false))
        .chain([("dgauss.50mm.dat", true), ("wide.22mm.dat", true)]);
    for (name, close_focus) in cases {
        let (system, gap, bounds) = setup(name, close_focus);
        let mut probes_outside = 0;
        for _ in 0..20_000 {
            let r = rng.uniform_f64() * HALF_DIAGONAL;
            let Some(rect) = bounds.rect_for_radius(r) else {
                continue;
            };
            let (w, h) = (rect.x_max - rect.x_min, rect.y_max);
            let p = DVec2::new(
                rect.x_min - 0.3 * w + 1.6 * w * rng.uniform_f64(),
                (2.0 * rng.uniform_f64() - 1.0) * 1.3 * h,
            );
            if rect.contains(p) {
                continue;
            }
            probes_outside += 1;
            assert!(
                !passes(&system, gap, r, p),
                "{name}: film r = {r} passes at {p} outside {rect:?}"
            );
        }
        assert!(probes_outside > 5_000, "{name}: too few probes outside");
        // Film radii whose bucket is empty get no light at all (fisheye corners).
        for (b, rect) in bounds.buckets().iter().enumerate() {
            if rect.is_none() {
                let r = (b as f64 + 0.5) / BUCKETS as f64 * HALF_DIAGONAL;
                let reach = 3.0 * system.rear_aperture_radius() + r;
                for i in 0..=40 {
                    for j in 0..=20 {
                        let p = DVec2::new(
                            -reach + 2.0 * reach * i as f64 / 40.0,
                            reach * j as f64 / 20.0,
                        );
                        assert!(
                            !passes(&system, gap, r, p),
                            "{name}: empty bucket {b} passes"
                        );
                    }
                }
            }
        }
    }
}

/// Against a brute-force 300 × 150 grid over five film radii per bucket, in a window 25 % larger
/// than the rectangle on every side (passing points outside that window would already fail the
/// containment test above): the rectangle contains the brute-force bounding box and wastes
/// little. The brute box falls short of the truth by up to one grid cell per side (0.5 % of the
/// extent) and the padding for film radii between samples adds ~1 %; 5 % extra area is allowed.
#[test]
fn bounds_are_tight() {
    for name in LENSES {
        let (system, gap, bounds) = setup(name, false);
        for b in [0, BUCKETS / 3, 2 * BUCKETS / 3] {
            let Some(rect) = bounds.buckets()[b] else {
                continue;
            };
            let margin = 0.25 * (rect.x_max - rect.x_min).max(rect.y_max);
            let (x0, x1, y1) = (
                rect.x_min - margin,
                rect.x_max + margin,
                rect.y_max + margin,
            );
            let (mut x_min, mut x_max, mut y_max) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
            for k in 0..5 {
                let r = (b as f64 + k as f64 / 4.0) / BUCKETS as f64 * HALF_DIAGONAL;
                for i in 0..=300 {
                    for j in 0..=150 {
                        let p =
                            DVec2::new(x0 + (x1 - x0) * i as f64 / 300.0, y1 * j as f64 / 150.0);
                        if passes(&system, gap, r, p) {
                            x_min = x_min.min(p.x);
                            x_max = x_max.max(p.x);
                            y_max = y_max.max(p.y);
                        }
                    }
                }
            }
            assert!(
                rect.x_min <= x_min && rect.x_max >= x_max && rect.y_max >= y_max,
                "{name} bucket {b}: {rect:?} misses brute box [{x_min}, {x_max}] x {y_max}"
            );
            let brute_area = (x_max - x_min) * 2.0 * y_max;
            assert!(
                rect.area() < 1.05 * brute_area,
                "{name} bucket {b}: area {} vs brute {brute_area}: {rect:?} vs [{x_min}, {x_max}] x {y_max}",
                rect.area()
            );
            eprintln!(
                "{name} bucket {b}: area ratio {:.4}",
                rect.area() / brute_area
            );
        }
    }
}
