//! Where test data lives: the repository's own files (`scenes/`, `tests/`) and the
//! shared data beside the repository (`../shared`: reference images, lens files, real
//! scenes), which `RADIANT_SHARED` can point elsewhere.

use std::path::PathBuf;

/// The repository's root (the workspace folder).
pub fn repo_root() -> PathBuf {
    let kit = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    kit.parent()
        .and_then(|crates| crates.parent())
        .expect("the test kit lives in crates/testkit")
        .to_path_buf()
}

/// A file or folder of the repository, e.g. `repo_path("scenes/cornell-box.pbrt")`.
pub fn repo_path(rel: &str) -> PathBuf {
    repo_root().join(rel)
}

/// The shared data folder: `$RADIANT_SHARED`, or `../shared` beside the repository.
pub fn shared_root() -> PathBuf {
    std::env::var_os("RADIANT_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo_root().join("../shared"))
}

/// A file under the shared data folder; panics with a clear message when it is missing.
pub fn shared(rel: &str) -> PathBuf {
    let p = shared_root().join(rel);
    assert!(
        p.exists(),
        "missing shared data {} (is ../shared beside the repository?)",
        p.display()
    );
    p
}

/// A folder for what a test writes for inspection (difference maps of failed
/// comparisons): `$CARGO_TARGET_DIR/test-output/<name>`, or `target/test-output/<name>`
/// in the repository. Created if missing.
pub fn output_dir(name: &str) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo_root().join("target"));
    let dir = target.join("test-output").join(name);
    std::fs::create_dir_all(&dir)
        .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    dir
}
