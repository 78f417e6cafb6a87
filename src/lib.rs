//! radiant — a physically based global-illumination renderer.
//!
//! Data flows one way: `scene` (parse pbrt-v4 files or build a canonical scene in code)
//! → `render` (geometry, BVH, materials, lights, cameras, integrators) → `image`
//! (film, EXR/PFM/PNG, metrics) → file. `radiosity` is a separate finite-element
//! solver that reads the same scene description and writes through the same film.
#![forbid(unsafe_code)]

pub mod color;
pub mod image;
pub mod math;
pub mod radiosity;
pub mod render;
pub mod scene;
