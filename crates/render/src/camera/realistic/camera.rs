//! Ray generation for the realistic camera and its radiometric weight.
//!
//! Radiometry (Kolb et al. 1995, section 4, eq. for the film irradiance): a film point receives
//! E = ∫ L cos θ cos θ' / d² dA over the rear vertex plane, θ the angle to the axis at the film and
//! θ' at the plane. Both planes are perpendicular to the axis, so θ' = θ and d = Z / cos θ with Z
//! the axial film-to-plane distance: E = (1/Z²) ∫ L cos⁴θ dA. Sampling A with density p gives the
//! estimator L · cos⁴θ / (p · Z²), so the weight is cos⁴θ / (p · Z²) — Z², not d² (that would
//! double-count the cos²θ already in cos⁴θ). Blocked rays carry zero weight, which is how
//! vignetting appears; cos⁴θ is the natural fall-off.
//!
//! Normalisation: none, as in pbrt-v4 (whose weight is the same quantity times the shutter
//! interval, 1 by default). The weight is dimensionless (mm² · mm⁻² ), so a white sky of radiance
//! 1 gives a pixel value ≈ π / (4N²) on the axis — 0.193 for dgauss.50mm at f/2 — exactly what
//! pbrt reports, and users comparing with pbrt see the same brightness. Sensor scaling (ISO,
//! exposure) is the film's job.

use super::{
    ApertureClipping, ExitPupilBounds, LensError, LensPrescription, LensRay, LensSystem,
    MM_PER_SCENE_UNIT, ParaxialData, film_distance_for_focus,
};
use radiant_math::{DVec2, DVec3, Vec2, Vec3};

/// A camera ray in camera space (metres; +z forward, +x right, +y up) and its weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRaySample {
    /// Where the ray leaves the front element.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// Film-irradiance weight, cos⁴θ / (pdf · Z²) (see the module comment).
    pub weight: f32,
}

/// A camera with a real lens system in front of the film (Kolb, Mitchell & Hanrahan 1995).
#[derive(Clone, Debug)]
pub struct RealisticCamera {
    system: LensSystem,
    paraxial: ParaxialData,
    film_gap: f64,
    film_size: DVec2,
    film_diagonal: f64,
    focus_distance: f64,
    resolution: (u32, u32),
    pupil: ExitPupilBounds,
    warnings: Vec<String>,
}

impl RealisticCamera {
    /// `lens`: prescription in mm. `aperture_diameter_mm`: stop diameter (clamped to the file's
    /// stop, with a warning in [`RealisticCamera::warnings`]). `focus_distance`: scene units
    /// (metres) from the film, `f64::INFINITY` allowed. `film_diagonal_mm` and `resolution` give
    /// the film's physical size (aspect from the resolution).
    pub fn new(
        lens: LensPrescription,
        aperture_diameter_mm: f64,
        focus_distance: f64,
        film_diagonal_mm: f64,
        resolution: (u32, u32),
    ) -> Result<RealisticCamera, LensError> {
        if resolution.0 == 0 || resolution.1 == 0 {
            return Err(LensError::InvalidParameter(format!(
                "film resolution must be positive, got {}x{}",
                resolution.0, resolution.1
            )));
        }
        let mut system = LensSystem::new(&lens)?;
        let warnings: Vec<String> = system
            .set_stop_diameter(aperture_diameter_mm)?
            .into_iter()
            .collect();
        let paraxial = ParaxialData::new(&system)?;
        let film_gap = film_distance_for_focus(&system, focus_distance, film_diagonal_mm)?;
        // Film extent as pbrt: the diagonal split by the pixel aspect ratio.
        let aspect = resolution.1 as f64 / resolution.0 as f64;
        let width = film_diagonal_mm / (1.0 + aspect * aspect).sqrt();
        let film_size = DVec2::new(width, width * aspect);
        let pupil = ExitPupilBounds::compute(
            &system,
            film_gap,
            0.5 * film_diagonal_mm,
            ExitPupilBounds::DEFAULT_BUCKETS,
        )?;
        Ok(RealisticCamera {
            system,
            paraxial,
            film_gap,
            film_size,
            film_diagonal: film_diagonal_mm,
            focus_distance,
            resolution,
            pupil,
            warnings,
        })
    }

    /// `raster`: continuous pixel coordinates (0,0 top-left, x right, y down); `u_lens` in
    /// [0,1)². None when the ray is blocked by an aperture or totally internally reflected.
    pub fn generate_ray(&self, raster: Vec2, u_lens: Vec2) -> Option<CameraRaySample> {
        let film = self.film_point(raster);
        let (rear, pdf) = self
            .pupil
            .sample(film, DVec2::new(u_lens.x as f64, u_lens.y as f64))?;
        let origin = DVec3::new(film.x, film.y, -self.film_gap);
        let dir = (DVec3::new(rear.x, rear.y, 0.0) - origin).normalize();
        let out = self
            .system
            .trace_to_scene(LensRay { origin, dir }, ApertureClipping::Clip)
            .ok()?;
        let cos2 = dir.z * dir.z;
        let weight = cos2 * cos2 / (pdf * self.film_gap * self.film_gap);
        // Lens space → camera space: move the origin from the rear vertex to the film centre and
        // convert mm to metres. Both frames share x, y and the forward z, so nothing flips here;
        // the image inversion is undone in film_point.
        let o = (out.origin + DVec3::new(0.0, 0.0, self.film_gap)) / MM_PER_SCENE_UNIT;
        Some(CameraRaySample {
            origin: o.as_vec3(),
            dir: out.dir.as_vec3(),
            weight: weight as f32,
        })
    }

    /// Film point (lens-space mm) for a raster position. A lens images a scene point at camera
    /// (+x, +y) onto film (−x, −y); to show it at raster right/top like the pinhole camera, raster
    /// right maps to film −x and raster down to film +y.
    pub fn film_point(&self, raster: Vec2) -> DVec2 {
        let s = DVec2::new(
            raster.x as f64 / self.resolution.0 as f64 - 0.5,
            raster.y as f64 / self.resolution.1 as f64 - 0.5,
        );
        DVec2::new(-s.x * self.film_size.x, s.y * self.film_size.y)
    }

    /// Warnings raised while building (e.g. aperture clamped to the lens's stop).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The laid-out lens system (with the stop diameter in use).
    pub fn system(&self) -> &LensSystem {
        &self.system
    }

    /// Paraxial data of the system with the stop in use.
    pub fn paraxial(&self) -> &ParaxialData {
        &self.paraxial
    }

    /// Film distance behind the rear vertex (mm) for the focus distance.
    pub fn film_gap(&self) -> f64 {
        self.film_gap
    }

    /// Physical film width and height (mm).
    pub fn film_size(&self) -> DVec2 {
        self.film_size
    }

    /// Film diagonal (mm).
    pub fn film_diagonal(&self) -> f64 {
        self.film_diagonal
    }

    /// Focus distance (scene units from the film).
    pub fn focus_distance(&self) -> f64 {
        self.focus_distance
    }

    /// Film resolution in pixels.
    pub fn resolution(&self) -> (u32, u32) {
        self.resolution
    }

    /// The exit-pupil bounds the camera samples in.
    pub fn exit_pupil(&self) -> &ExitPupilBounds {
        &self.pupil
    }
}
