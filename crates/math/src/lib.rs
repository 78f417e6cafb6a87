//! Small math toolkit shared by every module: glam vectors (f32 for geometry, f64
//! where precision matters), transforms, orthonormal frames, sample warps,
//! discrete and piecewise-constant distributions, the equal-area sphere mapping and
//! hashing.

#![forbid(unsafe_code)]

pub mod color;
pub mod distribution;
pub mod divisor;
pub mod equal_area;
pub mod frame;
pub mod hash;
pub mod sampling;
pub mod transform;

pub use color::Rgb;
pub use distribution::{Distribution1D, Distribution2D};
pub use frame::Frame;
pub use glam::{DMat4, DVec2, DVec3, Mat3, Mat4, Vec2, Vec3, Vec4};
pub use transform::Transform;

pub const PI: f32 = std::f32::consts::PI;
pub const INV_PI: f32 = std::f32::consts::FRAC_1_PI;

/// The largest f32 strictly below 1: uniform samples are clamped to `[0, ONE_MINUS_EPSILON]`.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

pub fn lerp(t: f32, a: f32, b: f32) -> f32 {
    (1.0 - t) * a + t * b
}

/// `sqrt(max(0, x))`: guards against tiny negative arguments from round-off.
pub fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}
