//! Reading a solution out: as an image from the scene camera, as files, or at points.
//!
//! - [`display`]: radiosities at the mesh vertices for Gouraud interpolation, and ray
//!   queries against the patches.
//! - [`shading`]: the per-pixel estimator of the image, Gouraud display or a final
//!   gather, through the renderer's pass loop.
//! - [`export`]: the lit mesh as glTF or PLY, and a CSV table of every patch.
//! - [`point_irradiance`]: irradiance at arbitrary points (sensors) from the patches'
//!   exact factors and shadow rays.

pub mod display;
pub mod export;
pub mod point_irradiance;
pub mod shading;
