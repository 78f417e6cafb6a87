//! The side-by-side figure of the radiosity docs: path traced | radiosity | false-colour
//! relative squared error of the radiosity image against a reference.
//!
//! ```text
//! cargo run --release --example radiosity_figure -- PT.exr RADIOSITY.exr REF.exr OUT.png [SCALE]
//! ```
//! SCALE is the error at the top of the colour ramp (default: the largest pixel error).

use radiant::color::Rgb;
use radiant::image::falsecolor::{ErrorMetric, false_color_error};
use radiant::image::{Image, ImageMeta, compare, read_image, write_image};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: radiosity_figure PT.exr RADIOSITY.exr REF.exr OUT.png [SCALE]".into());
    }
    let traced = read_image(&args[0])?;
    let radiosity = read_image(&args[1])?;
    let reference = read_image(&args[2])?;
    let scale = args.get(4).map(|s| s.parse::<f32>()).transpose()?;
    let error = false_color_error(&radiosity, &reference, ErrorMetric::RelativeSquared, scale)?;
    let m = compare(&radiosity, &reference, None)?;
    println!(
        "radiosity vs reference: relMSE {:.3e}, mean {:.6} vs {:.6} ({:+.2} %), error scale {}",
        m.relmse,
        m.mean_test,
        m.mean_ref,
        100.0 * (m.mean_test / m.mean_ref - 1.0),
        error.scale
    );
    let gap = 4;
    let (w, h) = (reference.width, reference.height);
    let mut out = Image::new(3 * w + 2 * gap, h);
    out.pixels.fill(Rgb::WHITE);
    for (panel, image) in [&traced, &radiosity, &error.image].into_iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                out.set(panel * (w + gap) + x, y, image.get(x, y));
            }
        }
    }
    write_image(&args[3], &out, &ImageMeta::default(), 0.0)?;
    Ok(())
}
