//! Writes a demo report from synthetic images, to see the page without rendering.
//!
//! `cargo run --release --example demo_report [OUT.html]` (default
//! `target/demo_report.html`). The "reference" is a smooth gradient with an HDR light;
//! each "method" adds noise of a different kind and level, and the convergence series
//! follow the power laws each method is known for. The ꟻLIP maps are stand-ins (a
//! squashed relative difference), not real ꟻLIP.

use radiant_report::{
    CropInfo, Effort, MethodResult, MetricsRow, Precision, ReportImage, Snapshot, StudyReport,
    write_report,
};

const SIZE: usize = 256;

/// Deterministic noise: SplitMix64 of the inputs, mapped to a standard normal (Box–Muller).
fn gaussian(seed: u64, x: usize, y: usize, c: usize) -> f32 {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let h = mix(seed ^ mix((x as u64) << 32 | (y as u64) << 8 | c as u64));
    let u1 = ((h >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let u2 = ((mix(h) >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
}

fn reference() -> ReportImage {
    ReportImage::from_fn(SIZE, SIZE, |x, y| {
        let (u, v) = (x as f32 / SIZE as f32, y as f32 / SIZE as f32);
        // A ceiling light: a small disc far brighter than 1, for the exposure control.
        let (dx, dy) = (u - 0.5, v - 0.12);
        if dx * dx + dy * dy < 0.004 {
            return [12.0, 11.0, 9.0];
        }
        let shade = 0.15 + 0.7 * (1.0 - v) * (0.6 + 0.4 * (6.0 * u).sin().abs());
        [
            shade * (0.4 + 0.6 * u),
            shade * 0.55,
            shade * (1.0 - 0.6 * u),
        ]
    })
}

/// The reference with noise of relative size `sigma` (and a per-method twist).
fn noisy(reference: &ReportImage, seed: u64, sigma: f32, blur: bool) -> ReportImage {
    ReportImage::from_fn(SIZE, SIZE, |x, y| {
        let base = if blur {
            // Photon-mapping-like bias: a box blur smears the light's edge.
            let mut sum = [0.0f32; 3];
            let r = 2i64;
            let mut n = 0.0;
            for j in -r..=r {
                for i in -r..=r {
                    let xx = (x as i64 + i).clamp(0, SIZE as i64 - 1) as usize;
                    let yy = (y as i64 + j).clamp(0, SIZE as i64 - 1) as usize;
                    let p = reference.get(xx, yy);
                    (0..3).for_each(|c| sum[c] += p[c]);
                    n += 1.0;
                }
            }
            sum.map(|s| s / n)
        } else {
            reference.get(x, y)
        };
        let mut out = [0.0; 3];
        for c in 0..3 {
            out[c] = (base[c] * (1.0 + sigma * gaussian(seed, x, y, c))).max(0.0);
        }
        out
    })
}

/// relMSE, RMSE and MAE over all pixels and channels, as `radiant compare` defines them.
fn errors(test: &ReportImage, reference: &ReportImage) -> (f64, f64, f64) {
    let (mut rel, mut se, mut ae) = (0.0f64, 0.0f64, 0.0f64);
    for (t, r) in test.pixels.iter().zip(&reference.pixels) {
        for c in 0..3 {
            let (a, b) = (f64::from(t[c]), f64::from(r[c]));
            rel += (a - b).powi(2) / (b * b + 0.01);
            se += (a - b).powi(2);
            ae += (a - b).abs();
        }
    }
    let n = (3 * test.pixels.len()) as f64;
    (rel / n, (se / n).sqrt(), ae / n)
}

/// A stand-in per-pixel "ꟻLIP" map: the luminance difference, squashed into [0, 1).
fn fake_flip(test: &ReportImage, reference: &ReportImage) -> Vec<f32> {
    let luminance = |p: [f32; 3]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    test.pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(&t, &r)| {
            let d = (luminance(t) - luminance(r)).abs() / (luminance(r) + 0.05);
            d / (1.0 + d)
        })
        .collect()
}

/// How a synthetic method behaves.
struct Behaviour {
    name: &'static str,
    effort: Effort,
    seconds: f64,
    /// Exponent of relMSE against samples (−1 for unbiased Monte Carlo).
    slope: f64,
    /// relMSE the method converges to (its bias); 0 for consistent methods.
    floor: f64,
    /// Seconds spent before the first sample (photon tracing, form factors).
    startup: f64,
}

/// A method whose relMSE follows `c × samples^slope + floor` over 8 snapshots, each
/// doubling the samples of the one before.
fn method(b: Behaviour, image: ReportImage, reference: &ReportImage) -> MethodResult {
    let (relmse, rmse, mae) = errors(&image, reference);
    let flip = fake_flip(&image, reference);
    let flip_mean = flip.iter().map(|&v| f64::from(v)).sum::<f64>() / flip.len() as f64;
    let total = b.effort.count();
    let convergence = (0..8)
        .map(|k| {
            let samples = (total >> (7 - k)).max(1);
            let frac = samples as f64 / total as f64;
            Snapshot {
                seconds: b.startup + (b.seconds - b.startup) * frac,
                samples,
                relmse: (relmse - b.floor) * frac.powf(b.slope) + b.floor,
                flip_mean: Some(flip_mean * frac.powf(b.slope / 2.0)),
            }
        })
        .collect();
    MethodResult {
        name: b.name.to_string(),
        image,
        flip_map: Some(flip),
        metrics: MetricsRow {
            relmse,
            rmse,
            mae,
            flip_mean: Some(flip_mean),
            seconds: b.seconds,
            effort: b.effort,
        },
        convergence,
    }
}

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/demo_report.html".to_string());
    let r = reference();
    let methods = vec![
        method(
            Behaviour {
                name: "path tracing",
                effort: Effort::SamplesPerPixel(256),
                seconds: 41.0,
                slope: -1.0,
                floor: 0.0,
                startup: 0.0,
            },
            noisy(&r, 1, 0.35, false),
            &r,
        ),
        method(
            Behaviour {
                name: "photon mapping",
                effort: Effort::SamplesPerPixel(128),
                seconds: 18.0,
                slope: -1.0,
                floor: 0.004,
                startup: 2.5,
            },
            noisy(&r, 2, 0.12, true),
            &r,
        ),
        method(
            Behaviour {
                name: "SPPM",
                effort: Effort::Iterations(512),
                seconds: 35.0,
                slope: -2.0 / 3.0,
                floor: 0.0,
                startup: 1.5,
            },
            noisy(&r, 3, 0.2, false),
            &r,
        ),
        method(
            Behaviour {
                name: "radiosity",
                effort: Effort::Iterations(128),
                seconds: 9.0,
                slope: -1.3,
                floor: 0.01,
                startup: 3.0,
            },
            noisy(&r, 4, 0.05, true),
            &r,
        ),
    ];
    let report = StudyReport {
        scene: "synthetic demo".to_string(),
        notes: vec![
            "reference: a synthetic gradient with an HDR light (values up to 12)".to_string(),
            "methods: the reference plus synthetic noise; ꟻLIP maps are stand-ins".to_string(),
        ],
        camera: Some("none (synthetic), 256×256".to_string()),
        crop: Some(CropInfo {
            x0: 16,
            y0: 48,
            x1: 240,
            y1: 240,
        }),
        reference: r,
        methods,
        precision: Precision::F32,
    };
    let html = write_report(&report);
    if let Err(e) = std::fs::write(&out, &html) {
        eprintln!("cannot write {out}: {e}");
        std::process::exit(1);
    }
    println!("wrote {out} ({:.1} MB)", html.len() as f64 / 1e6);
}
