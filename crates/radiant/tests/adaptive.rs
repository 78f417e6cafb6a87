//! Adaptive sampling (`RenderContext::adaptive`): unbiased against the Mitsuba 3
//! reference tile by tile, deterministic at any thread count, spending about the rays of
//! a uniform render, and interruptible with a consistent image.

mod common;

use std::sync::atomic::Ordering;

use radiant::Session;
use radiant::image::{Film, Image};
use radiant::render::integrator::RenderOutput;
use radiant::render::integrator::adaptive::pilot_samples;
use radiant::render::{Overrides, Progress};
use radiant::scene::SceneDesc;

fn adaptive_session(
    desc: &SceneDesc,
    spp: u32,
    seed: u64,
    resolution: Option<(u32, u32)>,
) -> Session {
    let mut s = Session::new(
        desc,
        &Overrides {
            spp: Some(spp),
            seed: Some(seed),
            resolution,
            ..Default::default()
        },
    )
    .expect("scene builds");
    s.ctx.adaptive = true;
    s
}

fn on_threads(threads: usize, f: impl FnOnce() -> RenderOutput + Send) -> RenderOutput {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

fn cornell() -> SceneDesc {
    radiant::scene::parse_file(&radiant_testkit::repo_path("scenes/cornell-box.pbrt")).unwrap()
}

/// Four adaptive renders of 128 samples per pixel on average (seeds 1–4; the pilot of
/// each is 32) against the reference: the mean within the noise of the four in every
/// 16 × 16 tile (4 standard errors plus 0.3 %, as for the uniform renders in
/// `reference_images.rs`), and over the whole image. A sample count chosen from a
/// pixel's own samples could bias it; the smoothing window is what keeps that below
/// the noise, and this is where it would show.
#[test]
fn adaptive_cornell_box_matches_the_reference_in_every_tile() {
    let desc = cornell();
    let passes: Vec<Image> = (1..=4)
        .map(|seed| {
            let out = adaptive_session(&desc, 128, seed, None).render(&Progress::default());
            let (lo, hi) = (out.film.min_samples(), out.film.max_samples());
            eprintln!("seed {seed}: samples per pixel {lo}..{hi}");
            assert_eq!(lo, pilot_samples(128));
            assert!(
                hi > 2 * 128,
                "the allocation should concentrate samples: max {hi}"
            );
            out.film.image()
        })
        .collect();
    common::assert_passes_match_reference("adaptive-cornell-box", "cornell-box", &passes);
}

/// The pilot, the counts chosen from it and the samples after it are the same on one
/// thread and two, so the image is too, bit for bit; and every pixel's count is the
/// same.
#[test]
fn adaptive_images_are_identical_at_one_and_two_threads() {
    let s = adaptive_session(&cornell(), 64, 5, Some((48, 40)));
    let one = on_threads(1, || s.render(&Progress::default()));
    let two = on_threads(2, || s.render(&Progress::default()));
    let counts = |f: &Film| f.pixels.iter().map(|p| p.samples).collect::<Vec<_>>();
    assert_eq!(counts(&one.film), counts(&two.film));
    assert!(counts(&one.film).iter().any(|&n| n != 64));
    assert!(
        common::pixel_bits(&one.film.image()) == common::pixel_bits(&two.film.image()),
        "images differ"
    );
}

/// The budget is counted in rays: an adaptive render of N samples per pixel on average
/// traces about the rays of a uniform one (within 3 %, the rounding down of counts
/// and the cost being the pilot's estimate), while its sample counts differ pixel by
/// pixel.
#[test]
fn adaptive_renders_spend_about_the_rays_of_uniform_ones() {
    let desc = cornell();
    let res = Some((96, 96));
    let adaptive = adaptive_session(&desc, 64, 2, res).render(&Progress::default());
    let mut uniform = adaptive_session(&desc, 64, 2, res);
    uniform.ctx.adaptive = false;
    let uniform = uniform.render(&Progress::default());
    let ratio = adaptive.rays as f64 / uniform.rays as f64;
    eprintln!(
        "rays: adaptive {} uniform {} ({ratio:.4})",
        adaptive.rays, uniform.rays
    );
    assert!((0.97..=1.03).contains(&ratio), "{ratio}");
    assert!(uniform.film.pixels.iter().all(|p| p.samples == 64));
}

/// Cancelled from the pass watcher after the first adaptive round (counts up to twice
/// the pilot), the render says it was interrupted, `spp_done` is what every pixel
/// holds (at least the pilot), some pixels hold more, and the image is the mean of what
/// each pixel received.
#[test]
fn an_interrupted_adaptive_render_keeps_what_each_pixel_received() {
    let s = adaptive_session(&cornell(), 128, 3, Some((64, 64)));
    let progress = Progress::default();
    let pilot = pilot_samples(128);
    let mut watched = Vec::new();
    let mut watch = |n: u32, film: &Film| {
        watched.push(n);
        if film.pixels.iter().any(|p| p.samples > pilot) {
            progress.cancel.store(true, Ordering::Relaxed);
        }
    };
    let out = s
        .render_watched(&progress, &mut |_, _| {}, None, None, Some(&mut watch))
        .unwrap();
    eprintln!("watched after passes: {watched:?}");
    assert!(out.interrupted);
    let (least, most) = (out.film.min_samples(), out.film.max_samples());
    assert_eq!(out.spp_done, least);
    assert!(least >= pilot, "{least}");
    assert!(most > pilot && most <= 2 * pilot, "{most}");
    assert!(out.film.image().mean() > 0.0);
}
