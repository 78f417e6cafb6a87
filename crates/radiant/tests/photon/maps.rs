//! The photon maps themselves: stored energy and projection maps.

use glam::Vec2;
use radiant::color::Rgb;
use radiant::math::hash::Pcg32;
use radiant::render::integrator::photon::{
    CAUSTIC, FIRST_DIFFUSE, PhotonSettings, ProjectionMaps, Visualize,
};
use radiant::render::world::World;
use radiant::scene::builtin::cornell_caustics;

use crate::scenes::{closed_cornell_caustics, maps, open_sky, point_light, relit, spot_light};

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
                let Some(e) = world.lights[l].sample_le(u_pos, u_dir, scene) else {
                    continue;
                };
                let inside = pm.contains(l, u_pos, u_dir);
                marked += inside as u32;
                let Some(hit) = world.intersect(&e.ray, f32::INFINITY) else {
                    continue;
                };
                if world.material_at(&hit, -e.ray.d).is_specular() {
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
