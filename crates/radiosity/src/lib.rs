//! Radiosity: the diffuse global-illumination balance `B_i = E_i + rho_i sum_j F_ij B_j`
//! over planar patches, solved per colour band (all three at once).
//!
//! - [`patch`]: patches over shared corner points, with per-band emission and reflectance.
//! - [`contour`]: the exact point-to-polygon form factor (Lambert's contour integral).
//! - [`quadrature`]: Gauss (optionally graded) and stratified points on patches.
//! - [`formfactor`]: ray-cast patch-to-patch factors (contour at quadrature points
//!   times shadow-ray visibility), as a full matrix or a row/column on the fly.
//! - [`hemicube`]: Cohen & Greenberg's hemi-cube with a depth/item buffer.
//! - [`visibility`]: the pluggable occlusion query (the renderer's BVH goes here).
//! - [`solver`]: Jacobi and Gauss-Seidel on a stored matrix.
//! - [`progressive`]: progressive refinement (shooting) with no N^2 storage.
//! - [`contact`], [`refine`], [`adaptive`]: grading towards contact lines, conforming
//!   red-green splits, and the solve-split-solve loop driven by neighbour contrast.
//! - [`report`]: reciprocity, closure, irradiance and energy balance.
//! - [`shapes`]: meshed boxes and spheres for tests and benchmarks.

#![forbid(unsafe_code)]

pub mod adaptive;
pub mod contact;
pub mod contour;
pub mod display;
pub mod export;
pub mod formfactor;
pub mod hemicube;
pub mod integrator;
pub mod irradiance;
pub mod matrix;
pub mod mesh;
pub mod patch;
pub mod progressive;
pub mod quadrature;
pub mod refine;
pub mod render;
pub mod report;
pub mod scene;
pub mod settings;
pub mod shaft;
pub mod shapes;
pub mod solve;
pub mod solver;
pub mod visibility;
pub mod world_visibility;

pub use contour::point_polygon_factor;
pub use formfactor::{Quadrature, RayCastSettings, RayCaster};
pub use hemicube::HemiCube;
pub use integrator::RadiosityIntegrator;
pub use matrix::FormFactorMatrix;
pub use patch::{Patch, PatchSet, Polygon};
pub use progressive::{
    ProgressiveReport, ProgressiveSettings, ProgressiveState, ShooterSelection, ShootingFactors,
    solve_progressive,
};
pub use solver::{IterationSettings, SolveReport, solve_gauss_seidel, solve_jacobi};
pub use visibility::{AlwaysVisible, BruteForceVisibility, Visibility};
