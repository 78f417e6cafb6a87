//! The patches the solver works on, and how a scene becomes them.
//!
//! - [`patch`]: patches over shared corner points, with per-band emission and
//!   reflectance ([`patch::PatchSet`]).
//! - [`meshed_scene`]: a scene description's diffuse surfaces as planar faces, meshed
//!   into one patch set with the surface, material and back twin of every patch
//!   ([`meshed_scene::RadiosityScene`]).
//! - [`face_mesh`]: planar input faces over welded points split into patches with no
//!   T-junctions (per-edge segment counts, grids, stitching strips; the cutting itself
//!   in the private `tessellation`).
//! - [`contact_grading`]: finding where one surface touches another it shares no edge
//!   with, so the patches there can be split a priori.
//! - [`refinement`]: conforming red-green splits of a meshed scene.
//! - [`procedural`]: meshed boxes and spheres built in code, for tests and benchmarks.

pub mod contact_grading;
pub mod face_mesh;
pub mod meshed_scene;
pub mod patch;
pub mod procedural;
pub mod refinement;
mod tessellation;
