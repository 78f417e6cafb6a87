//! Distributed renders merge to the bits of one render: every integrator split into
//! tiles, the per-pixel ones into sample ranges too, with 1, 2, 3 and 7 parts; each
//! part goes through its partial file's encoding. The merge refuses parts of another
//! scene, gaps, overlaps and duplicates.

use radiant::Session;
use radiant::partial::{self, Partial, PartialError, Split};
use radiant::render::{Overrides, SAMPLE_BLOCK, WorkUnit};
use radiant::scene::builtin::{cornell_box, cornell_caustics};
use radiant::scene::{ParamSet, ParamValue, SceneDesc};

const PARTS: [u32; 4] = [1, 2, 3, 7];

fn session(desc: &SceneDesc, integrator: &str, spp: u32, res: u32) -> Session {
    let overrides = Overrides {
        spp: Some(spp),
        seed: Some(11),
        resolution: Some((res, res)),
        integrator: Some(integrator.into()),
    };
    Session::new(desc, &overrides).expect("session")
}

/// Renders one unit and reads it back from its encoding.
fn render_unit(
    session: &mut Session,
    desc: &SceneDesc,
    unit: WorkUnit,
    part: (u32, u32),
) -> Partial {
    session.ctx.work = unit;
    let out = session.render(&Default::default());
    assert!(!out.interrupted);
    let partial = Partial::from_output(session.run_key(desc), unit, Some(part), out);
    Partial::decode(&partial.encode()).expect("decodes")
}

fn bits(image: &radiant::image::Image) -> Vec<u32> {
    image
        .pixels
        .iter()
        .flat_map(|p| [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()])
        .collect()
}

fn parts(session: &mut Session, desc: &SceneDesc, n: u32, split: Split) -> Vec<(String, Partial)> {
    let (res, spp) = (session.ctx.resolution, session.ctx.spp);
    (0..n)
        .map(|k| {
            let unit = partial::part_unit(res, spp, k, n, split).expect("unit");
            (
                format!("part {k}/{n}"),
                render_unit(session, desc, unit, (k, n)),
            )
        })
        .collect()
}

/// The one-machine image against merges of 1, 2, 3 and 7 parts, bit for bit.
fn assert_merges_exactly(desc: &SceneDesc, integrator: &str, spp: u32, res: u32, split: Split) {
    let mut s = session(desc, integrator, spp, res);
    let whole = s.render(&Default::default());
    let reference = bits(&whole.film.image());
    for n in PARTS {
        let merged = partial::merge(&parts(&mut s, desc, n, split)).expect("merges");
        assert_eq!(merged.min_samples(), whole.film.min_samples());
        let got = bits(&merged.image());
        let differing = got.iter().zip(&reference).filter(|(a, b)| a != b).count();
        assert_eq!(
            differing, 0,
            "{integrator}, {n} parts by {split:?}: {differing} channel values differ"
        );
        assert_eq!(
            sum_bits(&merged),
            sum_bits(&whole.film),
            "{integrator}, {n} parts"
        );
    }
}

fn small_photon_map(mut desc: SceneDesc) -> SceneDesc {
    desc.integrator.params = ParamSet::new()
        .with("photons", ParamValue::Int(vec![4000]))
        .with("causticphotons", ParamValue::Int(vec![4000]));
    desc
}

#[test]
fn path_tiles_merge_to_the_single_render() {
    // 100 spp: a full block and a partial one in every tile.
    assert_merges_exactly(&cornell_box(), "path", 100, 32, Split::Tiles);
}

#[test]
fn path_sample_ranges_merge_to_the_single_render() {
    // Seven blocks, the last a partial one, so seven parts are possible.
    let spp = 6 * SAMPLE_BLOCK + 16;
    assert_merges_exactly(&cornell_box(), "path", spp, 16, Split::Samples);
}

#[test]
fn photon_map_tiles_and_ranges_merge_to_the_single_render() {
    let desc = small_photon_map(cornell_caustics());
    assert_merges_exactly(&desc, "photonmap", 4, 16, Split::Tiles);
    assert_merges_exactly(&desc, "photonmap", 6 * SAMPLE_BLOCK + 1, 8, Split::Samples);
}

#[test]
fn sppm_tiles_merge_to_the_single_render() {
    assert_merges_exactly(&cornell_caustics(), "sppm", 4, 32, Split::Tiles);
}

#[test]
fn radiosity_display_tiles_merge_to_the_single_render() {
    let mut desc = cornell_box();
    desc.integrator.params = ParamSet::new()
        .with("maxpatcharea", ParamValue::Float(vec![5000.0]))
        .with("solver", ParamValue::String(vec!["jacobi".into()]))
        .with("finalgather", ParamValue::Int(vec![2]));
    assert_merges_exactly(&desc, "radiosity", 2, 16, Split::Tiles);
}

fn coverage_error(parts: &[(String, Partial)]) -> String {
    match partial::merge(parts) {
        Err(e @ PartialError::Coverage(_)) => e.to_string(),
        Err(e) => panic!("expected a coverage error, got {e}"),
        Ok(_) => panic!("expected a coverage error, got a merge"),
    }
}

#[test]
fn merge_refuses_other_scenes_gaps_overlaps_and_duplicates() {
    let desc = cornell_box();
    let mut s = session(&desc, "path", 2 * SAMPLE_BLOCK, 8);
    let tiles = parts(&mut s, &desc, 3, Split::Tiles);
    let ranges = parts(&mut s, &desc, 2, Split::Samples);

    // A gap: part 1 of 3 left out, named.
    let e = coverage_error(&[tiles[0].clone(), tiles[2].clone()]);
    assert!(e.contains("gap") && e.contains("1/3"), "{e}");
    // A gap in samples: the second block missing.
    let e = coverage_error(&ranges[..1]);
    assert!(e.contains("gap") && e.contains("64 of 128"), "{e}");
    // A duplicate, named by both parts.
    let e = coverage_error(&[
        tiles[0].clone(),
        tiles[0].clone(),
        tiles[1].clone(),
        tiles[2].clone(),
    ]);
    assert!(e.contains("duplicate") && e.contains("part 0/3"), "{e}");
    // An overlap: all samples of a tile again in a sample range.
    let mut mixed = tiles.clone();
    mixed.push(ranges[0].clone());
    let e = coverage_error(&mixed);
    assert!(e.contains("overlap"), "{e}");

    // Another scene: a different film diagonal.
    let mut other = cornell_box();
    other.film.diagonal_mm += 1.0;
    let mut s2 = session(&other, "path", 2 * SAMPLE_BLOCK, 8);
    let foreign = parts(&mut s2, &other, 3, Split::Tiles);
    match partial::merge(&[tiles[0].clone(), tiles[1].clone(), foreign[2].clone()]) {
        Err(e @ PartialError::Mismatch(_)) => assert!(e.to_string().contains("scene"), "{e}"),
        other => panic!("expected a scene mismatch, got {:?}", other.map(|_| ())),
    }
    // Another seed.
    let mut s3 = session(&desc, "path", 2 * SAMPLE_BLOCK, 8);
    s3.ctx.seed = 12;
    let reseeded = parts(&mut s3, &desc, 3, Split::Tiles);
    match partial::merge(&[tiles[0].clone(), reseeded[1].clone(), tiles[2].clone()]) {
        Err(e @ PartialError::Mismatch(_)) => assert!(e.to_string().contains("seed"), "{e}"),
        other => panic!("expected a seed mismatch, got {:?}", other.map(|_| ())),
    }
    // A damaged file.
    let mut bytes = tiles[0].1.encode();
    let last = bytes.len() - 20;
    bytes[last] ^= 1;
    assert!(matches!(
        Partial::decode(&bytes),
        Err(PartialError::Corrupt(_))
    ));
}

#[test]
fn units_off_the_sample_blocks_or_the_image_are_refused() {
    let unit = |samples| WorkUnit {
        samples,
        ..WorkUnit::full((8, 8), 200)
    };
    assert!(partial::check_unit(&unit((0, 64)), (8, 8), 200).is_ok());
    assert!(partial::check_unit(&unit((128, 200)), (8, 8), 200).is_ok());
    assert!(partial::check_unit(&unit((10, 64)), (8, 8), 200).is_err());
    assert!(partial::check_unit(&unit((64, 100)), (8, 8), 200).is_err());
    let mut off = unit((0, 200));
    off.pixels.x1 = 9;
    assert!(partial::check_unit(&off, (8, 8), 200).is_err());
    // pbrt-v4's crop window: edges at ceil(resolution × fraction).
    let b = partial::crop_window_bounds((10, 20), [0.25, 0.75, 0.0, 0.5]);
    assert_eq!((b.x0, b.x1, b.y0, b.y1), (3, 8, 0, 10));
}

fn sum_bits(film: &radiant::image::Film) -> Vec<u64> {
    film.pixels
        .iter()
        .flat_map(|p| {
            [
                p.sum[0].to_bits(),
                p.sum[1].to_bits(),
                p.sum[2].to_bits(),
                p.weight.to_bits(),
            ]
        })
        .collect()
}

/// Radiance spanning sixty binary orders of magnitude from sample to sample: the f64
/// sums of a pixel are then inexact, and their grouping shows in the bits.
struct WideRange;

impl radiant::render::integrator::PixelEstimator for WideRange {
    type Scratch = ();

    fn scratch(&self) {}

    fn radiance(
        &self,
        _ray: radiant::render::geometry::Ray,
        sampler: &mut radiant::render::sampler::PixelSample,
        _pixel: radiant::render::integrator::PixelId,
        _scratch: &mut (),
    ) -> (radiant::color::Rgb, u32) {
        let u = sampler.get_2d();
        let v = (2.0f32).powi((u.x * 60.0) as i32 - 30) * (1.0 + u.y);
        (radiant::color::Rgb::splat(v), 1)
    }
}

#[test]
fn sample_ranges_merge_exactly_where_the_sums_round() {
    use radiant::render::integrator::{RenderControl, render_passes};
    let desc = cornell_box();
    let spp = 5 * SAMPLE_BLOCK + 7;
    let mut s = session(&desc, "path", spp, 8);
    let progress = radiant::render::Progress::default();
    let render = |s: &Session| {
        render_passes(
            &s.ctx,
            &WideRange,
            &mut RenderControl::new(&progress, &mut |_, _| {}),
        )
    };
    let whole = render(&s);
    let reference = bits(&whole.film.image());
    let (res, key) = (s.ctx.resolution, s.run_key(&desc));
    for n in [2, 3, 5] {
        let mut parts = Vec::new();
        let mut naive = radiant::image::Film::new(8, 8, whole.film.sensor);
        for k in 0..n {
            let unit = partial::part_unit(res, spp, k, n, Split::Samples).unwrap();
            s.ctx.work = unit;
            let out = render(&s);
            // What a merge without the block grouping would make: the parts' sums
            // added as they are.
            for (p, q) in naive.pixels.iter_mut().zip(&out.film.pixels) {
                radiant::render::integrator::fold(p, q);
            }
            let part = Partial::from_output(key.clone(), unit, Some((k, n)), out);
            parts.push((format!("{k}/{n}"), Partial::decode(&part.encode()).unwrap()));
        }
        let merged = partial::merge(&parts).unwrap();
        assert_eq!(bits(&merged.image()), reference, "{n} parts");
        // The f64 sums themselves are the same bits (the f32 image hides most of the
        // rounding), and differ without the grouping.
        assert_eq!(sum_bits(&merged), sum_bits(&whole.film), "{n} parts");
        assert_ne!(
            sum_bits(&naive),
            sum_bits(&whole.film),
            "{n} parts: the sums are exact here, so the test shows nothing"
        );
    }
}
