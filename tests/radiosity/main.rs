//! Acceptance tests of the radiosity module against the reference data in
//! `../shared/data` (formfactors.json, enclosures.json, hemicube_errors.json).

mod common;
mod computed;
mod enclosures;
mod formfactors;
mod hemicube;
mod meshes;
