//! A small study report with known pixels and numbers, shared by the integration tests.
#![allow(dead_code)] // each test binary uses a different part

use radiant_report::{
    CropInfo, Effort, MethodResult, MetricsRow, Precision, ReportImage, Snapshot, StudyReport,
};

pub const W: usize = 64;
pub const H: usize = 48;
/// The pixel the page's self-test examines: the image centre.
pub const CX: usize = W / 2;
pub const CY: usize = H / 2;
/// Reference value at the centre pixel.
pub const REF_CENTER: [f32; 3] = [0.2, 0.5, 0.05];
/// First method's value there: 2 above the reference in every channel, so its relative
/// squared error (over 100) is beyond the top of the default 10^-4…10^0 error scale.
pub const ALPHA_CENTER: [f32; 3] = [2.2, 2.5, 2.05];

/// Top knots of the page's colour maps (viridis for relative error, magma for ꟻLIP).
pub const VIRIDIS_TOP: [u8; 3] = [253, 231, 37];
pub const MAGMA_TOP: [u8; 3] = [252, 253, 191];

/// Deterministic pseudo-random value in [0, 1) from a pixel and a seed.
fn hash01(x: usize, y: usize, seed: u64) -> f32 {
    let mut z = (x as u64) << 40 ^ (y as u64) << 20 ^ seed;
    z = (z ^ (z >> 33)).wrapping_mul(0xff51_afd7_ed55_8ccd);
    z = (z ^ (z >> 33)).wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    z ^= z >> 33;
    (z >> 40) as f32 / (1u64 << 24) as f32
}

pub fn reference() -> ReportImage {
    let mut img =
        ReportImage::from_fn(W, H, |x, y| [x as f32 / W as f32, y as f32 / H as f32, 0.3]);
    img.pixels[CY * W + CX] = REF_CENTER;
    img
}

fn metrics(relmse: f64, flip: Option<f64>, seconds: f64, effort: Effort) -> MetricsRow {
    MetricsRow {
        relmse,
        rmse: relmse.sqrt() * 0.7,
        mae: relmse * 0.31,
        flip_mean: flip,
        seconds,
        effort,
    }
}

fn series(relmse: f64, seconds: f64, samples: u64, slope: f64) -> Vec<Snapshot> {
    (0..6)
        .map(|k| {
            let frac = 0.5f64.powi(5 - k);
            Snapshot {
                seconds: seconds * frac,
                samples: ((samples as f64) * frac).max(1.0) as u64,
                relmse: relmse * frac.powf(slope),
                flip_mean: Some(0.2 * frac.powf(0.5 * slope)),
            }
        })
        .collect()
}

/// Three methods: "alpha" (with a ꟻLIP map), "beta & <b>" (no map; the name checks
/// escaping) and "gamma" (a different size, so it has no error views).
pub fn study(precision: Precision) -> StudyReport {
    let reference = reference();
    let mut alpha = ReportImage::from_fn(W, H, |x, y| {
        let r = reference.get(x, y);
        let n = 0.8 + 0.4 * hash01(x, y, 1);
        [r[0] * n, r[1] * n, r[2] * n]
    });
    alpha.pixels[CY * W + CX] = ALPHA_CENTER;
    let mut flip: Vec<f32> = (0..W * H).map(|i| hash01(i % W, i / W, 2) * 0.5).collect();
    flip[CY * W + CX] = 1.0;
    let beta = ReportImage::from_fn(W, H, |x, y| {
        let r = reference.get(x, y);
        [r[0] + 0.05, r[1], r[2] * 0.9]
    });
    let gamma = ReportImage::filled(W / 2, H / 2, [0.4, 0.4, 0.4]);
    StudyReport {
        scene: "known pixels </script> & co".to_string(),
        notes: vec!["reference: synthetic gradient".to_string()],
        camera: Some("pinhole, 64×48".to_string()),
        crop: Some(CropInfo {
            x0: 2,
            y0: 3,
            x1: 20,
            y1: 12,
        }),
        reference,
        methods: vec![
            MethodResult {
                name: "alpha".to_string(),
                image: alpha,
                flip_map: Some(flip),
                metrics: metrics(
                    0.0123456789,
                    Some(0.0871),
                    12.5,
                    Effort::SamplesPerPixel(64),
                ),
                convergence: series(0.0123456789, 12.5, 64, -1.0),
            },
            MethodResult {
                name: "beta & <b>".to_string(),
                image: beta,
                flip_map: None,
                metrics: metrics(1.5e-7, None, 3.25, Effort::Iterations(200)),
                convergence: series(1.5e-7, 3.25, 200, -2.0 / 3.0),
            },
            MethodResult {
                name: "gamma".to_string(),
                image: gamma,
                flip_map: None,
                metrics: metrics(2.75, Some(0.5), 1234.0, Effort::Iterations(7)),
                convergence: vec![],
            },
        ],
        precision,
    }
}

/// The sRGB byte a page should show for linear value `v` at `stops` of exposure.
pub fn srgb8(v: f32, stops: f64) -> u8 {
    let x = (f64::from(v) * 2f64.powf(stops)).clamp(0.0, 1.0);
    let e = if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (255.0 * e).round() as u8
}

/// Minimal standard base64 decoder (whitespace ignored), independent of the crate's encoder.
pub fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {c}"),
        }
    };
    let clean: Vec<u8> = text.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
    let mut out = Vec::new();
    for quad in clean.chunks(4) {
        let pad = quad.iter().filter(|&&b| b == b'=').count();
        let n = quad
            .iter()
            .map(|&b| if b == b'=' { 0 } else { value(b) })
            .fold(0u32, |acc, v| acc << 6 | v);
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    out
}

/// The text of the element `<script ... id="ID" ...>` in `html`.
pub fn script_text<'a>(html: &'a str, id: &str) -> Option<&'a str> {
    let marker = format!("id=\"{id}\"");
    let at = html.find(&marker)?;
    let start = at + html[at..].find('>')? + 1;
    let end = start + html[start..].find("</script>")?;
    Some(&html[start..end])
}
