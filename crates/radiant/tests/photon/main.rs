//! Photon mapping and stochastic progressive photon mapping: stored energy,
//! projection maps, the furnace, the cornell-caustics reference, the spot-lit caustic
//! the path tracer cannot render, visualisations, snapshots, cancellation,
//! determinism and parameters; rough glass against the path tracer and the power
//! its photons carry on; glossy and polished surfaces against the path tracer.

#[path = "../common/mod.rs"]
mod common;
mod glossy_points;
mod maps;
mod photonmap;
mod rough_glass;
mod scenes;
mod sppm;
