//! Properties of ꟻLIP that hold independently of the reference implementation:
//! identity, symmetry, range, mirror invariance, closed-form flat-image errors, the
//! HDR maximum over exposures and invariance of HDR-ꟻLIP to a common exposure scale.

use crate::common::{Image, noise, pairs, read_pfm};
use radiant_image::flip::{
    DEFAULT_PIXELS_PER_DEGREE, FlipError, MAGMA, flip_color, flip_hdr, flip_ldr,
    hdr_exposure_range, pixels_per_degree,
};

const PPD: f32 = DEFAULT_PIXELS_PER_DEGREE;

fn cornell() -> Image {
    read_pfm(&crate::common::refs().join("cornell-box-256-ref.pfm"))
}

fn noisy(img: &Image, seed: u64, amplitude: f64) -> Image {
    let pixels = img
        .pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (x, y) = (i % img.width, i / img.width);
            [0, 1, 2].map(|c| {
                (p[c] as f64 * (1.0 + amplitude * (2.0 * noise(seed, x, y, c) - 1.0))) as f32
            })
        })
        .collect();
    Image {
        pixels,
        ..img.clone()
    }
}

fn mirrored(img: &Image) -> Image {
    let mut pixels = img.pixels.clone();
    for row in pixels.chunks_mut(img.width) {
        row.reverse();
    }
    Image {
        pixels,
        ..img.clone()
    }
}

#[test]
fn identical_images_give_zero_error() {
    for pair in pairs() {
        let r = &pair.ldr_reference;
        let map = flip_ldr(&r.pixels, &r.pixels, r.width, r.height, PPD).unwrap();
        assert_eq!(map.mean, 0.0, "{}", pair.name);
        assert!(map.errors.iter().all(|&e| e == 0.0));
        let r = &pair.hdr_reference;
        let map = flip_hdr(&r.pixels, &r.pixels, r.width, r.height, PPD, None).unwrap();
        assert_eq!(map.mean, 0.0, "{}", pair.name);
    }
}

#[test]
fn errors_lie_in_unit_interval() {
    for pair in pairs() {
        let (r, t) = (&pair.ldr_reference, &pair.ldr_test);
        let ldr = flip_ldr(&t.pixels, &r.pixels, r.width, r.height, PPD).unwrap();
        let (r, t) = (&pair.hdr_reference, &pair.hdr_test);
        let hdr = flip_hdr(&t.pixels, &r.pixels, r.width, r.height, PPD, None).unwrap();
        for map in [ldr, hdr] {
            assert!(
                map.errors.iter().all(|e| (0.0..=1.0).contains(e)),
                "{}",
                pair.name
            );
            assert!(map.mean > 0.0 && map.mean < 1.0);
        }
    }
}

#[test]
fn ldr_flip_is_symmetric() {
    // Every per-pixel difference in LDR-ꟻLIP is symmetric (HyAB, absolute feature
    // differences), so swapping the images must give the same map.
    let pair = pairs()
        .into_iter()
        .find(|p| p.name == "cornell_noise")
        .unwrap();
    let (r, t) = (&pair.ldr_reference, &pair.ldr_test);
    let a = flip_ldr(&t.pixels, &r.pixels, r.width, r.height, PPD).unwrap();
    let b = flip_ldr(&r.pixels, &t.pixels, r.width, r.height, PPD).unwrap();
    assert_eq!(a.errors, b.errors);
}

#[test]
fn hdr_flip_with_fixed_exposures_is_symmetric() {
    // The only asymmetry of HDR-ꟻLIP is the automatic exposure range.
    let r = cornell();
    let t = noisy(&r, 7, 0.3);
    let range = Some(hdr_exposure_range(&r.pixels));
    let a = flip_hdr(&t.pixels, &r.pixels, r.width, r.height, PPD, range).unwrap();
    let b = flip_hdr(&r.pixels, &t.pixels, r.width, r.height, PPD, range).unwrap();
    assert_eq!(a.errors, b.errors);
}

#[test]
fn mirroring_both_images_mirrors_the_error_map() {
    // All filters are even or odd and borders clamp symmetrically, so the metric has no
    // preferred horizontal direction; only summation order may differ.
    let r = cornell();
    let t = noisy(&r, 3, 0.4);
    let a = flip_hdr(&t.pixels, &r.pixels, r.width, r.height, PPD, None).unwrap();
    let b = flip_hdr(
        &mirrored(&t).pixels,
        &mirrored(&r).pixels,
        r.width,
        r.height,
        PPD,
        None,
    )
    .unwrap();
    let mut worst = 0.0f32;
    for y in 0..r.height {
        for x in 0..r.width {
            worst = worst.max((a.error_at(x, y) - b.error_at(r.width - 1 - x, y)).abs());
        }
    }
    assert!(worst < 1e-5, "worst mirrored difference {worst}");
}

/// The colour error of two flat sRGB images, written out from the paper in f64:
/// sRGB decode → XYZ → CIELAB → Hunt → HyAB → ^0.7 → two-segment remap.
fn flat_color_error(a: [f64; 3], b: [f64; 3]) -> f64 {
    let decode = |c: f64| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let m = [
        [0.4124564, 0.3575761, 0.1804375],
        [0.2126729, 0.7151522, 0.0721750],
        [0.0193339, 0.1191920, 0.9503041],
    ];
    let hunt_lab = |lin: [f64; 3]| {
        let xyz: Vec<f64> = (0..3)
            .map(|r| {
                (m[r][0] * lin[0] + m[r][1] * lin[1] + m[r][2] * lin[2]) / m[r].iter().sum::<f64>()
            })
            .collect();
        let f = |t: f64| {
            if t > (6.0f64 / 29.0).powi(3) {
                t.cbrt()
            } else {
                t / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0
            }
        };
        let l = 116.0 * f(xyz[1]) - 16.0;
        let (a, b) = (
            500.0 * (f(xyz[0]) - f(xyz[1])),
            200.0 * (f(xyz[1]) - f(xyz[2])),
        );
        [l, 0.01 * l * a, 0.01 * l * b]
    };
    let hyab = |p: [f64; 3], q: [f64; 3]| {
        (p[0] - q[0]).abs() + ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    let cmax = hyab(hunt_lab([0.0, 1.0, 0.0]), hunt_lab([0.0, 0.0, 1.0])).powf(0.7);
    let d = hyab(hunt_lab(a.map(decode)), hunt_lab(b.map(decode))).powf(0.7);
    let knee = 0.4 * cmax;
    if d < knee {
        0.95 * d / knee
    } else {
        0.95 + 0.05 * (d - knee) / (cmax - knee)
    }
}

#[test]
fn flat_images_give_the_closed_form_colour_error() {
    let (w, h) = (24, 16);
    for (a, b) in [
        ([0.5, 0.5, 0.5], [0.6, 0.6, 0.6]),
        ([0.2, 0.4, 0.8], [0.25, 0.4, 0.7]),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.02, 0.01, 0.03], [0.0, 0.0, 0.0]),
    ] {
        let ta = vec![a.map(|v: f64| v as f32); w * h];
        let tb = vec![b.map(|v: f64| v as f32); w * h];
        let map = flip_ldr(&ta, &tb, w, h, PPD).unwrap();
        let want = flat_color_error(a, b);
        for &e in &map.errors {
            assert!(
                (e as f64 - want).abs() < 1e-4,
                "{a:?} vs {b:?}: {e} != {want}"
            );
        }
    }
}

#[test]
fn hdr_error_is_the_maximum_over_exposures() {
    let r = cornell();
    let t = noisy(&r, 5, 0.3);
    let (start, stop) = hdr_exposure_range(&r.pixels);
    let all = flip_hdr(
        &t.pixels,
        &r.pixels,
        r.width,
        r.height,
        PPD,
        Some((start, stop)),
    )
    .unwrap();
    let mut max_single = vec![0.0f32; all.errors.len()];
    for &c in &all.exposures {
        let one = flip_hdr(&t.pixels, &r.pixels, r.width, r.height, PPD, Some((c, c))).unwrap();
        assert!(one.errors.iter().zip(&all.errors).all(|(s, a)| s <= a));
        for (m, s) in max_single.iter_mut().zip(&one.errors) {
            *m = m.max(*s);
        }
    }
    assert_eq!(max_single, all.errors);
}

#[test]
fn hdr_flip_ignores_a_common_exposure_scale() {
    // The automatic range follows the reference's luminance, so scaling both images by
    // 2^k shifts every exposure by −k and leaves the tone-mapped images unchanged.
    let r = cornell();
    let t = noisy(&r, 9, 0.3);
    let scale = |img: &Image| {
        img.pixels
            .iter()
            .map(|p| p.map(|v| v * 8.0))
            .collect::<Vec<_>>()
    };
    let a = flip_hdr(&t.pixels, &r.pixels, r.width, r.height, PPD, None).unwrap();
    let b = flip_hdr(&scale(&t), &scale(&r), r.width, r.height, PPD, None).unwrap();
    for (ea, eb) in a.exposures.iter().zip(&b.exposures) {
        assert!((ea - 3.0 - eb).abs() < 1e-4);
    }
    assert!(
        (a.mean - b.mean).abs() < 1e-6 * a.mean.max(1e-3),
        "{} {}",
        a.mean,
        b.mean
    );
}

#[test]
fn more_noise_gives_more_error() {
    let r = cornell();
    let mut previous = 0.0;
    for amplitude in [0.05, 0.1, 0.2, 0.4] {
        let t = noisy(&r, 11, amplitude);
        let m = flip_hdr(&t.pixels, &r.pixels, r.width, r.height, PPD, None).unwrap();
        assert!(
            m.mean > previous,
            "amplitude {amplitude}: {} <= {previous}",
            m.mean
        );
        previous = m.mean;
    }
}

#[test]
fn invalid_inputs_are_refused() {
    let img = vec![[0.5f32; 3]; 12];
    assert!(matches!(
        flip_ldr(&img, &img[..11], 4, 3, PPD),
        Err(FlipError::SizeMismatch { len: 11, .. })
    ));
    assert!(matches!(
        flip_ldr(&img, &img, 0, 3, PPD),
        Err(FlipError::EmptyImage { .. })
    ));
    assert!(matches!(
        flip_ldr(&img, &img, 4, 3, 0.0),
        Err(FlipError::InvalidPixelsPerDegree(_))
    ));
    assert!(matches!(
        flip_hdr(&img, &img, 4, 3, PPD, Some((2.0, 1.0))),
        Err(FlipError::InvalidExposureRange { .. })
    ));
}

#[test]
fn default_viewing_condition_is_67_pixels_per_degree() {
    assert!((pixels_per_degree(0.7, 3840.0, 0.7) - DEFAULT_PIXELS_PER_DEGREE).abs() < 1e-4);
    assert!((DEFAULT_PIXELS_PER_DEGREE - 67.02).abs() < 0.01);
}

#[test]
fn magma_runs_from_black_to_light_yellow_with_rising_lightness() {
    assert_eq!(flip_color(0.0), [0, 0, 4]);
    assert_eq!(flip_color(1.0), [252, 253, 191]);
    assert_eq!(flip_color(-1.0), MAGMA[0]);
    assert_eq!(flip_color(f32::NAN), MAGMA[0]);
    assert_eq!(flip_color(0.5), MAGMA[128]);
    // magma is designed with strictly increasing lightness; CIELAB L* of the 8-bit
    // entries rises by 0.04 to 0.75 per step.
    let lightness = |c: [u8; 3]| {
        let lin = c.map(|v| {
            let v = v as f64 / 255.0;
            if v <= 0.04045 {
                v / 12.92
            } else {
                ((v + 0.055) / 1.055).powf(2.4)
            }
        });
        let y: f64 = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2];
        let f = if y > (6.0f64 / 29.0).powi(3) {
            y.cbrt()
        } else {
            y / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0
        };
        116.0 * f - 16.0
    };
    for i in 1..256 {
        let step = lightness(MAGMA[i]) - lightness(MAGMA[i - 1]);
        assert!(step > 0.0 && step < 1.0, "entry {i}: step {step}");
    }
}
