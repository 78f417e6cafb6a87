//! The test kit: paths to the repository's scenes and the shared reference data,
//! fixtures built on the canonical scenes, and statistical checks, shared by the tests
//! and benchmarks of every crate (a dev-dependency; nothing here ships in the binary).

#![forbid(unsafe_code)]

pub mod chi2;
pub mod data;
pub mod fixtures;

pub use data::{output_dir, repo_path, shared, shared_root};
