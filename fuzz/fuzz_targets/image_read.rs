//! Any bytes as an image file: PFM is decoded from memory, EXR and PNG through a
//! file (their readers take paths), chosen by the first byte. Errors, never panics.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = radiant_image::pfm::decode_pfm(data);
    let ext = match data.first() {
        Some(0x76) => "exr", // EXR magic 76 2f 31 01
        Some(0x89) => "png", // PNG magic 89 'P' 'N' 'G'
        _ => return,
    };
    let path = std::env::temp_dir().join(format!("radiant-fuzz-{}.{ext}", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        match ext {
            "exr" => {
                let _ = radiant_image::exr::read_exr(&path);
                let _ = radiant_image::exr::read_exr_attributes(&path);
            }
            _ => {
                let _ = radiant_image::png::read_png(&path);
            }
        }
    }
});
