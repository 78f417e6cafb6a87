//! Chief rays: for a film point, the ray through the centre of the aperture stop. Its angle to the
//! axis in object space is the field angle that film point sees (field of view, distortion,
//! the fisheye's r = f·θ mapping).

use super::{ApertureClipping, LensRay, LensSystem, ParaxialData};
use radiant_math::DVec3;

/// The chief ray of one film point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiefRay {
    /// Film radius it was traced from (mm).
    pub film_radius: f64,
    /// Angle between the outgoing ray and the axis (radians).
    pub field_angle: f64,
    /// The ray leaving the front element (lens space).
    pub outgoing: LensRay,
    /// Height at which it crosses the rear vertex plane (mm; opposite sign to the film point for
    /// an inverting lens).
    pub rear_plane_x: f64,
    /// True when some aperture rim other than the stop would block it.
    pub vignetted: bool,
}

/// Candidate aim points scanned across the rear plane before bisection.
const SCAN_STEPS: usize = 256;

/// Finds the chief ray from film point (film_radius, 0) with the film `film_gap` mm behind the
/// rear vertex, or None if no ray through the stop centre leaves the lens (outside the image
/// circle). Apertures are ignored while searching (the chief ray is defined by the stop centre
/// alone); [`ChiefRay::vignetted`] tells whether the rims would clip it.
pub fn chief_ray(system: &LensSystem, film_gap: f64, film_radius: f64) -> Option<ChiefRay> {
    let stop = system.stop_index();
    let film = DVec3::new(film_radius, 0.0, -film_gap);
    let ray_through = |x: f64| LensRay {
        origin: film,
        dir: (DVec3::new(x, 0.0, 0.0) - film).normalize(),
    };
    // Height at the stop plane of the ray aimed at (x, 0) on the rear vertex plane; only rays
    // that also leave the front of the lens forwards count.
    let stop_height = |x: f64| -> Option<f64> {
        let mut at_stop = None;
        let mut k = system.interfaces().len();
        let out = system
            .trace_to_scene_recording(ray_through(x), ApertureClipping::Ignore, 0, |p| {
                k -= 1;
                if k == stop {
                    at_stop = Some(p.x);
                }
            })
            .ok()?;
        if out.dir.z <= 0.0 {
            return None;
        }
        at_stop
    };

    // Scan a generous span of the rear plane for sign changes of the stop height, then pick the
    // root nearest the paraxial guess (the line from the film point to the exit-pupil centre).
    let span = 2.0 * system.rear_aperture_radius() + film_radius.abs();
    let guess = ParaxialData::new(system)
        .map(|p| {
            let pupil_z = -p.exit_pupil_from_rear;
            film_radius * pupil_z / (pupil_z + film_gap)
        })
        .unwrap_or(0.0);
    let mut best: Option<f64> = None;
    let mut previous: Option<(f64, f64)> = None;
    for i in 0..=SCAN_STEPS {
        let x = -span + 2.0 * span * i as f64 / SCAN_STEPS as f64;
        let h = stop_height(x);
        if let (Some((x0, h0)), Some(h1)) = (previous, h)
            && (h0 <= 0.0) != (h1 <= 0.0)
        {
            let root = bisect(x0, h0, x, &stop_height);
            if best.is_none_or(|b| (root - guess).abs() < (b - guess).abs()) {
                best = Some(root);
            }
        }
        previous = h.map(|h| (x, h));
    }
    let x = best?;
    let outgoing = system
        .trace_to_scene(ray_through(x), ApertureClipping::Ignore)
        .ok()
        .filter(|out| out.dir.z > 0.0)?;
    let vignetted = system
        .trace_to_scene(ray_through(x), ApertureClipping::Clip)
        .is_err();
    let d = outgoing.dir;
    Some(ChiefRay {
        film_radius,
        field_angle: d.x.hypot(d.y).atan2(d.z),
        outgoing,
        rear_plane_x: x,
        vignetted,
    })
}

/// Bisection steps for the image-circle radius (2⁻⁴⁰ of the search range).
const IMAGE_CIRCLE_STEPS: usize = 40;

/// The image circle: the largest film radius up to `max_radius` whose chief ray passes every
/// aperture rim, with that chief ray. None when even the centre's chief ray is blocked.
pub fn image_circle(system: &LensSystem, film_gap: f64, max_radius: f64) -> Option<ChiefRay> {
    let clear = |r: f64| chief_ray(system, film_gap, r).filter(|c| !c.vignetted);
    if let Some(c) = clear(max_radius) {
        return Some(c);
    }
    let mut best = clear(0.0)?;
    let (mut inside, mut outside) = (0.0, max_radius);
    for _ in 0..IMAGE_CIRCLE_STEPS {
        let m = 0.5 * (inside + outside);
        match clear(m) {
            Some(c) => {
                inside = m;
                best = c;
            }
            None => outside = m,
        }
    }
    Some(best)
}

/// Bisects `f` between `a` (value `fa`) and `b` of opposite sign; failed evaluations count as
/// being on `b`'s side.
fn bisect(mut a: f64, fa: f64, mut b: f64, f: &impl Fn(f64) -> Option<f64>) -> f64 {
    let negative_at_a = fa <= 0.0;
    for _ in 0..80 {
        let m = 0.5 * (a + b);
        if m == a || m == b {
            break;
        }
        match f(m) {
            Some(v) if (v <= 0.0) == negative_at_a => a = m,
            _ => b = m,
        }
    }
    0.5 * (a + b)
}
