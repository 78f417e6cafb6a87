//! Rendering: geometry and acceleration, materials, lights, cameras, samplers and the
//! integrators that turn a scene into film samples.

// Safe code throughout, except the AVX kernels (`accel::avx`), whose calls into
// run-time-detected instructions are the only unsafe operations.
#![deny(unsafe_code)]

pub mod accel;
pub mod aov;
pub mod bench;
/// The memory budget lives with the scene reader, which checks it for meshes it
/// generates (loop subdivision) before the renderer sees them.
pub use radiant_scene::budget;
pub mod camera;
pub mod context;
pub mod geometry;
pub mod integrator;
pub mod light;
pub mod material;
pub mod sampler;
pub mod stats;
pub mod texture;
pub mod world;

pub use context::{
    CameraSample, Overrides, PixelBounds, Progress, RenderContext, SAMPLE_BLOCK, WorkUnit,
};
pub use integrator::{Integrator, RenderControl, RenderOutput, Stats};
