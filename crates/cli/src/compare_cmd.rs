//! `radiant compare TEST REF`: error metrics of a render against a reference, with the
//! same definitions and output layout as `shared/tools/compare.py`.

use std::path::PathBuf;

use anyhow::{Context, bail};
use radiant::color::Rgb;
use radiant::image::exr::read_exr_attributes;
use radiant::image::falsecolor::{ErrorMetric, false_color_error};
use radiant::image::flip::{DEFAULT_PIXELS_PER_DEGREE, FlipMap};
use radiant::image::png::srgb_eotf;
use radiant::image::{Crop, Image, ImageMeta, compare, read_image, write_image};
use radiant::report::{Effort, write_report};

/// Arguments of `radiant compare`.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// The image under test (.exr, .pfm or .png).
    pub test: PathBuf,
    /// The reference image; relMSE is relative to it.
    pub reference: PathBuf,
    /// Also write a false-colour PNG of the per-pixel relative squared error
    /// (dark violet = 0, light yellow = the scale, magenta = NaN/inf in TEST).
    #[arg(long, value_name = "OUT.png")]
    pub diff: Option<PathBuf>,
    /// Error at the top of the --diff colour ramp (default: the largest pixel error).
    #[arg(long, value_name = "VALUE", requires = "diff")]
    pub diff_scale: Option<f32>,
    /// Compare only pixels x0 <= x < x1, y0 <= y < y1 (row 0 at the top).
    #[arg(long, value_name = "X0,Y0,X1,Y1")]
    pub crop: Option<Crop>,
    /// Print one JSON object instead of one figure per line.
    #[arg(long)]
    pub json: bool,
    /// Also compute the mean HDR-ꟻLIP error (Andersson et al. 2020, 2021) of the linear
    /// images at the default viewing condition (67 pixels per degree), over --crop; with
    /// --diff the PNG shows the ꟻLIP map (magma colours) instead.
    #[arg(long)]
    pub flip: bool,
    /// Also write the interactive report viewer (zoom, swipe, exposure, error views)
    /// for the two images.
    #[arg(long, value_name = "OUT.html")]
    pub html: Option<PathBuf>,
}

/// Runs the comparison and prints the figures.
pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    // Output paths are refused before the images are read and measured.
    if let Some(out) = &args.diff {
        crate::render_cmd::check_output(out)?;
    }
    if let Some(out) = &args.html {
        radiant::image::atomic::check_writable(out)
            .with_context(|| format!("cannot write {}", out.display()))?;
    }
    let test = read_image(&args.test)
        .with_context(|| format!("cannot read test image {}", args.test.display()))?;
    let reference = read_image(&args.reference)
        .with_context(|| format!("cannot read reference image {}", args.reference.display()))?;
    let context = || {
        format!(
            "comparing {} against {}",
            args.test.display(),
            args.reference.display()
        )
    };
    let m = compare(&test, &reference, args.crop).with_context(context)?;
    if m.count == 0 {
        bail!(
            "{}: every compared value of the reference is NaN or infinite",
            args.reference.display()
        );
    }
    let flip = if args.flip {
        Some(
            radiant::study::measure(&test, &reference, args.crop, DEFAULT_PIXELS_PER_DEGREE)
                .with_context(context)?,
        )
    } else {
        None
    };
    if let Some(out) = &args.html {
        write_html(out, &args, &test, &reference)?;
    }

    let diff_scale = match &args.diff {
        Some(out) if flip.is_some() => {
            let map = &flip.as_ref().expect("computed above").flip;
            write_flip_png(out, map)?;
            None
        }
        Some(out) => {
            let fc = false_color_error(
                &test,
                &reference,
                ErrorMetric::RelativeSquared,
                args.diff_scale,
            )
            .with_context(context)?;
            write_image(out, &fc.image, &ImageMeta::default(), 0.0)
                .with_context(|| format!("cannot write {}", out.display()))?;
            Some(fc.scale)
        }
        None => None,
    };

    if args.json {
        let mut fields = vec![
            format!("\"rmse\": {}", json_number(m.rmse)),
            format!("\"relmse\": {}", json_number(m.relmse)),
            format!("\"mae\": {}", json_number(m.mae)),
            format!("\"mean_test\": {}", json_number(m.mean_test)),
            format!("\"mean_ref\": {}", json_number(m.mean_ref)),
            format!("\"nonfinite\": {}", m.nonfinite),
            format!("\"nonfinite_ref\": {}", m.nonfinite_ref),
        ];
        if let Some(s) = diff_scale {
            fields.push(format!("\"diff_scale\": {}", json_number(s as f64)));
        }
        if let Some(f) = &flip {
            fields.push(format!("\"flip_mean\": {}", json_number(f.flip_mean)));
        }
        out!("{{{}}}", fields.join(", "));
    } else {
        for (name, v) in [
            ("rmse", m.rmse),
            ("relmse", m.relmse),
            ("mae", m.mae),
            ("mean_test", m.mean_test),
            ("mean_ref", m.mean_ref),
        ] {
            out!("{name} {}", format_g(v, 6));
        }
        out!("nonfinite {}", m.nonfinite);
        out!("nonfinite_ref {}", m.nonfinite_ref);
        if let Some(s) = diff_scale {
            out!("diff_scale {}", format_g(s as f64, 6));
        }
        if let Some(f) = &flip {
            out!("flip_mean {}", format_g(f.flip_mean, 6));
        }
    }
    Ok(())
}

/// The ꟻLIP map as a PNG of its magma colours (the 8-bit values are decoded to linear
/// so the sRGB writer puts back exactly those bytes).
fn write_flip_png(out: &std::path::Path, map: &FlipMap) -> anyhow::Result<()> {
    let pixels = map
        .to_magma()
        .iter()
        .map(|c| Rgb::from_array(c.map(|b| srgb_eotf(f32::from(b) / 255.0))))
        .collect();
    let image = Image {
        width: map.width,
        height: map.height,
        pixels,
    };
    write_image(out, &image, &ImageMeta::default(), 0.0)
        .with_context(|| format!("cannot write {}", out.display()))
}

/// The report viewer with TEST as the one method against REF; samples and time come
/// from the EXR header when it has them.
fn write_html(
    out: &std::path::Path,
    args: &CompareArgs,
    test: &Image,
    reference: &Image,
) -> anyhow::Result<()> {
    let attrs = read_exr_attributes(&args.test).ok();
    let spp = attrs
        .as_ref()
        .and_then(|a| a.samples_per_pixel)
        .unwrap_or(0);
    let seconds = attrs
        .as_ref()
        .and_then(|a| a.render_time_seconds)
        .map_or(0.0, f64::from);
    let name = args
        .test
        .file_name()
        .map_or_else(|| "test".to_string(), |n| n.to_string_lossy().into_owned());
    let mut report = radiant::study::comparison_report(
        &name,
        test,
        reference,
        args.crop,
        DEFAULT_PIXELS_PER_DEGREE,
        seconds,
        Effort::SamplesPerPixel(spp.max(0) as u64),
    )
    .with_context(|| {
        format!(
            "comparing {} against {}",
            args.test.display(),
            args.reference.display()
        )
    })?;
    report
        .notes
        .push(format!("reference: {}", args.reference.display()));
    let html = write_report(&report);
    radiant::image::atomic::atomic_write_bytes(out, html.as_bytes())
        .with_context(|| format!("cannot write {}", out.display()))
}

/// A JSON number; JSON has no NaN or infinity, so those become `null`.
fn json_number(v: f64) -> String {
    if v.is_finite() {
        format!("{v:?}")
    } else {
        "null".to_string()
    }
}

/// C's `%.{digits}g`: `digits` significant digits, exponent form outside 1e-4 ..
/// 1e`digits`, trailing zeros removed — the layout compare.py prints.
pub fn format_g(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return if v.is_nan() {
            "nan".into()
        } else if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    if v == 0.0 {
        // C keeps the sign of zero: "-0".
        return if v.is_sign_negative() { "-0" } else { "0" }.into();
    }
    let digits = digits.max(1);
    // The exponent after rounding to `digits` significant digits.
    let sci = format!("{:.*e}", digits - 1, v);
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let trim = |s: &str| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if exp < -4 || exp >= digits as i32 {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", trim(mantissa), exp.abs())
    } else {
        let decimals = (digits as i32 - 1 - exp).max(0) as usize;
        trim(&format!("{v:.decimals$}"))
    }
}

#[cfg(test)]
mod tests {
    use super::format_g;

    #[test]
    fn format_g_matches_printf() {
        // Expected strings are what Python's f"{v:.6g}" prints.
        assert_eq!(format_g(0.150794123, 6), "0.150794");
        assert_eq!(format_g(1.85112e-05, 6), "1.85112e-05");
        assert_eq!(format_g(0.0001, 6), "0.0001");
        assert_eq!(format_g(123456789.0, 6), "1.23457e+08");
        assert_eq!(format_g(999999.5, 6), "1e+06");
        assert_eq!(format_g(100.0, 6), "100");
        assert_eq!(format_g(-2.5, 6), "-2.5");
        assert_eq!(format_g(0.0, 6), "0");
    }

    #[test]
    fn format_g_matches_printf_at_nine_digits() {
        // pbrt-v4's MSE lines use "%.9g"; expected strings are C's printf output.
        for (v, c) in [
            (0.0003969466478, "0.000396946648"),
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (100.0, "100"),
            (123456789.0, "123456789"),
            (1234567890.0, "1.23456789e+09"),
            (123456789012.0, "1.23456789e+11"),
            (999999999.5, "1e+09"),
            (1e-05, "1e-05"),
            (0.0001, "0.0001"),
            (9.9999999995e-05, "0.0001"),
            (2.5e-10, "2.5e-10"),
            (1.0 / 3.0, "0.333333333"),
            (0.1 + 0.2, "0.3"),
        ] {
            assert_eq!(format_g(v, 9), c, "{v:e}");
        }
    }
}
