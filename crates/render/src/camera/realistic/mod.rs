//! The "realistic" camera: a real multi-element lens in front of the film, after
//! Kolb, Mitchell & Hanrahan, "A Realistic Camera Model for Computer Graphics" (SIGGRAPH 1995).
//!
//! Lens data are in millimetres and traced in f64; the camera hands rays to the renderer in
//! metres (f32), as pbrt-v4 does (scene units are metres, lens files are millimetres).
//!
//! Two coordinate frames are used, both with the optical axis as z:
//! * **lens space** (tracing): origin at the vertex of the rear surface, +z towards the scene,
//!   the film plane at `z = -film_gap`. Camera space is lens space shifted by `+film_gap`
//!   (film centre at the origin, +z forward, +x right, +y up) and scaled to metres.
//! * **design space** (reports, [`ParaxialData`]): origin at the front vertex, +z towards the film,
//!   as optical designers write prescriptions. [`ThickLens`] positions are measured from the rear
//!   vertex, positive towards the film.
//!
//! Pipeline: [`LensPrescription`] (parsed file) → [`LensSystem`] (laid-out interfaces, exact tracing)
//! → [`ParaxialData`] / [`ThickLens`] (first-order optics, focusing) → [`ExitPupilBounds`]
//! (where light can pass, per film radius) → [`RealisticCamera`] (ray generation and weights).

mod camera;
mod field;
mod focus;
mod lensfile;
mod paraxial;
mod pupil;
mod report;
mod svg;
mod system;

#[cfg(test)]
mod tests;

pub use camera::{CameraRaySample, RealisticCamera};
pub use field::{ChiefRay, chief_ray, image_circle};
pub use focus::{ThickLens, film_distance_for_focus};
pub use lensfile::{LensPrescription, LensSurface};
pub use paraxial::{Abcd, ParaxialData};
pub use pupil::{ExitPupilBounds, PupilRect};
pub use report::lens_report;
pub use svg::lens_svg;
pub use system::{ApertureClipping, Interface, LensRay, LensSystem, TraceFailure};

/// Millimetres per scene unit: pbrt-v4 treats scene units as metres and lens data as millimetres.
pub const MM_PER_SCENE_UNIT: f64 = 1000.0;

/// Everything that can go wrong building or focusing a lens.
#[derive(Debug, thiserror::Error)]
pub enum LensError {
    #[error("cannot read lens file {path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// A malformed row: wrong column count, not a number, NaN, non-positive aperture...
    #[error("{file}:{line}: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{file}: no aperture stop (a row with radius 0) in the lens description")]
    NoStop { file: String },
    /// A structurally impossible lens (surface numbers count from 0 at the front element).
    #[error("{lens}: surface {surface}: {message}")]
    InvalidSurface {
        lens: String,
        surface: usize,
        message: String,
    },
    /// The system has no focal power (C = 0 in its ABCD matrix), so it has no focal length.
    #[error("{lens}: the lens system is afocal (no focal power)")]
    Afocal { lens: String },
    /// The thick-lens focusing equation has no real solution: the object is too close.
    #[error(
        "{lens}: cannot focus at {focus_m} m: the closest focus distance (from the film) is {closest_m:.4} m \
         (thick-lens focal length {focal_mm:.3} mm)"
    )]
    FocusTooClose {
        lens: String,
        focus_m: f64,
        closest_m: f64,
        focal_mm: f64,
    },
    /// A parameter outside its domain (non-positive diagonal, NaN focus distance...).
    #[error("{0}")]
    InvalidParameter(String),
    /// A construction ray that must pass the lens was lost (total internal reflection or a miss).
    #[error("{lens}: {message}")]
    Trace { lens: String, message: String },
}
