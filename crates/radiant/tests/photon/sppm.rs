//! Stochastic progressive photon mapping: furnace, convergence to the cornell-caustics
//! reference, the spot-lit caustic, snapshots, cancellation, determinism, the default
//! radius and parameters.

use std::sync::atomic::Ordering;

use radiant::Session;
use radiant::image::{Image, compare};
use radiant::render::integrator::photon::{FROM_SPECULAR, PhotonMaps, PhotonSettings, Visualize};
use radiant::render::integrator::{SppmIntegrator, SppmStats};
use radiant::render::{Overrides, Progress};
use radiant::scene::builtin::{cornell_caustics, furnace};
use radiant::scene::params::{ParamSet, ParamValue};
use radiant::scene::{IntegratorDesc, SamplerKind, SceneDesc, parse_file};

use crate::common;
use crate::scenes::{CAUSTIC_CROP, FLOOR_CROP, crop_at, reference, with_integrator};

fn sppm_params() -> ParamSet {
    ParamSet::new().with("maxdepth", ParamValue::Int(vec![100]))
}

/// Renders and returns the image with its SPPM statistics and the snapshots taken.
fn render_sppm(
    desc: &SceneDesc,
    iterations: u32,
    threads: usize,
) -> (Image, SppmStats, Vec<(u32, Image)>) {
    let session = Session::new(
        desc,
        &Overrides {
            spp: Some(iterations),
            ..Default::default()
        },
    )
    .expect("scene");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let mut snaps = Vec::new();
    let out = pool.install(|| {
        session.render_with_snapshots(&Progress::default(), &mut |k, img| {
            snaps.push((k, img.image()))
        })
    });
    let stats = *out.stats.get::<SppmStats>().expect("SPPM statistics");
    (out.film.image(), stats, snaps)
}

/// Every pixel of the furnace converges to 2: emission 1 and direct 0.5 from the
/// camera pass, 0.5 from photons. The photon density is uniform, so the radius adds no
/// bias. Pixels share photons, so their errors correlate; the bound is 4 pixel-sd
/// standard errors plus 0.5 % for that correlation.
#[test]
fn furnace_converges_to_two() {
    let desc = with_integrator(furnace(), "sppm", sppm_params(), Some(64));
    let (img, stats, _) = render_sppm(&desc, 32, 2);
    for c in 0..3 {
        let v: Vec<f64> = img.pixels.iter().map(|p| p[c] as f64).collect();
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        eprintln!("channel {c}: mean {m}, pixel sd {sd}");
        assert!(
            (m - 2.0).abs() < 4.0 * sd / n.sqrt() + 0.01,
            "channel {c}: mean {m}, sd {sd}"
        );
    }
    assert_eq!(stats.iterations, 32);
    assert!(stats.final_radius < stats.initial_radius);
}

/// Consistency on cornell-caustics (64 × 64 against the 4 × 4-downsampled reference,
/// 4096 photons per iteration): relMSE falls at every step 4 → 16 → 64 → 256
/// iterations, and after 256 the caustic region's mean is within 3 % of the
/// reference's (the reference's own noise there is ~0.5 %).
#[test]
fn cornell_caustics_converges_to_the_reference() {
    let desc = with_integrator(cornell_caustics(), "sppm", sppm_params(), Some(64));
    let (img, stats, snaps) = render_sppm(&desc, 256, 2);
    let reference = reference(64);
    let mut last = f64::INFINITY;
    for (k, snap) in &snaps {
        let m = compare(snap, &reference, None).unwrap();
        eprintln!("{k:4} iterations: relmse {:.5}", m.relmse);
        if [4, 16, 64, 256].contains(k) {
            assert!(
                m.relmse < last,
                "relmse rose to {} at {k} iterations",
                m.relmse
            );
            last = m.relmse;
        }
    }
    assert_eq!(
        snaps.iter().map(|s| s.0).collect::<Vec<_>>(),
        [1, 2, 4, 8, 16, 32, 64, 128, 256]
    );
    assert_eq!(snaps.last().unwrap().1, img);
    let crop = crop_at(CAUSTIC_CROP, 64);
    let (m, r) = (img.mean_in(crop).unwrap(), reference.mean_in(crop).unwrap());
    eprintln!(
        "caustic mean {m} vs reference {r}; radius {} -> {}",
        stats.initial_radius, stats.final_radius
    );
    assert!(
        (m / r - 1.0).abs() < 0.03,
        "caustic mean {m} vs reference {r}"
    );
}

/// The caustic estimate (aimed photons arriving through specular surfaces, gathered
/// with their own radius) and the global one (every other photon path) together are
/// the single estimate: the same caustic and the same image mean as the single
/// estimate of all photons (`causticphotonsperiteration` 0), with neither path set
/// counted twice or lost — either would move the caustic crop by its whole share.
/// 64 × 64, 64 iterations; the crops' noise is ~1 %, bounds 4 % (caustic) and 1.5 %
/// (image).
#[test]
fn caustic_and_global_estimates_add_up_to_the_single_one() {
    let split = with_integrator(cornell_caustics(), "sppm", sppm_params(), Some(64));
    let single = with_integrator(
        cornell_caustics(),
        "sppm",
        sppm_params().with("causticphotonsperiteration", ParamValue::Int(vec![0])),
        Some(64),
    );
    let (a, sa, _) = render_sppm(&split, 64, 2);
    let (b, sb, _) = render_sppm(&single, 64, 2);
    assert!(sa.caustic_photons_per_iteration > 0 && sb.caustic_photons_per_iteration == 0);
    let caustic = crop_at(CAUSTIC_CROP, 64);
    let (ca, cb) = (a.mean_in(caustic).unwrap(), b.mean_in(caustic).unwrap());
    let (ma, mb) = (a.mean(), b.mean());
    eprintln!("caustic crop: split {ca}, single {cb}; image: split {ma}, single {mb}");
    assert!(
        (ca / cb - 1.0).abs() < 0.04,
        "caustic: split {ca}, single {cb}"
    );
    assert!(
        (ma / mb - 1.0).abs() < 0.015,
        "image: split {ma}, single {mb}"
    );
}

/// Lit by a spot light, the caustic is reachable only from the light: the path tracer
/// shows none, SPPM does (the region is many times brighter than the path tracer's).
/// On the floor away from the caustic the two differ by exactly the light whose first
/// scattering event was specular (L S …: the mirror's reflections and the glass's
/// stray light, a few per cent there), which no camera path can connect to a delta
/// light. That share f is measured from the photons themselves (flag `FROM_SPECULAR`,
/// photons near the floor points the crop's pixels see), and the path tracer must
/// match SPPM · (1 − f). Noise: ~1 % for each image's crop mean and for f; bound 3 %.
#[test]
fn spot_lit_caustic_appears_only_with_photons() {
    let path = radiant_testkit::repo_path("scenes/cornell-caustics-spot.pbrt");
    let desc = parse_file(&path).expect("spot scene");
    let sppm = with_integrator(desc.clone(), "sppm", sppm_params(), Some(64));
    let (photons, _, _) = render_sppm(&sppm, 64, 2);
    let path_desc = with_integrator(desc, "path", sppm_params(), Some(64));
    let traced = common::render(
        &path_desc,
        &Overrides {
            spp: Some(64),
            ..Default::default()
        },
    );
    let caustic = crop_at(CAUSTIC_CROP, 64);
    let (pc, tc) = (
        photons.mean_in(caustic).unwrap(),
        traced.mean_in(caustic).unwrap(),
    );
    let floor = crop_at(FLOOR_CROP, 64);
    let (pf, tf) = (
        photons.mean_in(floor).unwrap(),
        traced.mean_in(floor).unwrap(),
    );

    // The share of the floor's irradiance that came off a specular surface first.
    let session = Session::new(&sppm, &Overrides::default()).unwrap();
    let settings = PhotonSettings {
        photons: 1_000_000,
        caustic_photons: 0,
        visualize: Visualize::Density,
        max_depth: 100,
        ..Default::default()
    };
    let maps = PhotonMaps::build(
        &session.ctx.world,
        &settings,
        SamplerKind::Sobol,
        1,
        &Progress::default(),
    );
    let (mut all, mut specular) = (0.0f64, 0.0f64);
    for y in floor.y0..floor.y1 {
        for x in floor.x0..floor.x1 {
            let raster = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let ray = session
                .ctx
                .camera
                .generate_ray(raster, glam::Vec2::splat(0.5))
                .unwrap()
                .ray;
            let hit = session
                .ctx
                .world
                .intersect(&ray, f32::INFINITY)
                .expect("the floor");
            assert!(
                hit.p.y.abs() < 1e-3,
                "crop pixel ({x},{y}) does not see the floor"
            );
            maps.global.tree().within(hit.p, 15.0 * 15.0, |_, ph, _| {
                if ph.normal().y > 0.9 {
                    let g = maps.global.power(ph).g as f64;
                    all += g;
                    if ph.flags & FROM_SPECULAR != 0 {
                        specular += g;
                    }
                }
            });
        }
    }
    let f = specular / all;
    eprintln!(
        "caustic: sppm {pc}, path {tc}; floor: sppm {pf}, path {tf} ({:+.2} %), light via spheres {:.2} %",
        100.0 * (pf / tf - 1.0),
        100.0 * f
    );
    assert!(pc > 10.0 * tc, "caustic: sppm {pc}, path {tc}");
    let expect = pf * (1.0 - f);
    assert!(
        (tf / expect - 1.0).abs() < 0.03,
        "floor: path {tf} vs sppm without specular light {expect}"
    );
}

/// Cancelling after iteration 4 (from the snapshot callback) ends the render there with
/// exactly the 4-iteration image; images do not depend on the thread count.
#[test]
fn cancellation_and_thread_count_keep_the_image_exact() {
    let desc = with_integrator(cornell_caustics(), "sppm", sppm_params(), Some(32));
    let (full, _, snaps) = render_sppm(&desc, 8, 1);
    let (two, _, _) = render_sppm(&desc, 8, 2);
    assert_eq!(full, two);
    let session = Session::new(
        &desc,
        &Overrides {
            spp: Some(8),
            ..Default::default()
        },
    )
    .unwrap();
    let progress = Progress::default();
    let out = session.render_with_snapshots(&progress, &mut |k, _| {
        if k == 4 {
            progress.cancel.store(true, Ordering::Relaxed);
        }
    });
    assert!(out.interrupted);
    assert_eq!(out.spp_done, 4);
    let four = &snaps.iter().find(|s| s.0 == 4).unwrap().1;
    assert_eq!(&out.film.image(), four);
}

/// The default radii: the global estimate's 8 pixel footprints at the scene centre's
/// distance (at most 1/32 of the image's side), the caustic estimate's one. For the
/// pinhole camera of cornell-caustics a pixel at distance t spans
/// t · 2 tan(fov/2) / width (to 0.01 % this close to the axis), with t from the camera
/// to the centre of the scene's bounds.
#[test]
fn default_radii_are_pixel_footprints() {
    use radiant::render::integrator::sppm::{default_caustic_radius, default_radius};
    for (size, global_pixels) in [(256, 8.0), (128, 4.0), (64, 2.0), (512, 8.0)] {
        let desc = with_integrator(cornell_caustics(), "sppm", ParamSet::new(), Some(256));
        let overrides = Overrides {
            resolution: Some((size, size)),
            ..Default::default()
        };
        let session = Session::new(&desc, &overrides).unwrap();
        let centre = session.ctx.world.scene_sphere().center;
        let t = (centre - glam::Vec3::new(278.0, 273.0, -800.0)).length();
        let fov = 39.3077f32.to_radians();
        let pixel = t * 2.0 * (fov / 2.0).tan() / size as f32;
        let r = default_radius(&session.ctx);
        let expect = global_pixels * pixel;
        assert!(
            (r / expect - 1.0).abs() < 1e-3,
            "{size}: radius {r} vs {expect}"
        );
        let rc = default_caustic_radius(&session.ctx);
        assert!(
            (rc / pixel - 1.0).abs() < 1e-3,
            "{size}: caustic radius {rc} vs {pixel}"
        );
    }
}

#[test]
fn parameters_are_read_and_checked() {
    let desc = |params: ParamSet| IntegratorDesc {
        name: "sppm".into(),
        params,
        loc: cornell_caustics().integrator.loc,
    };
    let (i, w) = common::choose(&desc(
        ParamSet::new()
            .with("radius", ParamValue::Float(vec![4.0]))
            .with("photonsperiteration", ParamValue::Int(vec![1000]))
            .with("maxdepth", ParamValue::Int(vec![7]))
            .with("seed", ParamValue::Int(vec![9]))
            .with("alpha", ParamValue::Float(vec![0.7])),
    ))
    .unwrap();
    assert!(w.is_empty(), "{w:?}");
    let s = common::concrete::<SppmIntegrator>(&*i).settings;
    assert_eq!(
        (
            s.radius,
            s.photons_per_iteration,
            s.max_depth,
            s.seed,
            s.alpha
        ),
        (Some(4.0), Some(1000), 7, Some(9), 0.7)
    );
    let (i, _) = common::choose(&desc(
        ParamSet::new().with("photonsperiteration", ParamValue::Int(vec![-1])),
    ))
    .unwrap();
    let s = common::concrete::<SppmIntegrator>(&*i).settings;
    assert!(s.photons_per_iteration.is_none() && s.radius.is_none());
    assert_eq!(
        (
            s.caustic_radius,
            s.caustic_photons_per_iteration,
            s.sharp_direct_samples
        ),
        (None, None, 4)
    );
    let (i, w) = common::choose(&desc(
        ParamSet::new()
            .with("causticradius", ParamValue::Float(vec![0.5]))
            .with("causticphotonsperiteration", ParamValue::Int(vec![0]))
            .with("sharpdirectsamples", ParamValue::Int(vec![1])),
    ))
    .unwrap();
    assert!(w.is_empty(), "{w:?}");
    let s = common::concrete::<SppmIntegrator>(&*i).settings;
    assert_eq!(
        (
            s.caustic_radius,
            s.caustic_photons_per_iteration,
            s.sharp_direct_samples
        ),
        (Some(0.5), Some(0), 1)
    );
    for (k, v) in [
        ("radius", ParamValue::Float(vec![0.0])),
        ("causticradius", ParamValue::Float(vec![-1.0])),
        ("photonsperiteration", ParamValue::Int(vec![0])),
        ("causticphotonsperiteration", ParamValue::Int(vec![-2])),
        ("sharpdirectsamples", ParamValue::Int(vec![0])),
        ("alpha", ParamValue::Float(vec![1.0])),
    ] {
        assert!(
            common::choose(&desc(ParamSet::new().with(k, v))).is_err(),
            "{k}"
        );
    }
}
