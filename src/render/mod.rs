//! Rendering: geometry and acceleration, materials, lights, cameras, samplers and the
//! integrators that turn a scene into film samples.

pub mod camera;
pub mod geometry;
