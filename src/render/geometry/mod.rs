//! Geometric primitives and their ray-intersection and sampling kernels.

pub mod bounds;
pub mod ray;

pub use bounds::Aabb;
pub use ray::Ray;
