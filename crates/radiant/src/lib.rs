//! radiant — a physically based global-illumination renderer.
//!
//! The workspace's crates are its layers, and data flows one way through them:
//! `radiant-scene` (parse pbrt-v4 files or build a canonical scene in code) →
//! `radiant-render` (geometry, BVH, materials, lights, cameras, samplers, integrators)
//! → `radiant-image` (film, EXR/PFM/PNG, metrics) → file. `radiant-radiosity` is a
//! finite-element solver built on the render layer. This crate sits on top: it chooses
//! the integrator by name and re-exports the layers for programs and tests.
#![forbid(unsafe_code)]

pub use radiant_image as image;
pub use radiant_math as math;
pub use radiant_math::color;
pub use radiant_radiosity as radiosity;
pub use radiant_render as render;
pub use radiant_report as report;
pub use radiant_scene as scene;

pub mod checkpoint;
pub mod integrators;
pub mod partial;
pub mod session;
pub mod solution;
pub mod study;

pub use integrators::{INTEGRATOR_NAMES, integrator_from_desc};
pub use session::Session;
