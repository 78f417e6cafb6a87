//! Cameras: turn a film position and lens sample into a camera-space ray.

pub mod realistic;
