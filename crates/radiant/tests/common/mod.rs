//! Helpers shared by the integration tests.
#![allow(dead_code)]

use radiant::Session;
use radiant::image::Image;
use radiant::render::{Overrides, Progress};
use radiant::scene::SceneDesc;

pub use radiant_testkit::shared;

/// The image's pixels as f32 bit patterns, for bit-for-bit comparisons.
pub fn pixel_bits(img: &Image) -> Vec<[u32; 3]> {
    img.pixels
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

/// Renders a scene with the given overrides on all cores.
pub fn render(desc: &SceneDesc, overrides: &Overrides) -> Image {
    let session = Session::new(desc, overrides).expect("scene builds");
    session.render(&Progress::default()).film.image()
}

/// Renders the scene file at `path` with `spp` samples per pixel.
pub fn render_file(path: &std::path::Path, spp: u32) -> Image {
    let desc = radiant::scene::parse_file(path).unwrap_or_else(|e| panic!("{e}"));
    render(
        &desc,
        &Overrides {
            spp: Some(spp),
            ..Default::default()
        },
    )
}

/// Reads `key value` lines of a reference's `.noise.txt`.
pub fn noise_figure(rel: &str, key: &str) -> f64 {
    let text = std::fs::read_to_string(shared(rel)).expect("noise file");
    text.lines()
        .find_map(|l| {
            let mut it = l.split_whitespace();
            (it.next() == Some(key)).then(|| it.next().and_then(|v| v.parse().ok()))?
        })
        .unwrap_or_else(|| panic!("{key} not in {rel}"))
}

/// Chooses the integrator an `Integrator` directive names, as a scene would.
pub fn choose(
    desc: &radiant::scene::IntegratorDesc,
) -> Result<
    (
        Box<dyn radiant::render::Integrator>,
        Vec<radiant::scene::Warning>,
    ),
    radiant::scene::SceneError,
> {
    radiant::integrator_from_desc(&radiant::scene::builtin::cornell_box(), desc)
}

/// The integrator as its concrete type; panics when it is another.
pub fn concrete<T: radiant::render::Integrator>(i: &dyn radiant::render::Integrator) -> &T {
    let any: &dyn std::any::Any = i;
    any.downcast_ref::<T>()
        .unwrap_or_else(|| panic!("{} is not the integrator expected", i.name()))
}

/// `passes` renders of a scene with seeds `1..=passes`, `spp` samples each: independent
/// images whose spread measures the noise of their mean (see `radiant::image::tiles`).
pub fn render_passes(desc: &SceneDesc, spp: u32, passes: u64) -> Vec<Image> {
    (1..=passes)
        .map(|seed| {
            render(
                desc,
                &Overrides {
                    spp: Some(spp),
                    seed: Some(seed),
                    ..Default::default()
                },
            )
        })
        .collect()
}

/// Prints a tile comparison's worst tiles; when any tile fails, writes the tile-z map
/// and the test image to `target/test-output/tiles/<name>-*` and returns the table.
pub fn check_tiles(
    name: &str,
    cmp: &radiant::image::TileComparison,
    test: &Image,
) -> Result<(), String> {
    let table = cmp.report(12);
    eprintln!("{name}: {table}");
    if cmp.failures().is_empty() {
        return Ok(());
    }
    let dir = radiant_testkit::output_dir("tiles");
    let map = dir.join(format!("{name}-tile-z.png"));
    let meta = radiant::image::ImageMeta::default();
    radiant::image::write_image(&map, &cmp.z_map(), &meta, 0.0).expect("write tile map");
    let image = dir.join(format!("{name}-test.exr"));
    radiant::image::write_image(&image, test, &meta, 0.0).expect("write test image");
    radiant::image::write_image(image.with_extension("png"), test, &meta, 1.0)
        .expect("write test image");
    Err(format!(
        "{name}: tiles outside the bound (map: {}, image: {})\n{table}",
        map.display(),
        image.display()
    ))
}

/// [`check_tiles`], panicking with the table on failure.
pub fn assert_tiles(name: &str, cmp: &radiant::image::TileComparison, test: &Image) {
    if let Err(e) = check_tiles(name, cmp, test) {
        panic!("{e}");
    }
}

/// Mean over pixels and channels of the passes' variance of their mean: (absolute,
/// relative as in relMSE).
pub fn per_pixel_variance(passes: &[Image], reference: &Image) -> (f64, f64) {
    let k = passes.len() as f64;
    let (mut abs, mut rel) = (0.0, 0.0);
    for (i, r) in reference.pixels.iter().enumerate() {
        for c in 0..3 {
            let m = passes.iter().map(|p| p.pixels[i][c] as f64).sum::<f64>() / k;
            let s2 = passes
                .iter()
                .map(|p| (p.pixels[i][c] as f64 - m).powi(2))
                .sum::<f64>()
                / (k - 1.0);
            abs += s2 / k;
            rel += s2 / k / ((r[c] as f64).powi(2) + radiant::image::metrics::RELMSE_EPSILON);
        }
    }
    let n = 3.0 * reference.pixels.len() as f64;
    (abs / n, rel / n)
}

/// Independent renders of the canonical scene `scene` (`passes`, one seed each) against
/// its Mitsuba 3 reference: the image mean within 0.3 %, and every 16 × 16 tile within
/// 4 standard errors plus 0.3 % (the criterion of `reference_images.rs`), the renders'
/// tile variance measured from their spread and the reference's scaled from its noise
/// figure in the same proportion.
pub fn assert_passes_match_reference(name: &str, scene: &str, passes: &[Image]) {
    use radiant::image::metrics::compare;
    use radiant::image::tiles::{TileCriterion, TileStats, compare_tiles};
    const TILE: usize = 16;
    let reference =
        radiant::image::read_image(shared(&format!("refs/{scene}-256-ref.exr"))).unwrap();
    let ref_rmse = noise_figure(&format!("refs/{scene}-256-ref.noise.txt"), "ref_rmse_est");
    let (own, mean) = TileStats::from_passes(passes, TILE).unwrap();
    let (own_abs, _) = per_pixel_variance(passes, &reference);
    let ref_tiles = TileStats::from_image(&reference, TILE)
        .with_variance_of(&own)
        .scaled_variance(ref_rmse * ref_rmse / own_abs);
    let m = compare(&mean, &reference, None).unwrap();
    let rel = (m.mean_test - m.mean_ref).abs() / m.mean_ref;
    eprintln!(
        "{name}: relMSE of the mean {:.3e}; mean {:.6} vs {:.6}",
        m.relmse, m.mean_test, m.mean_ref
    );
    assert!(
        rel < 0.003,
        "{name}: mean {} vs {}",
        m.mean_test,
        m.mean_ref
    );
    let criterion = TileCriterion {
        k: 4.0,
        rel_floor: 0.003,
        abs_floor: 0.0,
    };
    let cmp = compare_tiles(&own, &ref_tiles, criterion, &|_, _| false).unwrap();
    assert_tiles(name, &cmp, &mean);
}
