//! The two-pass photon mapper: furnace, visualisations, the cornell-caustics
//! reference, determinism, parameters.

use glam::Vec3;
use radiant::Session;
use radiant::image::{Image, compare};
use radiant::render::integrator::photon::Visualize;
use radiant::render::integrator::{PhotonMapIntegrator, PhotonMapStats};
use radiant::render::{Overrides, PixelBounds, Progress, WorkUnit};
use radiant::scene::builtin::{cornell_caustics, furnace};
use radiant::scene::params::{ParamSet, ParamValue};
use radiant::scene::{IntegratorDesc, LightDesc, parse_file};

use crate::common;
use crate::scenes::{CAUSTIC_CROP, crop_at, mean_and_sd, reference, spot_light, with_integrator};

fn quick_params() -> ParamSet {
    ParamSet::new()
        .with("photons", ParamValue::Int(vec![50_000]))
        .with("causticphotons", ParamValue::Int(vec![100_000]))
        .with("finalgathersamples", ParamValue::Int(vec![8]))
        .with("lookup", ParamValue::Int(vec![50]))
        .with("globallookup", ParamValue::Int(vec![100]))
        .with("maxdepth", ParamValue::Int(vec![100]))
}

/// In the furnace every pixel is Le / (1 − albedo) = 2. With final gathering: emission
/// 1 + direct 0.5 (next-event estimation) + indirect 0.5 from the global map read at the
/// gather rays' hits. The photon density is uniform, so the kernel adds no bias; the
/// pixel spread measures the noise, and the image mean must lie within 4 standard
/// errors of 2 plus 0.5 % for the irradiance precomputed at discrete points.
#[test]
fn furnace_converges_to_two() {
    let desc = with_integrator(furnace(), "photonmap", quick_params(), None);
    let img = common::render(
        &desc,
        &Overrides {
            spp: Some(2),
            ..Default::default()
        },
    );
    for c in 0..3 {
        let (m, sd) = mean_and_sd(&img, c);
        let se = sd / (img.pixels.len() as f64).sqrt();
        eprintln!("channel {c}: mean {m}, pixel sd {sd}, se {se}");
        assert!(
            (m - 2.0).abs() < 4.0 * se + 0.01,
            "channel {c}: mean {m}, se {se}"
        );
    }
}

/// The visualisations read the maps directly. In the furnace: `density` (emission plus
/// every stored photon) is 2, `global` (indirect photons only) is 0.5 (everything after
/// the first bounce: 0.5 · (0.5 + 0.25 + …) · 2 = 0.5), `caustic` is 0 (nothing is
/// specular). Tolerance 4 %: the pixels see ~1/13 of the sphere, where some 4000
/// indirect photons land, so the image mean carries ~1.6 % noise (the area of a sphere
/// within distance r of a point on it is exactly πr², so curvature adds no bias).
#[test]
fn visualisations_show_the_maps() {
    for (mode, expect) in [("density", 2.0), ("global", 0.5), ("caustic", 0.0)] {
        let params = quick_params().with("visualize", ParamValue::String(vec![mode.into()]));
        let desc = with_integrator(furnace(), "photonmap", params, None);
        let img = common::render(
            &desc,
            &Overrides {
                spp: Some(1),
                ..Default::default()
            },
        );
        let m = img.mean();
        eprintln!("{mode}: mean {m}");
        assert!(
            (m - expect).abs() <= 0.04 * expect + 1e-6,
            "{mode}: mean {m}, expected {expect}"
        );
    }
    // Dots: photons light some pixels, not all (at 64 × 64 a pixel is 12 mm wide).
    let params = quick_params().with("visualize", ParamValue::String(vec!["photons".into()]));
    let desc = with_integrator(cornell_caustics(), "photonmap", params, Some(64));
    let img = common::render(
        &desc,
        &Overrides {
            spp: Some(1),
            ..Default::default()
        },
    );
    let lit = img
        .pixels
        .iter()
        .filter(|p| p.max_component() > 0.0)
        .count();
    eprintln!("photons: {lit} of {} pixels lit", img.pixels.len());
    assert!(lit > 100 && lit < img.pixels.len(), "{lit} lit pixels");
}

/// cornell-caustics at 64 × 64 against the 4 × 4-downsampled reference: the caustic
/// region's mean within 5 % (kernel blur moves light only within the region, whose
/// margin holds it; the rest is noise of 100k caustic photons, ~1 %), and the whole
/// image close to the reference (relMSE below 0.03: 4 spp of 8 gather rays are noisy).
#[test]
fn cornell_caustics_caustic_matches_the_reference() {
    let desc = with_integrator(cornell_caustics(), "photonmap", quick_params(), Some(64));
    let img = common::render(
        &desc,
        &Overrides {
            spp: Some(4),
            ..Default::default()
        },
    );
    let reference = reference(64);
    let crop = crop_at(CAUSTIC_CROP, 64);
    let m = img.mean_in(crop).unwrap();
    let r = reference.mean_in(crop).unwrap();
    let metrics = compare(&img, &reference, None).unwrap();
    eprintln!(
        "caustic mean {m} vs reference {r}; relmse {}",
        metrics.relmse
    );
    assert!(
        (m / r - 1.0).abs() < 0.05,
        "caustic mean {m} vs reference {r}"
    );
    assert!(metrics.relmse < 0.03, "relmse {}", metrics.relmse);
}

/// With its default settings (and the scene's unbounded path length) the photon mapper
/// resolves the caustic below the glass sphere at full resolution: the caustic crop of
/// the 256 × 256 image within relMSE 4e-3 of the reference at 64 camera samples. The
/// caustic estimate's blur alone is about 0.8e-3 there (4.5e-3 with the earlier
/// defaults, 500k caustic photons and 100 per estimate, which could never pass), the
/// camera samples' noise about 1.7e-3. Only the crop's pixels are rendered: they are
/// the pixels a full render computes.
#[test]
fn default_settings_resolve_the_caustic_crop() {
    let params = ParamSet::new().with("maxdepth", ParamValue::Int(vec![100]));
    let desc = with_integrator(cornell_caustics(), "photonmap", params, None);
    let mut session = Session::new(
        &desc,
        &Overrides {
            spp: Some(64),
            ..Default::default()
        },
    )
    .expect("scene builds");
    let (x0, y0, x1, y1) = CAUSTIC_CROP;
    session.ctx.work = WorkUnit {
        pixels: PixelBounds {
            x0: x0 as u32,
            x1: x1 as u32,
            y0: y0 as u32,
            y1: y1 as u32,
        },
        samples: (0, 64),
    };
    let img = session.render(&Progress::default()).film.image();
    let expected = reference(256)
        .crop(crop_at(CAUSTIC_CROP, 256))
        .expect("the crop lies in the image");
    let metrics = compare(&img, &expected, None).unwrap();
    eprintln!("caustic crop relMSE {}", metrics.relmse);
    assert!(
        metrics.relmse < 4e-3,
        "caustic crop relMSE {}",
        metrics.relmse
    );
}

/// Photon maps and images are identical at any thread count.
#[test]
fn photon_maps_are_identical_at_one_and_two_threads() {
    let desc = with_integrator(cornell_caustics(), "photonmap", quick_params(), Some(24));
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let session = Session::new(
            &desc,
            &Overrides {
                spp: Some(1),
                ..Default::default()
            },
        )
        .unwrap();
        let out = pool.install(|| session.render(&Progress::default()));
        (out.film.image(), out.stats)
    };
    let (a, sa) = run(1);
    let (b, sb) = run(2);
    let bits = |img: &Image| {
        img.pixels
            .iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
    let (sa, sb) = (
        sa.get::<PhotonMapStats>().expect("photon map statistics"),
        sb.get::<PhotonMapStats>().expect("photon map statistics"),
    );
    assert_eq!(
        (sa.global_stored, sa.caustic_stored),
        (sb.global_stored, sb.caustic_stored)
    );
    assert!(sa.global_stored > 0 && sa.caustic_stored > 0);
}

/// Parameters are read, bad values are errors, and `photonviz` defaults to density.
#[test]
fn parameters_are_read_and_checked() {
    let desc = |params: ParamSet, name: &str| IntegratorDesc {
        name: name.into(),
        params,
        loc: cornell_caustics().integrator.loc,
    };
    let (i, warnings) = common::choose(&desc(
        quick_params()
            .with("maxradius", ParamValue::Float(vec![12.5]))
            .with("kernel", ParamValue::String(vec!["epanechnikov".into()]))
            .with("projectionmaps", ParamValue::Bool(vec![false]))
            .with("seed", ParamValue::Int(vec![3]))
            .with("bogus", ParamValue::Int(vec![1])),
        "photonmap",
    ))
    .unwrap();
    let s = common::concrete::<PhotonMapIntegrator>(&*i).settings;
    assert_eq!(
        (
            s.photons,
            s.caustic_photons,
            s.lookup,
            s.final_gather_samples
        ),
        (50_000, 100_000, 50, 8)
    );
    assert_eq!(s.max_radius, Some(12.5));
    assert!(!s.projection_maps && s.seed == Some(3));
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].message.contains("bogus"));
    let (i, _) = common::choose(&desc(ParamSet::new(), "photonviz")).unwrap();
    assert_eq!(
        common::concrete::<PhotonMapIntegrator>(&*i)
            .settings
            .visualize,
        Visualize::Density
    );
    for (k, v) in [
        ("kernel", ParamValue::String(vec!["gaussian".into()])),
        ("visualize", ParamValue::String(vec!["everything".into()])),
        ("maxradius", ParamValue::Float(vec![-1.0])),
        ("photons", ParamValue::Int(vec![-5])),
    ] {
        assert!(
            common::choose(&desc(ParamSet::new().with(k, v), "photonmap")).is_err(),
            "{k}"
        );
    }
}

/// The spot-lit variant of cornell-caustics in `scenes/` parses into the light the
/// tests build in code.
#[test]
fn spot_scene_file_matches_the_code_variant() {
    let path = radiant_testkit::repo_path("scenes/cornell-caustics-spot.pbrt");
    let desc = parse_file(&path).expect("scene parses");
    assert!(desc.shapes.iter().all(|s| s.area_light.is_none()));
    let [
        LightDesc::Spot {
            position,
            direction,
            intensity,
            cos_falloff_start,
            cos_total_width,
            ..
        },
    ] = desc.lights.as_slice()
    else {
        panic!("one spot light expected: {:?}", desc.lights);
    };
    let LightDesc::Spot {
        intensity: i2,
        cos_falloff_start: s2,
        cos_total_width: t2,
        ..
    } = spot_light(&desc)
    else {
        unreachable!()
    };
    assert!((*position - Vec3::new(278.0, 540.0, 279.5)).length() < 1e-3);
    assert!(direction.normalize().dot(-Vec3::Y) > 0.99999);
    assert!((*intensity - i2).max_component().abs() < 1e-3 * i2.max_component());
    assert!((cos_falloff_start - s2).abs() < 1e-5 && (cos_total_width - t2).abs() < 1e-5);
}
