//! The realistic camera inside the renderer: under a uniform sky of unit radiance every
//! pixel is the film irradiance per unit radiance, so the image centre must equal the
//! lens's axial irradiance (pbrt convention, `axial_E0_pbrt_weight_mean` in
//! `lenses.json`) and the image must fall off towards the corners (vignetting, cos⁴).

mod common;

use radiant::color::Rgb;
use radiant::render::Overrides;
use radiant::scene::builtin::furnace;
use radiant::scene::{CameraKind, LightDesc};

fn sky_image(lens: &str, aperture_mm: f32) -> radiant::image::Image {
    let mut desc = furnace();
    desc.shapes.clear();
    desc.lights.push(LightDesc::Infinite {
        radiance: Rgb::WHITE,
        image: None,
        loc: desc.camera.loc.clone(),
    });
    desc.camera.kind = CameraKind::Realistic {
        lens_file: common::shared(&format!("data/lenses/{lens}")),
        aperture_diameter_mm: aperture_mm,
        focus_distance: f32::INFINITY,
    };
    common::render(
        &desc,
        &Overrides {
            spp: Some(1024),
            resolution: Some((49, 49)),
            ..Default::default()
        },
    )
}

fn json_figure(lens: &str, key: &str) -> f64 {
    let text = std::fs::read_to_string(common::shared("data/lenses/lenses.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["summary"][lens][key].as_f64().unwrap()
}

#[test]
fn sky_through_dgauss_gives_the_axial_irradiance_and_vignettes() {
    let img = sky_image("dgauss.50mm.dat", 17.1);
    // The central 3x3 pixels span ±0.75 mm of film, where the fall-off is below 0.3 %.
    // One sample's weight has a relative spread of about 0.45 (a quarter of the pupil
    // rectangle is blocked), so 9 × 1024 samples leave a noise of about 0.5 %.
    let centre = (23..26)
        .flat_map(|y| (23..26).map(move |x| (x, y)))
        .map(|(x, y)| img.get(x, y).g as f64)
        .sum::<f64>()
        / 9.0;
    // pbrt's mean ray weight on the axis at infinity focus (lenses.json).
    let e0 = json_figure("dgauss.50mm.dat", "axial_E0_pbrt_weight_mean");
    assert!((centre - e0).abs() < 0.025 * e0, "centre {centre} vs {e0}");
    // Corner: relative illumination 0.32 in lenses.json for the 35 mm diagonal; the
    // corner pixel's centre sits slightly inside the corner, so allow 25 %.
    let corner = img.get(0, 0).g as f64 / centre;
    eprintln!("centre {centre:.5} vs E0 {e0:.5}; corner ratio {corner:.4}");
    let expected = json_figure("dgauss.50mm.dat", "relative_illumination_corner");
    assert!(
        (corner - expected).abs() < 0.25 * expected,
        "corner ratio {corner} vs {expected}"
    );
    // Symmetric fall-off: the four corners agree.
    let c = [
        img.get(0, 0).g,
        img.get(48, 0).g,
        img.get(0, 48).g,
        img.get(48, 48).g,
    ];
    let m = c.iter().sum::<f32>() / 4.0;
    assert!(c.iter().all(|v| (v - m).abs() < 0.05 * m), "{c:?}");
}
