//! Splitting at the first vertex (`Integrator "path" "integer primarysplit" k`): unbiased
//! against the Mitsuba 3 reference tile by tile, in the white furnace with every sampler
//! and roulette from the first bounce, and deterministic at any thread count.

mod common;

use radiant::Session;
use radiant::image::Image;
use radiant::render::{Overrides, Progress};
use radiant::scene::builtin::furnace;
use radiant::scene::{DigitRandomization, ParamValue, SamplerKind, SceneDesc};

fn split(mut desc: SceneDesc, k: i32) -> SceneDesc {
    desc.integrator.params = desc
        .integrator
        .params
        .clone()
        .with("primarysplit", ParamValue::Int(vec![k]));
    desc
}

fn cornell() -> SceneDesc {
    radiant::scene::parse_file(&radiant_testkit::repo_path("scenes/cornell-box.pbrt")).unwrap()
}

fn render_on(
    desc: &SceneDesc,
    spp: u32,
    seed: u64,
    resolution: Option<(u32, u32)>,
    threads: usize,
) -> Image {
    let session = Session::new(
        desc,
        &Overrides {
            spp: Some(spp),
            seed: Some(seed),
            resolution,
            ..Default::default()
        },
    )
    .expect("scene builds");
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| session.render(&Progress::default()))
        .film
        .image()
}

/// Four renders of 32 camera samples split 4 ways (128 paths per pixel; seeds 1–4)
/// against the reference: the mean within the noise of the four in every 16 × 16 tile
/// (4 standard errors plus 0.3 %, as for the unsplit renders in `reference_images.rs`)
/// and over the whole image. Branches weighted wrongly, or drawing the same numbers,
/// would show here.
#[test]
fn split_cornell_box_matches_the_reference_in_every_tile() {
    let desc = split(cornell(), 4);
    let passes: Vec<Image> = (1..=4)
        .map(|seed| render_on(&desc, 32, seed, None, 2))
        .collect();
    common::assert_passes_match_reference("split-cornell-box", "cornell-box", &passes);
}

/// The furnace (Le / (1 − albedo) = 2 everywhere) split 3 ways, with roulette from the
/// first bounce (so that the branches play it too), under each sampler: the Sobol
/// sampler's branches are further samples of the pixel's sequence, Halton's too, and
/// the stratified and independent samplers' branches draw independent numbers. Every
/// channel's image mean lies within 4 standard errors of 2 (from the spread between
/// pixels, which share one distribution).
#[test]
fn the_split_furnace_is_two_with_every_sampler() {
    let samplers = [
        SamplerKind::Sobol,
        SamplerKind::Halton {
            randomization: DigitRandomization::Owen,
        },
        SamplerKind::Stratified {
            x: 4,
            y: 4,
            jitter: true,
        },
        SamplerKind::Independent,
    ];
    for kind in samplers {
        let mut desc = split(furnace(), 3);
        desc.sampler.kind = kind;
        desc.integrator.params = desc
            .integrator
            .params
            .clone()
            .with("rrdepth", ParamValue::Int(vec![0]));
        let img = render_on(&desc, 16, 2, None, 2);
        for c in 0..3 {
            let v: Vec<f64> = img.pixels.iter().map(|p| p[c] as f64).collect();
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let se = sd / n.sqrt();
            eprintln!("{kind:?} channel {c}: {mean:.5} ± {se:.5}");
            assert!(
                (mean - 2.0).abs() < 4.0 * se,
                "{kind:?}, channel {c}: mean {mean}, se {se}"
            );
            assert!(v.iter().all(|&x| x >= 1.0), "{kind:?}: a pixel below Le");
        }
    }
}

/// A branch's numbers depend only on its sample and branch index, so a split render is
/// the same on one thread and two, bit for bit; and it differs from the unsplit render
/// of as many camera samples (it traces more paths), while `primarysplit 1` is that
/// unsplit render exactly.
#[test]
fn split_images_are_identical_at_one_and_two_threads() {
    let res = Some((48, 40));
    let desc = split(cornell(), 3);
    let one = render_on(&desc, 4, 5, res, 1);
    let two = render_on(&desc, 4, 5, res, 2);
    assert!(
        common::pixel_bits(&one) == common::pixel_bits(&two),
        "images differ"
    );
    let unsplit = render_on(&cornell(), 4, 5, res, 2);
    assert!(common::pixel_bits(&one) != common::pixel_bits(&unsplit));
    assert!(
        common::pixel_bits(&render_on(&split(cornell(), 1), 4, 5, res, 2))
            == common::pixel_bits(&unsplit)
    );
}
