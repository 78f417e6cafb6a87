//! Radiosity: the diffuse global-illumination balance `B_i = E_i + rho_i sum_j F_ij B_j`
//! over planar patches, solved per colour band (all three at once), and shown through
//! the renderer's film as one more [`radiant_render::integrator::Integrator`].
//!
//! Its parts, in the order data flows through them:
//! - [`mesh`]: patches ([`PatchSet`]) and the meshing of a scene's diffuse surfaces
//!   into them ([`mesh::meshed_scene::RadiosityScene`]), a-priori grading towards
//!   contact lines, conforming red-green refinement, and meshed test shapes.
//! - [`formfactor`]: the exact point-to-polygon factor (contour integral), quadrature
//!   on patches, ray-cast patch-to-patch factors, the hemi-cube, and the factor matrix.
//! - [`visibility`]: the occlusion query the factors use ([`Visibility`]), answered by
//!   the renderer's BVHs or by brute force, with shaft culling per progressive shot.
//! - [`solve`]: a meshed scene's solve (delta lights as the first shot, factors, the
//!   chosen solver, the power balance), with Jacobi and Gauss-Seidel, progressive
//!   refinement, the adaptive solve-split-solve loop, and diagnostics.
//! - [`output`]: the image (Gouraud display or final gather), glTF/PLY/CSV exports, and
//!   irradiance at points.
//! - [`settings`]: the parameters of `Integrator "radiosity"`; [`integrator`]: the
//!   integrator that meshes when chosen, solves when asked to render, then shows the
//!   solution through the shared pass loop.

#![forbid(unsafe_code)]

pub mod formfactor;
pub mod integrator;
pub mod mesh;
pub mod output;
pub mod settings;
pub mod solve;
pub mod visibility;

pub use formfactor::contour_integral::point_polygon_factor;
pub use formfactor::hemicube::HemiCube;
pub use formfactor::matrix::FormFactorMatrix;
pub use formfactor::ray_cast::{Quadrature, RayCastSettings, RayCaster};
pub use integrator::RadiosityIntegrator;
pub use mesh::patch::{Patch, PatchSet, Polygon};
pub use solve::matrix_solvers::{IterationSettings, SolveReport, solve_gauss_seidel, solve_jacobi};
pub use solve::progressive::{
    ProgressiveReport, ProgressiveSettings, ProgressiveState, ShooterSelection, ShootingFactors,
    solve_progressive,
};
pub use visibility::{AlwaysVisible, BruteForceVisibility, Visibility};
