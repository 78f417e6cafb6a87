//! Acceptance tests of the radiosity module against the reference data in
//! `../shared/data` (formfactors.json, enclosures.json, hemicube_errors.json).

mod common;
mod computed;
mod cornell_radiance;
mod enclosures;
mod export;
mod formfactors;
mod hemicube;
mod mesh_checks;
mod meshes;
mod pipeline;
mod refinement;
