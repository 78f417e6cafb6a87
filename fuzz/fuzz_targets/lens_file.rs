//! Any bytes as a lens prescription: parsed, and a parsed one built into a lens
//! system, with an error (never a panic) for what is not a lens.
#![no_main]

use libfuzzer_sys::fuzz_target;
use radiant_render::camera::realistic::{LensPrescription, LensSystem};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(prescription) = LensPrescription::parse(text, "fuzz.dat") {
        let _ = LensSystem::new(&prescription);
    }
});
