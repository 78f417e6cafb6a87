//! `radiant compare TEST REF`: error metrics of a render against a reference, with the
//! same definitions and output layout as `shared/tools/compare.py`.

use std::path::PathBuf;

use anyhow::Context;
use radiant::image::falsecolor::{ErrorMetric, false_color_error};
use radiant::image::{Crop, ImageMeta, compare, read_image, write_image};

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
}

/// Runs the comparison and prints the figures.
pub fn run(args: CompareArgs) -> anyhow::Result<()> {
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

    let diff_scale = match &args.diff {
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
        ];
        if let Some(s) = diff_scale {
            fields.push(format!("\"diff_scale\": {}", json_number(s as f64)));
        }
        println!("{{{}}}", fields.join(", "));
    } else {
        for (name, v) in [
            ("rmse", m.rmse),
            ("relmse", m.relmse),
            ("mae", m.mae),
            ("mean_test", m.mean_test),
            ("mean_ref", m.mean_ref),
        ] {
            println!("{name} {}", format_g(v, 6));
        }
        println!("nonfinite {}", m.nonfinite);
        if let Some(s) = diff_scale {
            println!("diff_scale {}", format_g(s as f64, 6));
        }
    }
    Ok(())
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
        return "0".into();
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
}
