//! Agreement with NVIDIA's reference ꟻLIP (flip-evaluator, see tools/flip_reference.py)
//! on the pairs of tests/common: mean errors within 1e-3 relative, probe pixels within
//! an absolute tolerance, and the automatic HDR exposure range.

use crate::common::{Pair, expected, pairs};
use radiant_image::flip::{
    DEFAULT_PIXELS_PER_DEGREE, FlipMap, flip_hdr, flip_ldr, hdr_exposure_range,
};
use serde_json::Value;

/// Relative tolerance on mean errors.
const MEAN_RELATIVE_TOLERANCE: f64 = 1e-3;
/// Absolute tolerance on single-pixel errors (the pixel values are in [0, 1]).
const PIXEL_TOLERANCE: f64 = 2e-4;
/// Absolute tolerance on the means of the 8x8 tiles.
const TILE_TOLERANCE: f64 = 2e-4;
/// Tiles per side of the block-mean grid of tools/flip_reference.py.
const TILES: usize = 8;

/// Means over a TILES x TILES grid of equal tiles, row-major from the top left.
fn tile_means(map: &FlipMap) -> Vec<f64> {
    let (tw, th) = (map.width / TILES, map.height / TILES);
    let mut out = Vec::new();
    for by in 0..TILES {
        for bx in 0..TILES {
            let mut sum = 0.0;
            for y in by * th..(by + 1) * th {
                for x in bx * tw..(bx + 1) * tw {
                    sum += map.error_at(x, y) as f64;
                }
            }
            out.push(sum / (tw * th) as f64);
        }
    }
    out
}

fn expected_pair(name: &str) -> Value {
    expected()["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no expected values for {name}"))
        .clone()
}

/// Compares one map with its expected values and returns a list of failures.
fn compare(pair: &Pair, range: &str, map: &FlipMap, expected: &Value) -> Vec<String> {
    let mut failures = Vec::new();
    let want = expected["mean"].as_f64().unwrap();
    let rel = (map.mean - want).abs() / want;
    println!(
        "{:20} {range}: mean {:.6} reference {:.6} (rel {:.2e})",
        pair.name, map.mean, want, rel
    );
    if rel > MEAN_RELATIVE_TOLERANCE {
        failures.push(format!(
            "{} {range}: mean {} vs {want}",
            pair.name, map.mean
        ));
    }
    let mut worst_pixel = 0.0f64;
    for p in expected["pixels"].as_array().unwrap() {
        let (x, y) = (
            p[0].as_u64().unwrap() as usize,
            p[1].as_u64().unwrap() as usize,
        );
        let want = p[2].as_f64().unwrap();
        let got = map.error_at(x, y) as f64;
        worst_pixel = worst_pixel.max((got - want).abs());
        if (got - want).abs() > PIXEL_TOLERANCE {
            failures.push(format!(
                "{} {range}: pixel ({x}, {y}) {got} vs {want}",
                pair.name
            ));
        }
    }
    let mut worst_tile = 0.0f64;
    let tiles = tile_means(map);
    for (i, want) in expected["block_means"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let diff = (tiles[i] - want.as_f64().unwrap()).abs();
        worst_tile = worst_tile.max(diff);
        if diff > TILE_TOLERANCE {
            failures.push(format!(
                "{} {range}: tile {i} {} vs {want}",
                pair.name, tiles[i]
            ));
        }
    }
    println!(
        "{:20} {range}: worst probe pixel {worst_pixel:.2e}, worst tile {worst_tile:.2e}",
        ""
    );
    failures
}

#[test]
fn pixels_per_degree_matches_reference_default() {
    let want = expected()["pixels_per_degree"].as_f64().unwrap();
    assert!((DEFAULT_PIXELS_PER_DEGREE as f64 - want).abs() < 1e-4);
}

#[test]
fn ldr_flip_matches_reference() {
    let mut failures = Vec::new();
    for pair in pairs() {
        let (r, t) = (&pair.ldr_reference, &pair.ldr_test);
        let map = flip_ldr(
            &t.pixels,
            &r.pixels,
            r.width,
            r.height,
            DEFAULT_PIXELS_PER_DEGREE,
        )
        .unwrap();
        failures.extend(compare(
            &pair,
            "LDR",
            &map,
            &expected_pair(pair.name)["ldr"],
        ));
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn hdr_flip_matches_reference() {
    let mut failures = Vec::new();
    for pair in pairs() {
        let (r, t) = (&pair.hdr_reference, &pair.hdr_test);
        let want = expected_pair(pair.name)["hdr"].clone();
        let map = flip_hdr(
            &t.pixels,
            &r.pixels,
            r.width,
            r.height,
            DEFAULT_PIXELS_PER_DEGREE,
            None,
        )
        .unwrap();
        let (start, stop) = hdr_exposure_range(&r.pixels);
        let want_start = want["start_exposure"].as_f64().unwrap();
        let want_stop = want["stop_exposure"].as_f64().unwrap();
        println!(
            "{:20} exposures [{start:.5}, {stop:.5}] x{} reference [{want_start:.5}, {want_stop:.5}] x{}",
            pair.name,
            map.exposures.len(),
            want["num_exposures"]
        );
        if (start as f64 - want_start).abs() > 1e-4 || (stop as f64 - want_stop).abs() > 1e-4 {
            failures.push(format!("{}: exposure range ({start}, {stop})", pair.name));
        }
        if map.exposures.len() as u64 != want["num_exposures"].as_u64().unwrap() {
            failures.push(format!("{}: {} exposures", pair.name, map.exposures.len()));
        }
        failures.extend(compare(&pair, "HDR", &map, &want));
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn ldr_flip_at_other_pixels_per_degree_matches_reference() {
    let pair = pairs()
        .into_iter()
        .find(|p| p.name == "cornell_noise")
        .unwrap();
    let want = expected_pair(pair.name)["ldr_low_ppd"].clone();
    let ppd = want["pixels_per_degree"].as_f64().unwrap() as f32;
    let (r, t) = (&pair.ldr_reference, &pair.ldr_test);
    let map = flip_ldr(&t.pixels, &r.pixels, r.width, r.height, ppd).unwrap();
    let failures = compare(&pair, "LDR 30 ppd", &map, &want);
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn hdr_flip_with_given_exposures_matches_reference() {
    let pair = pairs()
        .into_iter()
        .find(|p| p.name == "cornell_blur")
        .unwrap();
    let want = expected_pair(pair.name)["hdr_fixed_exposure"].clone();
    let start = want["start_exposure"].as_f64().unwrap() as f32;
    let stop = want["stop_exposure"].as_f64().unwrap() as f32;
    let (r, t) = (&pair.hdr_reference, &pair.hdr_test);
    let map = flip_hdr(
        &t.pixels,
        &r.pixels,
        r.width,
        r.height,
        DEFAULT_PIXELS_PER_DEGREE,
        Some((start, stop)),
    )
    .unwrap();
    assert_eq!(
        map.exposures.len() as u64,
        want["num_exposures"].as_u64().unwrap()
    );
    assert_eq!(
        (map.exposures[0], *map.exposures.last().unwrap()),
        (start, stop)
    );
    let failures = compare(&pair, "HDR fixed", &map, &want);
    assert!(failures.is_empty(), "{failures:#?}");
}
