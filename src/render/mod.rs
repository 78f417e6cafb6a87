//! Rendering: geometry and acceleration, materials, lights, cameras, samplers and the
//! integrators that turn a scene into film samples.

pub mod accel;
pub mod bench;
pub mod camera;
pub mod geometry;
pub mod integrator;
pub mod light;
pub mod material;
pub mod sampler;
pub mod session;
pub mod world;

pub use session::{Overrides, Progress, RenderOutput, Session};
