//! Checks against the reference renders in `../shared/refs`: the EXR and PFM copies of
//! each reference must agree pixel for pixel, and their mean must match the `mean` line of
//! the matching `*.noise.txt` (written by the tool that made the references).

use std::path::{Path, PathBuf};

use super::{compare, read_image};

fn refs_dir() -> PathBuf {
    radiant_testkit::shared_root().join("refs")
}

/// The `mean` figure from a `*.noise.txt` file, if it has one.
fn noise_mean(path: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(path).ok()?;
    text.lines().find_map(|line| {
        let mut it = line.split_whitespace();
        (it.next() == Some("mean")).then(|| it.next()?.parse().ok())?
    })
}

#[test]
fn exr_and_pfm_references_agree() {
    let dir = refs_dir();
    for stem in [
        "cornell-box-256-ref",
        "cornell-caustics-256-ref",
        "furnace-64-analytic",
    ] {
        let exr = read_image(dir.join(format!("{stem}.exr"))).unwrap();
        let pfm = read_image(dir.join(format!("{stem}.pfm"))).unwrap();
        assert_eq!((exr.width, exr.height), (pfm.width, pfm.height), "{stem}");
        // Both copies hold the same float32 data (PFM is float32; if the EXR were half
        // the difference would be bounded by half's 2^-11 relative precision instead).
        let m = compare(&exr, &pfm, None).unwrap();
        assert_eq!(m.nonfinite, 0, "{stem}");
        let max_rel = exr
            .pixels
            .iter()
            .zip(&pfm.pixels)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs() / b[c].abs().max(1e-6)))
            .fold(0.0f32, f32::max);
        assert!(
            max_rel <= 2f32.powi(-11),
            "{stem}: max relative difference {max_rel}"
        );

        if let Some(mean) = noise_mean(&dir.join(format!("{stem}.noise.txt"))) {
            // noise.txt prints 6 significant digits: rounding moves a mean of ~0.15 by
            // up to 5e-7, i.e. 3.3e-6 relative; 1e-5 relative leaves room for that only.
            for img in [&exr, &pfm] {
                let got = img.mean();
                assert!(
                    ((got - mean) / mean).abs() < 1e-5,
                    "{stem}: mean {got} vs noise.txt {mean}"
                );
            }
        }
    }
}

#[test]
fn cornell_box_reference_is_plausible() {
    let img = read_image(refs_dir().join("cornell-box-256-ref.exr")).unwrap();
    assert_eq!((img.width, img.height), (256, 256));
    assert!(
        img.pixels
            .iter()
            .all(|p| p.is_finite() && p.min_component() >= 0.0)
    );
}
