//! cornell-caustics with its glass sphere made rough (Trowbridge–Reitz, pbrt roughness
//! 0.1, i.e. alpha = √0.1 with the default remapping): SPPM and the photon mapper
//! against the path tracer tile by tile, and the photons' power at their first
//! non-delta hits against an independent photon walk.
//!
//! Unlike the smooth sphere, the rough one lets the path tracer find the caustic by
//! next-event estimation from the glass's inner surface, so the path tracer is a
//! reference for all three integrators at once.

use glam::Vec2;
use radiant::color::Rgb;
use radiant::image::Image;
use radiant::image::tiles::{TileCriterion, TileStats, compare_tiles};
use radiant::math::hash::Pcg32;
use radiant::render::integrator::photon::{FIRST_DIFFUSE, PhotonSettings, Visualize};
use radiant::render::material::TransportMode;
use radiant::render::world::World;
use radiant::scene::builtin::cornell_caustics;
use radiant::scene::params::{ParamSet, ParamValue};
use radiant::scene::{MaterialDesc, SceneDesc};

use crate::common;
use crate::scenes::{closed_cornell_caustics, maps, with_integrator};

const RES: u32 = 64;
const TILE: usize = 8;
const PASSES: u64 = 4;

/// `desc` with its (smooth, η = 1.5) glass made rough.
pub fn roughened(mut desc: SceneDesc) -> SceneDesc {
    let alpha = 0.1f32.sqrt();
    let mut found = 0;
    for m in &mut desc.materials {
        if let MaterialDesc::Dielectric { eta } = *m {
            *m = MaterialDesc::RoughDielectric {
                eta,
                alpha_u: alpha,
                alpha_v: alpha,
            };
            found += 1;
        }
    }
    assert_eq!(found, 1, "one glass material expected");
    desc
}

fn passes(desc: &SceneDesc, spp: u32) -> (TileStats, Image) {
    let start = std::time::Instant::now();
    let passes = common::render_passes(desc, spp, PASSES);
    eprintln!(
        "{}: {PASSES} passes of {spp} spp in {:.1} s",
        desc.integrator.name,
        start.elapsed().as_secs_f64()
    );
    TileStats::from_passes(&passes, TILE).unwrap()
}

/// Path tracer (4 × 256 spp), SPPM (4 × 64 iterations) and the photon mapper (4 × 4 spp
/// of 8 gather rays) on `scene` at 64 × 64, each as four independent passes whose
/// spread gives every 8 × 8 tile mean its standard error (`radiant::image::tiles`). A
/// tile passes within 4 standard errors of the two images plus 1 % of the path
/// tracer's mean: the density estimates' kernel bias, which the final radii here (SPPM
/// after 64 iterations, the photon mapper's 50-photon caustic lookups) keep below that
/// on these smooth walls (measured on the rough-glass room: every tile outside the
/// sphere within 4 SE with no floor at all). Failures are reported as `{name}-sppm` and
/// `{name}-photonmap`. Returns the path tracer's and SPPM's tile statistics.
pub fn photon_methods_match_the_path_tracer(
    scene: SceneDesc,
    name: &str,
) -> (TileStats, TileStats) {
    const CRITERION: TileCriterion = TileCriterion {
        k: 4.0,
        rel_floor: 0.01,
        abs_floor: 0.0,
    };
    let depth = ParamSet::new().with("maxdepth", ParamValue::Int(vec![100]));
    let path = with_integrator(scene.clone(), "path", depth.clone(), Some(RES));
    let (reference, _) = passes(&path, 256);

    let sppm = with_integrator(scene.clone(), "sppm", depth.clone(), Some(RES));
    let (s, s_img) = passes(&sppm, 64);
    let cmp = compare_tiles(&s, &reference, CRITERION, &|_, _| false).unwrap();
    common::assert_tiles(&format!("{name}-sppm"), &cmp, &s_img);

    let params = depth
        .with("photons", ParamValue::Int(vec![50_000]))
        .with("causticphotons", ParamValue::Int(vec![100_000]))
        .with("finalgathersamples", ParamValue::Int(vec![8]))
        .with("lookup", ParamValue::Int(vec![50]))
        .with("globallookup", ParamValue::Int(vec![100]));
    let pm = with_integrator(scene, "photonmap", params, Some(RES));
    let (p, p_img) = passes(&pm, 4);
    let cmp = compare_tiles(&p, &reference, CRITERION, &|_, _| false).unwrap();
    common::assert_tiles(&format!("{name}-photonmap"), &cmp, &p_img);
    (reference, s)
}

/// [`photon_methods_match_the_path_tracer`] in cornell-caustics with its glass made
/// rough. Every tile counts, those that see the room through the rough sphere included:
/// there the ceiling light seen in and through the glass is found by light samples at
/// the glass's vertices (weighted by MIS against the sampled bounce). Treated as a
/// specular surface, with the bounce alone, it arrives in rare, very bright samples,
/// and at these sample counts the photon mapper's tiles behind the sphere fail.
#[test]
fn sppm_and_photon_map_match_the_path_tracer_through_rough_glass() {
    photon_methods_match_the_path_tracer(roughened(cornell_caustics()), "rough-glass");
}

/// In the closed room (front wall added, mirror of reflectance 1) every photon
/// reaches a first non-delta surface, the rough glass being passed like a specular
/// one. A non-absorbing smooth chain keeps the photon's power, so there the stored
/// flux is the lights' power; the microfacet dielectric conserves only single
/// scattering (its directional albedo is below 1), so what reaches the walls is the
/// power less what the rough glass lost. An independent walk here (own random numbers,
/// no Russian roulette, no projection maps, no f16 storage) measures both terms: the
/// photon map's stored flux must equal power − lost within the noise of the two
/// estimates, and `lost` is many standard errors above zero.
#[test]
fn first_non_delta_hits_carry_the_power_the_rough_glass_passes_on() {
    let desc = roughened(closed_cornell_caustics());
    let (world, _) = World::build(&desc).expect("world");
    let scene = world.scene_sphere();
    let power = world
        .lights
        .iter()
        .fold(Rgb::BLACK, |a, l| a + l.power(scene));

    // The walk: per photon, the fraction of its power stored and lost (channel g; the
    // scene's glass and mirror are grey).
    let n = 200_000usize;
    let mut rng = Pcg32::new(21, 5);
    let (mut lost, mut lost2, mut glass_photons, mut escaped) = (0.0f64, 0.0f64, 0usize, 0usize);
    for _ in 0..n {
        let chosen = world
            .light_sampler
            .sample_emission_light(rng.uniform())
            .expect("a light");
        let u_pos = Vec2::new(rng.uniform(), rng.uniform());
        let u_dir = Vec2::new(rng.uniform(), rng.uniform());
        let Some(e) = world.lights[chosen.index].sample_le(u_pos, u_dir, scene) else {
            continue;
        };
        let mut ray = e.ray;
        let mut weight = 1.0f64;
        let mut touched_glass = false;
        let mut landed = false;
        for _ in 0..100 {
            let Some(hit) = world.intersect(&ray, f32::INFINITY) else {
                break;
            };
            let wo_world = -ray.d.normalize();
            let material = world.material_at(&hit, wo_world);
            if !material.passes_photon_paths() {
                landed = true;
                break;
            }
            touched_glass |= material.dielectric_eta().is_some();
            let frame = World::shading_frame(&hit, &material);
            let wo = frame.to_local(wo_world);
            let u = Vec2::new(rng.uniform(), rng.uniform());
            let Some(bs) = material.sample(wo, rng.uniform(), u, TransportMode::Importance) else {
                weight = 0.0;
                landed = true;
                break;
            };
            weight *= (bs.f.g * bs.wi.z.abs() / bs.pdf) as f64;
            ray = hit.spawn_ray(frame.to_world(bs.wi));
        }
        escaped += !landed as usize;
        glass_photons += touched_glass as usize;
        let l = 1.0 - weight;
        lost += l;
        lost2 += l * l;
    }
    let lost_fraction = lost / n as f64;
    let lost_se = ((lost2 / n as f64 - lost_fraction * lost_fraction) / n as f64).sqrt();

    let m = maps(
        &world,
        PhotonSettings {
            photons: 200_000,
            caustic_photons: 0,
            visualize: Visualize::Density,
            max_depth: 100,
            ..Default::default()
        },
    );
    let stored = m.global.total_power(FIRST_DIFFUSE);
    // The map's noise lies in the glass photons alone (the others carry Φ/N exactly);
    // each stores at most about Φ/N after Russian roulette, so its variance is below
    // the share of photons through the glass, over the photon count. f16 storage adds
    // up to 2⁻¹¹ of each value, systematically.
    let glass_share = glass_photons as f64 / n as f64;
    let stored_se = (glass_share / 200_000.0).sqrt();
    let tolerance = 4.0 * (stored_se * stored_se + lost_se * lost_se).sqrt() + 5e-4;
    let expected = 1.0 - lost_fraction;
    eprintln!(
        "stored {stored:?} of power {power:?}: fraction {:.5}; walk: lost {lost_fraction:.5} ± {lost_se:.5}, \
         {glass_photons} of {n} photons through the glass, {escaped} escaped",
        stored[1] / power.g as f64
    );
    eprintln!("tolerance {tolerance:.5}");
    assert_eq!(escaped, 0, "the room is closed");
    assert!(
        lost_fraction > 20.0 * lost_se,
        "lost {lost_fraction} ± {lost_se}"
    );
    for c in 0..3 {
        let fraction = stored[c] / power[c] as f64;
        assert!(
            (fraction - expected).abs() < tolerance,
            "channel {c}: stored {fraction} of the power, expected {expected} ± {tolerance}"
        );
    }
}
