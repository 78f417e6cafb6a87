//! Form factors `F_ij`, the fraction of the energy leaving patch `i` that arrives at
//! patch `j`, by two methods, and the matrix that stores them.
//!
//! - [`contour_integral`]: the exact point-to-polygon factor (Lambert's contour
//!   integral) and its far-field disk approximation.
//! - [`quadrature`]: Gauss (optionally graded) and stratified points on patches.
//! - [`ray_cast`]: patch-to-patch factors as the contour factor at quadrature points
//!   times shadow-ray visibility, as a full matrix or a row/column on the fly.
//! - [`hemicube`]: Cohen & Greenberg's hemi-cube with a depth/item buffer.
//! - [`matrix`]: the dense row-major factor matrix, in `f64` or `f32`.

pub mod contour_integral;
pub mod hemicube;
pub mod matrix;
pub mod quadrature;
pub mod ray_cast;
