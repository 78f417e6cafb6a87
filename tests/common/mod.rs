//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use radiant::image::Image;
use radiant::render::{Overrides, Progress, Session};
use radiant::scene::SceneDesc;

/// A file under `../shared` (the data beside the repository); `RADIANT_SHARED` overrides.
pub fn shared(rel: &str) -> PathBuf {
    let base = std::env::var_os("RADIANT_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared"));
    let p = base.join(rel);
    assert!(
        p.exists(),
        "missing shared data {} (is ../shared beside the repository?)",
        p.display()
    );
    p
}

/// Renders a scene with the given overrides on all cores.
pub fn render(desc: &SceneDesc, overrides: &Overrides) -> Image {
    let session = Session::new(desc, overrides).expect("scene builds");
    session.render(&Progress::default()).film.image()
}

/// Reads `key value` lines of a reference's `.noise.txt`.
pub fn noise_figure(rel: &str, key: &str) -> f64 {
    let text = std::fs::read_to_string(shared(rel)).expect("noise file");
    text.lines()
        .find_map(|l| {
            let mut it = l.split_whitespace();
            (it.next() == Some(key)).then(|| it.next().and_then(|v| v.parse().ok()))?
        })
        .unwrap_or_else(|| panic!("{key} not in {rel}"))
}
