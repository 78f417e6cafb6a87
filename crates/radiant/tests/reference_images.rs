//! No bias against the Mitsuba 3 references in `shared/refs`: radiant's path tracer on the
//! canonical scenes (`scenes/*.pbrt`, 256 x 256, 1024 spp) must differ from the
//! reference by no more than the two images' noise — over the whole image and in every
//! 16 x 16 tile.
//!
//! Own noise is measured, not assumed: the 1024 samples are four independent passes of
//! 256 (seeds 1..4), and the passes' per-pixel spread gives each tile mean's standard
//! error (`radiant::image::tiles`). The reference ships one noise figure, its per-pixel
//! RMS error `ref_rmse_est` (from two independent halves). It is spread over the tiles
//! in proportion to our own noise — both are path tracers with light sampling on the
//! same scene, so their noise has the same shape — i.e. each tile's reference variance
//! is ours times (ref_rmse_est² / our mean per-pixel variance). That ratio is 0.08
//! (cornell-box) and 0.05 (cornell-caustics), so the model's shape hardly matters.
//!
//! A tile passes when every channel is within 4 standard errors plus 0.3 % of the
//! reference: over 256 tiles x 3 channels an unbiased render exceeds 4 SE with
//! probability about 768 x 6.3e-5 = 5 %, and the seeds are fixed, so a pass is stable.
//! The floor covers what is no noise: the reference's own rounding and renderer-to-
//! renderer differences below a per cent; a 3 % error in one tile is several times
//! the bound (measured tile standard errors: about 0.1 % of the signal in cornell-box,
//! up to 0.5 % in cornell-caustics, whose glass and mirror make the path tracer noisier).
//!
//! The whole-image checks stay: relMSE(test, ref) ≈ σ² + σ²_ref for an unbiased test,
//! with σ² the test's measured per-pixel relative variance; the threshold 1.5 x
//! (σ² + σ²_ref) leaves room for the estimate's own scatter.

mod common;

use radiant::image::metrics::compare;
use radiant::image::tiles::{TileCriterion, TileStats, compare_tiles};
use radiant::image::{Image, read_image};
use radiant::render::Overrides;
use radiant::scene::builtin::builtin_scene;

const TILE: usize = 16;
const PASSES: u64 = 4;
const SPP: u32 = 1024;
const CRITERION: TileCriterion = TileCriterion {
    k: 4.0,
    rel_floor: 0.003,
    abs_floor: 0.0,
};

fn check_against_reference(scene: &str, mask: &dyn Fn(&Image) -> Vec<bool>) {
    let reference = read_image(common::shared(&format!("refs/{scene}-256-ref.exr"))).unwrap();
    let noise = |key| common::noise_figure(&format!("refs/{scene}-256-ref.noise.txt"), key);
    let (ref_relmse, ref_rmse) = (noise("ref_relmse_est"), noise("ref_rmse_est"));
    let desc =
        radiant::scene::parse_file(&radiant_testkit::repo_path(&format!("scenes/{scene}.pbrt")))
            .unwrap();
    let masked = mask(&reference);
    let start = std::time::Instant::now();
    let passes = common::render_passes(&desc, SPP / PASSES as u32, PASSES);
    eprintln!(
        "{scene}: {SPP} spp in {PASSES} passes, {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let (own, mean) = TileStats::from_passes(&passes, TILE).unwrap();
    let (own_abs, own_rel) = common::per_pixel_variance(&passes, &reference);
    let ref_tiles = TileStats::from_image(&reference, TILE)
        .with_variance_of(&own)
        .scaled_variance(ref_rmse * ref_rmse / own_abs);

    let m = compare(&mean, &reference, None).unwrap();
    let limit = 1.5 * (own_rel + ref_relmse);
    eprintln!(
        "{scene}: relMSE vs ref {:.3e}, own noise {own_rel:.3e}, ref noise {ref_relmse:.3e}, limit {limit:.3e}; mean {:.6} vs {:.6}; ref/own variance {:.3}",
        m.relmse,
        m.mean_test,
        m.mean_ref,
        ref_rmse * ref_rmse / own_abs
    );
    assert!(
        m.relmse <= limit,
        "{scene}: relMSE {} above {limit}",
        m.relmse
    );
    let rel = (m.mean_test - m.mean_ref).abs() / m.mean_ref;
    assert!(
        rel < 0.005,
        "{scene}: mean {} vs reference {} ({:.3} %)",
        m.mean_test,
        m.mean_ref,
        100.0 * rel
    );

    let cmp = compare_tiles(&own, &ref_tiles, CRITERION, &|tx, ty| {
        masked[ty * own.nx + tx]
    })
    .unwrap();
    common::assert_tiles(scene, &cmp, &mean);
}

/// The tiles the caustics cover, found in the reference: in the lower half of the image
/// (the floor, where the glass sphere focuses the light, and the spheres that show it),
/// pixels more than four times as bright as the median of the 33 x 33 pixels around them
/// — a focused caustic is a local spike, while lit walls, shadows and edges change by
/// less than that within a tile or two. This finds the ball-lens caustic on the floor, the
/// mirror sphere's reflection caustic and the light's images in both spheres. A tile with eight or more such pixels is caustic,
/// and so are its eight neighbours (the caustic's dimmer fringe). There a path tracer's
/// estimate comes from rare paths that hit the light through the glass: heavy-tailed,
/// so four passes do not measure its noise.
fn caustic_tiles(reference: &Image) -> Vec<bool> {
    let (w, h) = (reference.width, reference.height);
    let (nx, ny) = (w.div_ceil(TILE), h.div_ceil(TILE));
    let lum: Vec<f32> = reference.pixels.iter().map(|p| p.luminance()).collect();
    let mut spikes = vec![0usize; nx * ny];
    const R: usize = 16;
    const SPIKE: f32 = 4.0;
    const MIN_SPIKES: usize = 8;
    let mut window = Vec::with_capacity((2 * R + 1) * (2 * R + 1));
    for y in h / 2..h {
        for x in 0..w {
            window.clear();
            for wy in y.saturating_sub(R)..(y + R + 1).min(h) {
                window.extend_from_slice(
                    &lum[wy * w + x.saturating_sub(R)..wy * w + (x + R + 1).min(w)],
                );
            }
            let mid = window.len() / 2;
            let median = *window.select_nth_unstable_by(mid, f32::total_cmp).1;
            if lum[y * w + x] > SPIKE * median {
                spikes[(y / TILE) * nx + x / TILE] += 1;
            }
        }
    }
    let mut mask = vec![false; nx * ny];
    for ty in 0..ny {
        for tx in 0..nx {
            if spikes[ty * nx + tx] >= MIN_SPIKES {
                for my in ty.saturating_sub(1)..(ty + 2).min(ny) {
                    for mx in tx.saturating_sub(1)..(tx + 2).min(nx) {
                        mask[my * nx + mx] = true;
                    }
                }
            }
        }
    }
    let rows: Vec<String> = (0..ny)
        .map(|ty| {
            (0..nx)
                .map(|tx| if mask[ty * nx + tx] { '#' } else { '.' })
                .collect()
        })
        .collect();
    eprintln!("caustic tiles (#):\n{}", rows.join("\n"));
    mask
}

#[test]
fn cornell_box_matches_the_reference_in_every_tile() {
    check_against_reference("cornell-box", &|r| {
        vec![false; r.width.div_ceil(TILE) * r.height.div_ceil(TILE)]
    });
}

#[test]
fn cornell_caustics_matches_the_reference_outside_the_caustic() {
    check_against_reference("cornell-caustics", &caustic_tiles);
}

/// Bitterli's Cornell box (pbrt-v4 syntax) against Tungsten's 1024² render, an
/// independent RGB renderer's, tile by tile: 8 × 8 tiles of a 128² render (four seeds
/// of 256 spp, whose spread gives each tile's standard error) against the means of
/// Tungsten's pixels over the same parts of the film. A tile passes within 4 standard
/// errors plus 1 % plus 2.5e-4 (0.2 % of the image's mean). The floors cover what the
/// test cannot measure: the two films' filters differ, which moves light across tile
/// edges at the light's rim, and Tungsten's own noise is not known. The absolute floor
/// is for the blue channel of the coloured walls, about 2 % of their light, where
/// Tungsten's tiles differ from radiant's by up to 3 % of that (1.1e-4; 33 σ at these
/// counts, 0.05 % of the tiles' light). A wall off by 3 % still fails by a factor of ten.
/// The file's `maxdepth 4`
/// was lowered by its converter (its comment gives the original, 65), and Tungsten
/// rendered full transport, so the depth is restored here.
///
/// pbrt-v4's render of the file (`refs/scenes/cornell-box`, maxdepth 4) differs from
/// radiant's by up to +11 % on the red wall and −3 % on the green one: pbrt-v4 renders
/// spectrally, and the products of its reflectance and illuminant spectra are not the
/// products of their RGB values; Tungsten, like radiant, multiplies RGB.
#[test]
fn bitterli_cornell_box_matches_tungsten_tile_by_tile() {
    const SIZE: usize = 128;
    const TILE: usize = 16;
    let path = common::shared("data/scenes/bitterli/cornell-box/scene-v4.pbrt");
    let mut desc = radiant::scene::parse_file(&path).unwrap();
    let unused: Vec<_> = desc
        .warnings
        .iter()
        .filter(|w| w.message.contains("not used"))
        .collect();
    assert!(unused.is_empty(), "unused parameters: {unused:?}");
    desc.integrator.params =
        radiant::scene::ParamSet::new().with("maxdepth", radiant::scene::ParamValue::Int(vec![65]));
    let passes: Vec<Image> = (1..=4)
        .map(|seed| {
            common::render(
                &desc,
                &Overrides {
                    spp: Some(256),
                    seed: Some(seed),
                    resolution: Some((SIZE as u32, SIZE as u32)),
                    ..Default::default()
                },
            )
        })
        .collect();
    let (stats, img) = TileStats::from_passes(&passes, TILE).unwrap();
    let tungsten = read_image(common::shared(
        "data/scenes/bitterli/cornell-box/TungstenRender.exr",
    ))
    .unwrap();
    assert_eq!(
        tungsten.width % SIZE,
        0,
        "Tungsten's film is a multiple of ours"
    );
    let scale = tungsten.width / SIZE;
    // Tungsten's tile means, on the grid of the render's tiles.
    let reference = TileStats {
        tile: TILE,
        width: SIZE,
        height: SIZE,
        ..TileStats::from_image(&tungsten, TILE * scale)
    };
    let rel = (img.mean() - tungsten.mean()).abs() / tungsten.mean();
    eprintln!(
        "bitterli mean {:.6} vs Tungsten {:.6} ({:.2} %)",
        img.mean(),
        tungsten.mean(),
        100.0 * rel
    );
    assert!(rel < 0.005, "{rel}");
    let criterion = TileCriterion {
        k: 4.0,
        rel_floor: 0.01,
        abs_floor: 2.5e-4,
    };
    let cmp = compare_tiles(&stats, &reference, criterion, &|_, _| false).unwrap();
    common::assert_tiles("bitterli-cornell-box-tungsten", &cmp, &img);
}

/// Per-pixel mean of the three channels, row-major.
fn luminance(img: &Image) -> Vec<f64> {
    img.pixels
        .iter()
        .map(|c| (c.r as f64 + c.g as f64 + c.b as f64) / 3.0)
        .collect()
}

/// Tile means of `(a + b) / 2` against `reference` (all per-pixel values of 256²
/// images): the worst |z| over 16 x 16 tiles, with the render's tile variance measured
/// from a − b (Var((a+b)/2) = E[(a−b)²] / 4 per pixel) and the reference's from its
/// per-pixel rmse.
fn worst_tile_z(a: &[f64], b: &[f64], reference: &[f64], ref_rmse: f64) -> f64 {
    const SIZE: usize = 256;
    const TILE: usize = 16;
    let mut worst = 0.0f64;
    for ty in 0..SIZE / TILE {
        for tx in 0..SIZE / TILE {
            let (mut d, mut var) = (0.0, 0.0);
            for y in ty * TILE..(ty + 1) * TILE {
                for x in tx * TILE..(tx + 1) * TILE {
                    let i = y * SIZE + x;
                    d += 0.5 * (a[i] + b[i]) - reference[i];
                    var += 0.25 * (a[i] - b[i]) * (a[i] - b[i]);
                }
            }
            let n = (TILE * TILE) as f64;
            let sigma = (var / (n * n) + ref_rmse * ref_rmse / n).sqrt();
            // The floor keeps tiles that are black in every image at z = 0.
            let z = (d / n).abs() / (sigma + 1e-6);
            if z > 3.5 {
                eprintln!(
                    "tile ({tx}, {ty}): difference {:.5}, sigma {sigma:.5}, z {z:.2}",
                    d / n
                );
            }
            worst = worst.max(z);
        }
    }
    worst
}

/// The rough conductor and rough dielectric spheres (Trowbridge–Reitz) of
/// `scenes/materials/` against Mitsuba 3: whole-image relMSE within 1.5 × (own noise +
/// reference noise) and the mean within 0.5 %. Tile by tile, what the materials
/// change is compared: (radiant's m − radiant's cornell-caustics) against (Mitsuba's
/// m − Mitsuba's cornell-caustics), every 16² tile within 5.5 σ. The difference cancels
/// what the two renderers already disagree on in the unchanged room (radiant's
/// cornell-caustics is about 2.5 % darker than Mitsuba's on the middle of the green
/// wall, tiles x 208–240, y 112–160, at 512 spp: 11 σ), and its variance is measured
/// from the two seeds' differences, which keeps the correlation of equal seeds.
fn check_materials_scene(variant: &str, spp: u32) {
    // More samples for a closer look (the criterion does not depend on the count).
    let spp = std::env::var("RADIANT_MATERIALS_SPP").map_or(spp, |s| s.parse().unwrap());
    let scene = format!("cornell-materials-{variant}");
    let path = common::shared(&format!("scenes/materials/{scene}.pbrt"));
    let desc = radiant::scene::parse_file(&path).unwrap();
    let unsupported: Vec<_> = desc
        .warnings
        .iter()
        .filter(|w| w.message.contains("not supported"))
        .collect();
    assert!(unsupported.is_empty(), "{unsupported:?}");
    let reference = read_image(common::shared(&format!(
        "refs/materials/{scene}-256-ref.exr"
    )))
    .unwrap();
    let noise = format!("refs/materials/{scene}-256-ref.noise.txt");
    let ref_relmse = common::noise_figure(&noise, "ref_relmse_est");
    let ref_rmse = common::noise_figure(&noise, "ref_rmse_est");
    let base_desc = builtin_scene("cornell-caustics").unwrap();
    let base_ref = read_image(common::shared("refs/cornell-caustics-256-ref.exr")).unwrap();
    let base_rmse = common::noise_figure("refs/cornell-caustics-256-ref.noise.txt", "ref_rmse_est");
    let run = |desc, seed| {
        common::render(
            desc,
            &Overrides {
                spp: Some(spp),
                seed: Some(seed),
                ..Default::default()
            },
        )
    };
    let (a, b) = (run(&desc, 1), run(&desc, 2));
    let own = compare(&a, &b, None).unwrap().relmse / 2.0;
    let m = compare(&a, &reference, None).unwrap();
    let limit = 1.5 * (own + ref_relmse);
    let mean_both = (a.mean() + b.mean()) / 2.0;
    eprintln!(
        "{scene} @ {spp} spp: relMSE vs ref {:.3e}, own noise {own:.3e}, ref noise {ref_relmse:.3e}, limit {limit:.3e}; mean {mean_both:.6} vs {:.6}",
        m.relmse, m.mean_ref
    );
    assert!(
        m.relmse <= limit,
        "{scene}: relMSE {} above {limit}",
        m.relmse
    );
    let rel = (mean_both - m.mean_ref).abs() / m.mean_ref;
    assert!(
        rel < 0.005,
        "{scene}: mean {mean_both} vs {} ({:.3} %)",
        m.mean_ref,
        100.0 * rel
    );

    let (base_a, base_b) = (run(&base_desc, 1), run(&base_desc, 2));
    let minus = |x: &Image, y: &Image| -> Vec<f64> {
        luminance(x)
            .iter()
            .zip(luminance(y))
            .map(|(p, q)| p - q)
            .collect()
    };
    let z = worst_tile_z(
        &minus(&a, &base_a),
        &minus(&b, &base_b),
        &minus(&reference, &base_ref),
        (ref_rmse * ref_rmse + base_rmse * base_rmse).sqrt(),
    );
    eprintln!("{scene}: worst tile of the material change {z:.2} sigma");
    // 256 tiles of a heavy-tailed (caustic) estimate: 5.5 σ keeps correct code from
    // failing by chance while a 1 % bias of a bright tile still stands out at 512 spp.
    assert!(
        z < 5.5,
        "{scene}: a tile of the material change is {z:.2} sigma off"
    );
}

#[test]
fn rough_conductor_and_glass_m1_match_the_reference() {
    check_materials_scene("m1", 64);
}

#[test]
fn rough_conductor_and_glass_m2_match_the_reference() {
    check_materials_scene("m2", 64);
}
