//! Adaptive refinement: the refined mesh stays conforming and covers the same surfaces,
//! contact grading finds the contact lines, and a refined render runs through the
//! integrator and the session.

use std::ops::ControlFlow;

use radiant_math::DVec3;
use radiant_math::hash::hash_u64s;
use radiant_radiosity::mesh::meshed_scene::{NO_TWIN, RadiosityScene};
use radiant_radiosity::mesh::refinement::Refinement;
use radiant_radiosity::settings::RadiositySettings;
use radiant_radiosity::solve::adaptive::contrast_marks;
use radiant_radiosity::visibility::bvh::FaceVisibility;
use radiant_render::world::World;
use radiant_scene::builtin::cornell_box;

use crate::mesh_checks::{assert_conforming, segment_distance};

fn cornell(area: f64, two_sided: bool) -> RadiosityScene {
    let settings = RadiositySettings {
        max_patch_area: Some(area),
        two_sided,
        ..RadiositySettings::default()
    };
    RadiosityScene::from_desc(&cornell_box(), &settings).unwrap()
}

#[test]
fn refined_meshes_stay_conforming_and_cover_the_same_surfaces() {
    // Three rounds of splitting a pseudo-random third of the leaves (closure pieces
    // included, so their leaves split), on both sides of two-sided surfaces. Every
    // round must keep the total area (to rounding), the twin pairs and the absence of
    // T-junctions. Red splits keep the shapes of triangles (and nearly of quads) and
    // closure pieces are never split again, so angles cannot shrink round after round:
    // the smallest is a closure median cutting the smallest corner of the base mesh
    // once (measured 7.1 degrees from the 18.3 of a stitching triangle, every round;
    // allowed 0.35 of the base's).
    let base = cornell(4000.0, true);
    let area = base.patches.total_area();
    let base_boundary = assert_conforming(&base).0;
    let smallest_angle = |scene: &RadiosityScene| {
        (0..scene.patches.len())
            .map(|i| {
                let polygon = scene.patches.polygon(i);
                let c = polygon.as_slice();
                (0..c.len())
                    .map(|k| {
                        let (a, b, d) =
                            (c[k], c[(k + 1) % c.len()], c[(k + c.len() - 1) % c.len()]);
                        (b - a).angle_between(d - a)
                    })
                    .fold(f64::MAX, f64::min)
            })
            .fold(f64::MAX, f64::min)
    };
    let base_angle = smallest_angle(&base);
    let mut forest = Refinement::new(base.clone());
    let mut refined = forest.scene();
    assert_eq!(refined.scene.patches.len(), base.patches.len());
    for round in 0..3u64 {
        let cells: Vec<u32> = refined.patch_cell[..refined.scene.front_count]
            .iter()
            .copied()
            .filter(|&c| hash_u64s(&[round, c as u64]).is_multiple_of(3))
            .collect();
        assert!(forest.split(&cells, 8) > 0);
        refined = forest.scene();
        let scene = &refined.scene;
        assert!(
            (scene.patches.total_area() / area - 1.0).abs() < 1e-9,
            "round {round}: area {} vs {area}",
            scene.patches.total_area()
        );
        // Back sides mirror their fronts.
        for i in 0..scene.front_count {
            let t = scene.twin[i];
            if t != NO_TWIN {
                assert_eq!(scene.twin[t as usize], i as u32);
                let (f, b) = (
                    &scene.patches.patches[i],
                    &scene.patches.patches[t as usize],
                );
                assert!((f.area - b.area).abs() < 1e-9 * f.area);
                assert!((f.normal + b.normal).length() < 1e-9);
            }
        }
        assert_eq!(scene.patch_face.len(), scene.patches.len());
        // Refining never opens the input boundary further: the open edges are the
        // input's boundary cut at the new points.
        assert!(assert_conforming(scene).0 >= base_boundary);
        let angle = smallest_angle(scene);
        assert!(
            angle > 0.35 * base_angle,
            "{} vs {}",
            angle.to_degrees(),
            base_angle.to_degrees()
        );
    }
}

#[test]
fn contact_grading_refines_towards_the_blocks_bases_only() {
    // Two levels of grading on the canonical box: the floor elements next to the
    // blocks' bases and the blocks' lowest elements halve twice (a quarter of the
    // edge); the room's corners (joined faces) and the ceiling keep their size.
    let base = cornell(2000.0, false);
    let mut forest = Refinement::new(base.clone());
    assert!(forest.grade_contacts(2, 0.5) > 0);
    let scene = forest.scene().scene;
    assert_conforming(&scene);
    let base_edge = base.max_edge;
    let smallest_near = |region: &dyn Fn(DVec3) -> bool| {
        (0..scene.front_count)
            .filter(|&i| region(scene.patches.patches[i].centroid))
            .map(|i| scene.patches.patches[i].area.sqrt())
            .fold(f64::MAX, f64::min)
    };
    // Floor (y = 0) within 10 mm of the short block's front face, which runs from
    // (290, 114) to (130, 65) in (x, z) (the builtin box's blocks, rounded).
    let near_short_block = |p: DVec3| {
        let (a, b) = (DVec3::new(290.0, 0.0, 114.0), DVec3::new(130.0, 0.0, 65.0));
        p.y < 1e-3 && segment_distance(DVec3::new(p.x, 0.0, p.z), a, b) < 10.0
    };
    let floor_at_contact = smallest_near(&near_short_block);
    assert!(
        floor_at_contact < 0.3 * base_edge,
        "{floor_at_contact} vs {base_edge}"
    );
    // Ceiling elements (y = 548.8) keep the base size, as do the floor's corners.
    let ceiling = smallest_near(&|p: DVec3| p.y > 548.0);
    assert!(ceiling > 0.6 * base_edge, "{ceiling} vs {base_edge}");
    let floor_corner = smallest_near(&|p: DVec3| p.y < 1e-3 && p.x < 40.0 && p.z > 520.0);
    assert!(
        floor_corner > 0.6 * base_edge,
        "{floor_corner} vs {base_edge}"
    );
}

#[test]
fn contrast_marks_follow_the_shadow_edges() {
    // After a coarse solve of the canonical box, the patches whose radiosity differs
    // from a neighbour's by more than 25 % lie where light changes fast: along the
    // shadows of the blocks on the floor, at the wall tops next to the light's plane,
    // at the bases of the blocks. The unshadowed floor at the front right, between
    // the short block's shadow and the red wall, has none.
    let base = cornell(2000.0, false);
    let vis = FaceVisibility::new(&base);
    let (world, _) = World::build(&cornell_box()).unwrap();
    let settings = RadiositySettings {
        max_patch_area: Some(2000.0),
        tolerance: 1e-2,
        ..RadiositySettings::default()
    };
    let solution = crate::common::solve_to_end(&base, &world, &settings, &vis);
    let marks = contrast_marks(
        &base,
        &solution.display_radiosity(&base.patches),
        &solution.irradiance,
        0.25,
    );
    let marked = marks.iter().filter(|m| **m).count();
    assert!(marked > 0 && marked < base.patches.len() / 2, "{marked}");
    let open_floor = (0..base.front_count).filter(|&i| {
        let c = base.patches.patches[i].centroid;
        c.y < 1e-3 && (380.0..500.0).contains(&c.x) && (20.0..140.0).contains(&c.z)
    });
    assert!(open_floor.clone().count() > 0);
    assert!(open_floor.clone().all(|i| !marks[i]));
    // The floor under the short block (unlit, hidden) is never marked.
    let hidden = (0..base.front_count).filter(|&i| {
        let c = base.patches.patches[i].centroid;
        c.y < 1e-3 && (c - DVec3::new(186.0, 0.0, 169.0)).length() < 40.0
    });
    assert!(hidden.clone().count() > 0);
    assert!(
        hidden
            .clone()
            .all(|i| !marks[i] && solution.irradiance[i] == [0.0; 3])
    );
}

#[test]
fn a_primed_solve_reaches_the_cold_solution() {
    // Progressive refinement from a starting guess (what a refinement pass carries
    // over from the coarser mesh) converges to the same radiosities as a cold start,
    // from a guess that is too bright (negative unshot radiosity) as from one too
    // dark, and keeps every watt booked.
    use radiant_radiosity::solve::solve_from;
    let scene = cornell(4000.0, false);
    let vis = FaceVisibility::new(&scene);
    let (world, _) = World::build(&cornell_box()).unwrap();
    let settings = RadiositySettings {
        max_patch_area: Some(4000.0),
        tolerance: 1e-7,
        ..RadiositySettings::default()
    };
    let solve_with = |guess: Option<&[[f64; 3]]>| {
        solve_from(
            &scene,
            &world.lights,
            world.scene_sphere(),
            &settings,
            &vis,
            guess,
            |_| ControlFlow::Continue(()),
        )
        .unwrap()
    };
    let cold = solve_with(None);
    assert!(cold.converged);
    let scale =
        |s: f64| -> Vec<[f64; 3]> { cold.radiosity.iter().map(|b| b.map(|v| s * v)).collect() };
    let mean_b: f64 = cold
        .radiosity
        .iter()
        .map(|b| b[0] + b[1] + b[2])
        .sum::<f64>()
        / (3 * cold.radiosity.len()) as f64;
    for s in [0.8, 1.25] {
        let guess = scale(s);
        let primed = solve_with(Some(&guess));
        assert!(primed.converged);
        let worst = primed
            .radiosity
            .iter()
            .zip(&cold.radiosity)
            .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
            .fold(0.0, f64::max);
        // Both stop at 1e-7 of the emitted power unshot.
        assert!(
            worst < 1e-5 * mean_b,
            "guess x{s}: {worst} vs mean {mean_b}"
        );
        let imbalance = primed.balance.imbalance();
        assert!(
            (0..3).all(|b| imbalance[b].abs() < 1e-9 * primed.balance.emitted[b]),
            "{imbalance:?}"
        );
    }
    // The exact solution as the guess: its priming shots alone leave (almost) nothing
    // to shoot.
    let exact = solve_with(Some(&cold.radiosity));
    assert!(exact.converged);
    assert!(
        exact.iterations <= scene.patches.len() + 10,
        "{} shots for {} patches (cold: {})",
        exact.iterations,
        scene.patches.len(),
        cold.iterations
    );
}
