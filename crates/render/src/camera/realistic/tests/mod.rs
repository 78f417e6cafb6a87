//! Tests of the realistic camera. Reference data: ../shared/data/lenses (lens files and
//! lenses.json, an independent Python y-nu trace and pbrt-v4 emulation with full-precision
//! fields next to the 4-decimal summary).

mod camera;
mod closed_form;
mod lensfile;
mod pupil;
mod reference;

use super::LensPrescription;
use std::path::PathBuf;
use std::sync::OnceLock;

/// The four lenses the acceptance criteria name.
pub(super) const LENSES: [&str; 4] = [
    "dgauss.50mm.dat",
    "wide.22mm.dat",
    "fisheye.10mm.dat",
    "telephoto.250mm.dat",
];

pub(super) fn lens_dir() -> PathBuf {
    radiant_testkit::shared_root().join("data/lenses")
}

pub(super) fn lens(name: &str) -> LensPrescription {
    LensPrescription::from_file(lens_dir().join(name)).expect("reference lens parses")
}

/// lenses.json, read once.
pub(super) fn reference() -> &'static serde_json::Value {
    static JSON: OnceLock<serde_json::Value> = OnceLock::new();
    JSON.get_or_init(|| {
        let text = std::fs::read_to_string(lens_dir().join("lenses.json")).expect("lenses.json");
        serde_json::from_str(&text).expect("lenses.json parses")
    })
}

/// The full-precision record of one lens in lenses.json.
pub(super) fn lens_record(name: &str) -> &'static serde_json::Value {
    &reference()["lenses"][name]
}

pub(super) fn num(v: &serde_json::Value) -> f64 {
    v.as_f64()
        .unwrap_or_else(|| panic!("expected a number, found {v}"))
}

pub(super) fn relative_error(value: f64, expected: f64) -> f64 {
    ((value - expected) / expected).abs()
}
