//! A scene that parses is also built (world, BVH, lights, camera) and rendered at
//! 8×8 pixels, 1 sample, by the path tracer: no stage may panic on what the parser
//! accepted.
#![no_main]

use libfuzzer_sys::fuzz_target;
use radiant::Session;
use radiant_render::{Overrides, Progress};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(desc) = radiant_scene::parse_str(text, "fuzz.pbrt", Path::new("corpus/scene_parse"))
    else {
        return;
    };
    let overrides = Overrides {
        spp: Some(1),
        seed: Some(1),
        resolution: Some((8, 8)),
        integrator: Some("path".into()),
    };
    if let Ok(session) = Session::new(&desc, &overrides) {
        let _ = session.render(&Progress::default());
    }
});
