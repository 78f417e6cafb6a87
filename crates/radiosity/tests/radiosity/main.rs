//! Tests of the radiosity solver: closed-form and tabulated form factors and solutions
//! from the shared data (formfactors.json, enclosures.json, hemicube_errors.json),
//! physical invariants (closure, reciprocity, energy balance) on meshed scenes, and the
//! exports read back. One binary with a module per topic; the tests that need the whole
//! pipeline (`radiant::Session`) are in crates/radiant/tests/radiosity.rs.

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
