//! Any bytes given as a scene file: the parser returns a scene or a located error,
//! never panics. Relative includes resolve inside the corpus folder.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = radiant_scene::parse_str(text, "fuzz.pbrt", Path::new("corpus/scene_parse"));
});
