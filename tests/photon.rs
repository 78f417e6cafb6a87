//! Photon mapping: energy of the stored photons, projection maps (conservative and
//! unbiased), the furnace, the caustic of cornell-caustics against the reference, the
//! visualisations, determinism and parameters.

mod common;

use glam::{Vec2, Vec3};
use radiant::color::Rgb;
use radiant::image::{Crop, Image, compare, read_image};
use radiant::math::hash::Pcg32;
use radiant::render::integrator::photon::{
    CAUSTIC, FIRST_DIFFUSE, PhotonMaps, PhotonSettings, ProjectionMaps, Visualize,
};
use radiant::render::integrator::{Integrator, IntegratorStats};
use radiant::render::world::World;
use radiant::render::{Overrides, Progress, Session};
use radiant::scene::builtin::{LIGHT_LE, cornell_caustics, furnace};
use radiant::scene::params::{ParamSet, ParamValue};
use radiant::scene::{Geometry, IntegratorDesc, LightDesc, SamplerKind, SceneDesc, parse_file};

/// The caustic of the glass sphere in 256 × 256 pixel coordinates (x0, y0, x1, y1),
/// located from the reference: the bright ball-lens focus on the floor in front of and
/// right of the sphere spans pixels x 161..191, y 232..243; the crop adds a margin and
/// is aligned to multiples of 4 so that it survives 4 × 4 downsampling.
const CAUSTIC_CROP: (usize, usize, usize, usize) = (160, 232, 192, 244);

fn crop_at(res: usize) -> Crop {
    let f = 256 / res;
    let (x0, y0, x1, y1) = CAUSTIC_CROP;
    Crop {
        x0: x0 / f,
        y0: y0 / f,
        x1: x1 / f,
        y1: y1 / f,
    }
}

/// Box-downsampled reference: a pixel of a low-resolution render estimates exactly the
/// mean of the reference pixels it covers (one-pixel box filter).
fn reference(res: usize) -> Image {
    let full = read_image(common::shared("refs/cornell-caustics-256-ref.exr")).expect("reference");
    let f = full.width / res;
    let mut out = Image::new(res, res);
    for y in 0..res {
        for x in 0..res {
            let mut s = Rgb::BLACK;
            for j in 0..f {
                for i in 0..f {
                    s += full.get(x * f + i, y * f + j);
                }
            }
            out.set(x, y, s * (1.0 / (f * f) as f32));
        }
    }
    out
}

/// cornell-caustics with a front wall at z = 0 (facing the room): no photon escapes.
fn closed_cornell_caustics() -> SceneDesc {
    let mut desc = cornell_caustics();
    let mut wall = desc.shapes[0].clone();
    wall.geometry = Geometry::TriangleMesh {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(552.8, 0.0, 0.0),
            Vec3::new(556.0, 548.8, 0.0),
            Vec3::new(0.0, 548.8, 0.0),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        normals: None,
        uvs: None,
    };
    wall.area_light = None;
    desc.shapes.push(wall);
    desc
}

/// Replaces the area light by `light` (the luminaire stays, without emission).
fn relit(mut desc: SceneDesc, light: LightDesc) -> SceneDesc {
    for s in &mut desc.shapes {
        s.area_light = None;
    }
    desc.lights = vec![light];
    desc
}

fn point_light(desc: &SceneDesc) -> LightDesc {
    LightDesc::Point {
        position: Vec3::new(278.0, 540.0, 279.5),
        intensity: LIGHT_LE * 13650.0,
        loc: desc.camera.loc.clone(),
    }
}

fn spot_light(desc: &SceneDesc) -> LightDesc {
    LightDesc::Spot {
        position: Vec3::new(278.0, 540.0, 279.5),
        direction: -Vec3::Y,
        intensity: LIGHT_LE * 13650.0,
        cos_falloff_start: 40f32.to_radians().cos(),
        cos_total_width: 50f32.to_radians().cos(),
        loc: desc.camera.loc.clone(),
    }
}

/// Floor and spheres of cornell-caustics under the open sky: a distant light (sun) and
/// a constant environment.
fn open_sky() -> SceneDesc {
    let mut desc = cornell_caustics();
    let n = desc.shapes.len();
    // The floor, then the two spheres (the last two shapes).
    desc.shapes = vec![
        desc.shapes[0].clone(),
        desc.shapes[n - 2].clone(),
        desc.shapes[n - 1].clone(),
    ];
    for s in &mut desc.shapes {
        s.area_light = None;
    }
    let loc = desc.camera.loc.clone();
    desc.lights = vec![
        LightDesc::Distant {
            direction: Vec3::new(0.3, -1.0, 0.2),
            radiance: Rgb::new(3.0, 2.5, 2.0),
            loc: loc.clone(),
        },
        LightDesc::Infinite {
            radiance: Rgb::splat(0.05),
            loc,
        },
    ];
    desc
}

fn maps(world: &World, settings: PhotonSettings) -> PhotonMaps {
    PhotonMaps::build(
        world,
        &settings,
        SamplerKind::Sobol,
        7,
        &Progress::default(),
    )
}

/// Every photon reaches a first diffuse surface in a closed scene whose specular
/// surfaces absorb nothing (mirror reflectance 1, clear glass), carrying its share of
/// the lights' power unchanged (Russian roulette never fires at weight 1). The stored
/// first hits must therefore add up to the lights' power. Area and point lights give
/// every photon exactly Φ/N, so only rounding remains (f16 storage: below 2⁻¹¹ ≈ 4.9e-4 of each value, and
/// systematic here because all photons carry the same power); the
/// spot's photons vary with its falloff, whose Sobol-stratified mean over 100k photons
/// is good to far better than 5e-3.
#[test]
fn first_diffuse_hits_carry_the_lights_power() {
    let closed = closed_cornell_caustics();
    let cases = [
        ("area", closed.clone(), 1e-3),
        ("point", relit(closed.clone(), point_light(&closed)), 1e-3),
        ("spot", relit(closed.clone(), spot_light(&closed)), 5e-3),
    ];
    for (name, desc, tol) in cases {
        let (world, _) = World::build(&desc).expect("world");
        let scene = world.scene_sphere();
        let power = world
            .lights
            .iter()
            .fold(Rgb::BLACK, |a, l| a + l.power(scene));
        let m = maps(
            &world,
            PhotonSettings {
                photons: 100_000,
                caustic_photons: 0,
                visualize: Visualize::Density,
                max_depth: 100,
                ..Default::default()
            },
        );
        let stored = m.global.total_power(FIRST_DIFFUSE);
        eprintln!("{name}: stored {stored:?}, power {power:?}");
        for c in 0..3 {
            let rel = stored[c] / power[c] as f64 - 1.0;
            assert!(
                rel.abs() < tol,
                "{name} channel {c}: stored {} vs power {} ({rel:e})",
                stored[c],
                power[c]
            );
        }
    }
}

/// Conservativeness: every light sample (u_pos, u_dir) whose ray hits a specular object
/// first lies in a marked cell. A single miss would bias the caustics.
#[test]
fn projection_maps_cover_every_ray_that_hits_a_specular_object() {
    let base = cornell_caustics();
    for (name, desc) in [
        ("area", base.clone()),
        ("point", relit(base.clone(), point_light(&base))),
        ("spot", relit(base.clone(), spot_light(&base))),
        ("distant and infinite", open_sky()),
    ] {
        let (world, _) = World::build(&desc).expect("world");
        let scene = world.scene_sphere();
        let pm = ProjectionMaps::build(&world).expect("specular objects exist");
        let mut rng = Pcg32::new(3, 1);
        for l in 0..world.lights.len() {
            let (mut specular, mut marked) = (0, 0);
            for _ in 0..100_000 {
                let u_pos = Vec2::new(rng.uniform(), rng.uniform());
                let u_dir = Vec2::new(rng.uniform(), rng.uniform());
                let Some(e) = world.lights[l].sample_emission(u_pos, u_dir, scene) else {
                    continue;
                };
                let inside = pm.contains(l, u_pos, u_dir);
                marked += inside as u32;
                let Some(hit) = world.intersect(&e.ray, f32::INFINITY) else {
                    continue;
                };
                if world.materials[hit.material as usize].is_specular() {
                    specular += 1;
                    assert!(
                        inside,
                        "{name}: light {l}, u_pos {u_pos}, u_dir {u_dir} hits a sphere outside the map"
                    );
                }
            }
            let fraction = pm.fraction(l);
            eprintln!(
                "{name}, light {l}: {specular} rays hit a sphere first, {marked} lie in marked cells (fraction {fraction:.3})"
            );
            assert!(
                specular > 500,
                "{name}: only {specular} rays hit the spheres"
            );
            // Mapped lights must also save work: at most 4x the rays that actually hit.
            // (The environment has no map: fraction 1.)
            if fraction < 1.0 {
                assert!(
                    marked < 4 * specular,
                    "{name}: {marked} marked for {specular} hits"
                );
            }
        }
    }
}

/// Unbiasedness: the caustic map's flux is the same with photons aimed by projection
/// maps (fewer, weighted by the covered fraction) as with photons sent everywhere. The
/// untargeted run stores n ≈ 12k caustic photons of equal power, so its flux has a
/// relative standard deviation near 1/√n ≈ 0.9 %; the targeted run's is smaller. Four
/// standard deviations of the difference: 4 %.
#[test]
fn projection_maps_do_not_change_the_caustic_flux() {
    for (name, desc) in [
        ("area", cornell_caustics()),
        ("distant and infinite", open_sky()),
    ] {
        let (world, _) = World::build(&desc).expect("world");
        let settings = |projection_maps| PhotonSettings {
            photons: 0,
            caustic_photons: 200_000,
            projection_maps,
            final_gather_samples: 0,
            max_depth: 100,
            ..Default::default()
        };
        let aimed = maps(&world, settings(true));
        let everywhere = maps(&world, settings(false));
        let a = aimed.caustic.total_power(CAUSTIC);
        let b = everywhere.caustic.total_power(CAUSTIC);
        eprintln!(
            "{name}: aimed {} photons, flux {a:?}; everywhere {} photons, flux {b:?}",
            aimed.caustic.len(),
            everywhere.caustic.len()
        );
        assert!(
            aimed.caustic.len() > 3 * everywhere.caustic.len(),
            "{name}: no gain"
        );
        for c in 0..3 {
            assert!(
                (a[c] / b[c] - 1.0).abs() < 0.04,
                "{name} channel {c}: {} vs {}",
                a[c],
                b[c]
            );
        }
    }
}

fn photonmap_desc(mut desc: SceneDesc, params: ParamSet, name: &str) -> SceneDesc {
    desc.integrator = IntegratorDesc {
        name: name.into(),
        params,
        loc: desc.integrator.loc.clone(),
    };
    desc
}

fn quick_params() -> ParamSet {
    ParamSet::new()
        .with("photons", ParamValue::Int(vec![50_000]))
        .with("causticphotons", ParamValue::Int(vec![100_000]))
        .with("finalgathersamples", ParamValue::Int(vec![8]))
        .with("lookup", ParamValue::Int(vec![50]))
        .with("globallookup", ParamValue::Int(vec![100]))
        .with("maxdepth", ParamValue::Int(vec![100]))
}

fn mean_and_sd(img: &Image, c: usize) -> (f64, f64) {
    let v: Vec<f64> = img.pixels.iter().map(|p| p[c] as f64).collect();
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (
        m,
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt(),
    )
}

/// In the furnace every pixel is Le / (1 − albedo) = 2. With final gathering: emission
/// 1 + direct 0.5 (next-event estimation) + indirect 0.5 from the global map read at the
/// gather rays' hits. The photon density is uniform, so the kernel adds no bias; the
/// pixel spread measures the noise, and the image mean must lie within 4 standard
/// errors of 2 plus 0.5 % for the irradiance precomputed at discrete points.
#[test]
fn furnace_converges_to_two() {
    let desc = photonmap_desc(furnace(), quick_params(), "photonmap");
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
        let desc = photonmap_desc(furnace(), params, "photonmap");
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
    let mut desc = photonmap_desc(cornell_caustics(), params, "photonmap");
    desc.film.xresolution = 64;
    desc.film.yresolution = 64;
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
    let mut desc = photonmap_desc(cornell_caustics(), quick_params(), "photonmap");
    desc.film.xresolution = 64;
    desc.film.yresolution = 64;
    let img = common::render(
        &desc,
        &Overrides {
            spp: Some(4),
            ..Default::default()
        },
    );
    let reference = reference(64);
    let crop = crop_at(64);
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

/// Photon maps and images are identical at any thread count.
#[test]
fn photon_maps_are_identical_at_one_and_two_threads() {
    let mut desc = photonmap_desc(cornell_caustics(), quick_params(), "photonmap");
    desc.film.xresolution = 24;
    desc.film.yresolution = 24;
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
    let (IntegratorStats::PhotonMap(sa), IntegratorStats::PhotonMap(sb)) = (sa, sb) else {
        panic!("photon map statistics expected");
    };
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
    let (i, warnings) = Integrator::from_desc(&desc(
        quick_params()
            .with("maxradius", ParamValue::Float(vec![12.5]))
            .with("kernel", ParamValue::String(vec!["epanechnikov".into()]))
            .with("projectionmaps", ParamValue::Bool(vec![false]))
            .with("seed", ParamValue::Int(vec![3]))
            .with("bogus", ParamValue::Int(vec![1])),
        "photonmap",
    ))
    .unwrap();
    let Integrator::PhotonMap(s) = i else {
        panic!("photonmap expected")
    };
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
    let (i, _) = Integrator::from_desc(&desc(ParamSet::new(), "photonviz")).unwrap();
    assert!(matches!(
        i,
        Integrator::PhotonMap(PhotonSettings {
            visualize: Visualize::Density,
            ..
        })
    ));
    for (k, v) in [
        ("kernel", ParamValue::String(vec!["gaussian".into()])),
        ("visualize", ParamValue::String(vec!["everything".into()])),
        ("maxradius", ParamValue::Float(vec![-1.0])),
        ("photons", ParamValue::Int(vec![-5])),
    ] {
        assert!(
            Integrator::from_desc(&desc(ParamSet::new().with(k, v), "photonmap")).is_err(),
            "{k}"
        );
    }
}

/// The spot-lit variant of cornell-caustics in `scenes/` parses into the light the
/// tests build in code.
#[test]
fn spot_scene_file_matches_the_code_variant() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-caustics-spot.pbrt");
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
