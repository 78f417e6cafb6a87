//! Thick-lens approximation from traced rays and focusing by the thick-lens equation.
//!
//! Kolb et al. (1995, section 3.2) replace the lens by its cardinal points for focusing. They are
//! found here from two exact rays parallel to the axis at a small height h, one from each side:
//! where a ray's outgoing part crosses the axis is a focal point, where it (extended backwards)
//! reaches height h is a principal plane. pbrt-v4 uses h = 0.001 × film diagonal, and its
//! `focusdistance` film gaps are reproduced to 1e-9 mm only with the same h: at finite h the
//! spherical aberration of the marginal zone already shifts the focal point (by 5.4e-4 mm on
//! fisheye.10mm relative to the paraxial limit), so the camera uses that h for compatibility.

use super::{ApertureClipping, LensError, LensRay, LensSystem, MM_PER_SCENE_UNIT};
use radiant_math::DVec3;

/// Cardinal points from traced near-axial rays, measured along the axis from the rear vertex,
/// positive towards the film (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThickLens {
    /// Principal plane H' of the rays arriving from the scene.
    pub image_principal: f64,
    /// Focal point F' of the rays arriving from the scene (the back focus for that height).
    pub image_focal: f64,
    /// Principal plane H of the rays leaving towards the scene.
    pub object_principal: f64,
    /// Focal point F on the scene side.
    pub object_focal: f64,
}

/// The ray height pbrt-v4 uses for its thick-lens rays: 1/1000 of the film diagonal.
pub fn thick_lens_ray_height(film_diagonal_mm: f64) -> f64 {
    0.001 * film_diagonal_mm
}

impl ThickLens {
    /// Traces one ray from each side at `height` mm, apertures ignored (the construction is
    /// about the refracting surfaces, and at this height nothing is clipped anyway).
    pub fn from_traced_rays(system: &LensSystem, height: f64) -> Result<ThickLens, LensError> {
        let lost = |side: &str| LensError::Trace {
            lens: system.name.clone(),
            message: format!(
                "the thick-lens ray from the {side} side at height {height} mm did not pass"
            ),
        };
        let front = &system.interfaces()[0];
        let from_scene = LensRay {
            origin: DVec3::new(height, 0.0, front.sag_z(height) + 1.0),
            dir: DVec3::NEG_Z,
        };
        let out = system
            .trace_to_film(from_scene, ApertureClipping::Ignore)
            .map_err(|_| lost("scene"))?;
        let (image_focal, image_principal) = axis_and_height_crossings(system, out, height)?;

        let from_film = LensRay {
            origin: DVec3::new(height, 0.0, system.rear().sag_z(height) - 1.0),
            dir: DVec3::Z,
        };
        let out = system
            .trace_to_scene(from_film, ApertureClipping::Ignore)
            .map_err(|_| lost("film"))?;
        let (object_focal, object_principal) = axis_and_height_crossings(system, out, height)?;
        Ok(ThickLens {
            image_principal,
            image_focal,
            object_principal,
            object_focal,
        })
    }

    /// Focal length of the approximation, F' − H'.
    pub fn focal_length(&self) -> f64 {
        self.image_focal - self.image_principal
    }

    /// The smallest focus distance (mm, from the film) the thick-lens equation can reach:
    /// object-to-image distance 4f, at unit magnification.
    pub fn closest_focus_mm(&self) -> f64 {
        4.0 * self.focal_length() + self.image_principal - self.object_principal
    }

    /// Film distance behind the rear vertex (mm) that focuses an object `focus_mm` in front of
    /// the film (infinity allowed).
    ///
    /// With the film at g and the object at g − D (positions from the rear vertex, + towards the
    /// film), the object distance from H is s = H − (g − D) and the image distance from H' is
    /// s' = g − H'. Their sum L = s + s' = D − (H' − H) does not depend on g, and the Gaussian
    /// equation 1/s + 1/s' = 1/f gives s·s' = f·L: s' is a root of x² − L·x + f·L = 0. The root
    /// that tends to f as L → ∞ (film near the focal plane, not the magnified macro solution) is
    /// (L − √(L² − 4fL))/2, which cancels catastrophically for L ≫ f (the f32 textbook form gives
    /// 62.5 mm instead of 36.1 mm for dgauss.50mm at 10⁶ m). Multiplying by the conjugate gives the
    /// equivalent cancellation-free s' = 2f / (1 + √(1 − 4f/L)); it has a real value iff L ≥ 4f.
    pub fn film_distance_for_focus(&self, focus_mm: f64, lens: &str) -> Result<f64, LensError> {
        if focus_mm.is_nan() || focus_mm <= 0.0 {
            return Err(LensError::InvalidParameter(format!(
                "{lens}: focus distance must be positive, got {} m",
                focus_mm / MM_PER_SCENE_UNIT
            )));
        }
        let f = self.focal_length();
        if f.is_nan() || f <= 0.0 {
            return Err(LensError::InvalidParameter(format!(
                "{lens}: cannot focus a lens with non-positive focal length {f} mm"
            )));
        }
        let total = focus_mm - (self.image_principal - self.object_principal);
        let ratio = 4.0 * f / total;
        if !(total > 0.0 && ratio <= 1.0) {
            return Err(LensError::FocusTooClose {
                lens: lens.to_string(),
                focus_m: focus_mm / MM_PER_SCENE_UNIT,
                closest_m: self.closest_focus_mm() / MM_PER_SCENE_UNIT,
                focal_mm: f,
            });
        }
        let image_distance = 2.0 * f / (1.0 + (1.0 - ratio).sqrt());
        let gap = self.image_principal + image_distance;
        if gap.is_nan() || gap <= 0.0 {
            return Err(LensError::InvalidParameter(format!(
                "{lens}: focusing at {} m would put the film {gap} mm inside the lens",
                focus_mm / MM_PER_SCENE_UNIT
            )));
        }
        Ok(gap)
    }
}

/// Film distance behind the rear vertex (mm) for `focus_distance` in scene units (metres,
/// measured from the film; `f64::INFINITY` allowed), using the pbrt-v4-compatible thick lens for
/// a film of `film_diagonal_mm`.
pub fn film_distance_for_focus(
    system: &LensSystem,
    focus_distance: f64,
    film_diagonal_mm: f64,
) -> Result<f64, LensError> {
    if !(film_diagonal_mm > 0.0 && film_diagonal_mm.is_finite()) {
        return Err(LensError::InvalidParameter(format!(
            "film diagonal must be positive, got {film_diagonal_mm} mm"
        )));
    }
    let thick = ThickLens::from_traced_rays(system, thick_lens_ray_height(film_diagonal_mm))?;
    thick.film_distance_for_focus(focus_distance * MM_PER_SCENE_UNIT, &system.name)
}

/// Where the outgoing ray crosses the axis and where it is at `height`, converted to the
/// rear-vertex, towards-the-film coordinate.
fn axis_and_height_crossings(
    system: &LensSystem,
    ray: LensRay,
    height: f64,
) -> Result<(f64, f64), LensError> {
    if ray.dir.x == 0.0 {
        return Err(LensError::Afocal {
            lens: system.name.clone(),
        });
    }
    let z_at = |x: f64| ray.origin.z + (x - ray.origin.x) / ray.dir.x * ray.dir.z;
    // Lens space has +z towards the scene; these coordinates have + towards the film.
    Ok((-z_at(0.0), -z_at(height)))
}
