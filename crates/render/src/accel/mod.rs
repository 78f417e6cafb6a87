//! Ray-tracing acceleration: an 8-wide BVH behind one small interface (closest hit and
//! any hit), so that another backend (e.g. Embree) could replace it.
//!
//! - [`Bvh`]: generic; primitives are intersected by a caller closure, which may itself
//!   transform the ray and traverse another BVH (two-level instancing).
//! - [`TriangleBvh`]: triangles stored in leaf order as 4-lane SIMD blocks and intersected
//!   inline with the watertight test — the fast path.
//! - [`ray_benchmark`]: the Mrays/s benchmark behind `radiant bench` and `benches/rays.rs`.

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx;
mod bench;
mod build;
mod bvh;
mod cluster;
pub mod displaced_sphere;
mod node;
mod traverse;
mod triangle4;
mod triangle_bvh;

#[cfg(test)]
mod tests;

pub use bench::{RayBenchConfig, RayBenchFigures, ray_benchmark};
pub use bvh::Bvh;
pub use triangle_bvh::{MeshHit, TriangleBvh};
