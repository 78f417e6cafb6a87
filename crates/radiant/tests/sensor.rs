//! The sensor's imaging ratio, exposure time × ISO / 100 (pbrt-v4), with the exposure
//! time taken from the camera's shutter interval.

use std::path::Path;

use radiant::render::Overrides;
use radiant::scene::parse_str;

mod common;

/// A lit floor seen through `camera_params`, rendered by `integrator`.
fn render(camera_params: &str, integrator: &str) -> radiant::image::Image {
    let text = format!(
        r#"LookAt 0 -3 4  0 0 0  0 0 1
Camera "perspective" "float fov" 45 {camera_params}
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
Sampler "sobol" "integer pixelsamples" 4
Integrator "{integrator}"
WorldBegin
LightSource "point" "point3 from" [0 0 2] "rgb I" [3 3 3]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-3 -3 0  3 -3 0  3 3 0  -3 3 0]
"#
    );
    let desc = parse_str(&text, "t.pbrt", Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    common::render(&desc, &Overrides::default())
}

/// A quarter-second shutter records a quarter of the one-second image, exactly (a power
/// of two scales floating point exactly), whenever the shutter opens.
#[test]
fn the_shutter_interval_scales_the_image_as_the_exposure_time() {
    for integrator in ["path", "sppm"] {
        let second = render("", integrator);
        assert!(second.mean() > 0.0);
        for shutter in [
            "\"float shutteropen\" 0 \"float shutterclose\" 0.25",
            "\"float shutteropen\" 0.5 \"float shutterclose\" 0.75",
        ] {
            let quarter = render(shutter, integrator);
            let exact = second
                .pixels
                .iter()
                .zip(&quarter.pixels)
                .all(|(a, b)| (*a * 0.25).to_array() == b.to_array());
            assert!(
                exact,
                "{integrator} {shutter}: {} against {}",
                quarter.mean(),
                second.mean()
            );
        }
    }
}
