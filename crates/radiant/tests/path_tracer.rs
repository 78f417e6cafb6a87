//! Path tracer physics: the white furnace, pbrt's analytic sphere, and determinism
//! across thread counts.

use radiant::Session;
use radiant::image::Image;
use radiant::render::{Overrides, Progress};
use radiant::scene::builtin::{cornell_box, furnace};
use radiant::scene::{ParamValue, SceneDesc};
use radiant_testkit::fixtures::{LIT_SPHERE_RADIANCE, lit_sphere};

fn render(desc: &SceneDesc, spp: u32, threads: usize) -> Image {
    let session = Session::new(
        desc,
        &Overrides {
            spp: Some(spp),
            ..Default::default()
        },
    )
    .expect("scene builds");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| session.render(&Progress::default()))
        .film
        .image()
}

/// Per-pixel statistics of one channel: mean over pixels and the spread between pixels.
fn stats(img: &Image, channel: usize) -> (f64, f64) {
    let v: Vec<f64> = img.pixels.iter().map(|p| p[channel] as f64).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (mean, sd)
}

/// The image mean of `channel` lies within 4 standard errors (from the spread between
/// pixels) of `expected`; returns the standard deviation between pixels.
fn assert_mean_near(img: &Image, channel: usize, expected: f64, what: &str) -> f64 {
    let (mean, sd) = stats(img, channel);
    let se = sd / (img.pixels.len() as f64).sqrt();
    assert!(
        (mean - expected).abs() < 4.0 * se + 1e-6,
        "{what}, channel {channel}: mean {mean}, se {se}"
    );
    sd
}

/// Every pixel of the furnace converges to Le / (1 - albedo) = 2. All pixels share one
/// distribution, so the spread between pixels measures the per-pixel noise: the image
/// mean must lie within 4 standard errors of 2. Pixels are not normally distributed: a
/// path that survives Russian roulette goes on with its weight raised to the roulette
/// threshold, so a pixel's 16 paths have a long right tail (measured with roulette from
/// the fifth vertex at threshold 1: 1.4 % of 4096 pixels beyond 3 standard deviations,
/// against 0.27 % for a normal distribution, the largest 8 standard deviations out). So
/// at most 3 % may lie beyond 3 standard deviations, and every pixel holds what every
/// sample must — at least the emission seen first, 1 — and lies within 16 standard
/// deviations.
#[test]
fn white_furnace_is_two_everywhere() {
    let img = render(&furnace(), 16, 2);
    for c in 0..3 {
        let sd = assert_mean_near(&img, c, 2.0, "furnace");
        let mut beyond_3 = 0usize;
        for p in &img.pixels {
            let d = (p[c] as f64 - 2.0).abs();
            assert!(p[c] >= 1.0 && d < 16.0 * sd, "pixel {p:?}, sd {sd}");
            beyond_3 += (d > 3.0 * sd) as usize;
        }
        assert!(
            beyond_3 * 100 <= 3 * img.pixels.len(),
            "channel {c}: {beyond_3} of {} pixels beyond 3 sd",
            img.pixels.len()
        );
    }
}

/// Russian roulette's threshold changes the noise, not the mean: from pbrt-v4's rule
/// (θ = 1) down to θ = 0.05, with roulette from the first bounce on, every channel of
/// the furnace stays within 4 standard errors of 2.
#[test]
fn roulette_thresholds_keep_the_furnace_at_two() {
    for theta in [1.0f32, 0.35, 0.05] {
        let mut desc = furnace();
        desc.integrator.params = desc
            .integrator
            .params
            .clone()
            .with("rrdepth", ParamValue::Int(vec![0]))
            .with("rrthreshold", ParamValue::Float(vec![theta]));
        let img = render(&desc, 16, 2);
        for c in 0..3 {
            assert_mean_near(&img, c, 2.0, &format!("threshold {theta}"));
        }
    }
}

/// pbrt's analytic case: inside a unit sphere of Kd 0.5 with a point light of intensity
/// pi at its centre, radiance is 1 everywhere (direct 0.5, then a geometric series).
#[test]
fn analytic_sphere_with_point_light_gives_radiance_one() {
    let img = render(&lit_sphere(), 16, 2);
    assert_mean_near(&img, 1, LIT_SPHERE_RADIANCE as f64, "lit sphere");
}

/// The same scene, seed and sample count give the same image at any thread count.
#[test]
fn images_are_identical_at_one_and_two_threads() {
    let mut desc = cornell_box();
    desc.film.xresolution = 48;
    desc.film.yresolution = 48;
    let a = render(&desc, 4, 1);
    let b = render(&desc, 4, 2);
    assert!(
        a.pixels
            .iter()
            .zip(&b.pixels)
            .all(|(p, q)| p.to_array().map(f32::to_bits) == q.to_array().map(f32::to_bits))
    );
    assert!(a.mean() > 0.0);
}
