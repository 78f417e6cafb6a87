//! Any bytes as an OBJ mesh (through a file, as the reader takes a path): a mesh or a
//! file error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("radiant-fuzz-{}.obj", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = radiant_scene::obj::read_obj(&path);
    }
});
