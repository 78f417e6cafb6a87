//! Helpers shared by the command-line tests: the binary, scratch folders and what a
//! handled failure looks like.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `radiant` binary Cargo built for these tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_radiant");

/// A command for the binary.
pub fn radiant() -> Command {
    Command::new(BIN)
}

/// The binary run with `args` in `dir`.
pub fn radiant_in(dir: &Path, args: &[&str]) -> Output {
    radiant()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("radiant runs")
}

/// An empty scratch folder for one test, named after it and this process (test
/// binaries run side by side).
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("radiant-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn stderr_of(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

pub fn assert_ok(out: &Output, what: &str) {
    assert!(out.status.success(), "{what}: {}", stderr_of(out));
}

/// A handled error: exit status 1 and no panic (which exits with 101 and prints
/// "panicked"). Returns the message.
pub fn assert_clean_failure(out: &Output, what: &str) -> String {
    let stderr = stderr_of(out);
    assert_eq!(out.status.code(), Some(1), "{what}: {stderr}");
    assert!(!stderr.contains("panicked"), "{what} panicked: {stderr}");
    stderr
}
