//! Adaptive refinement driven by the solution (Cohen, Greenberg, Immel & Brock, "An
//! Efficient Radiosity Approach for Realistic Image Synthesis", IEEE CG&A 1986: elements
//! are subdivided where the radiosity changes strongly between neighbours, since a
//! constant element there is a poor fit).
//!
//! Solve, compare every pair of patches that share an edge on the same surface (same
//! material, normals within the display's smoothing angle), split both when their
//! radiosities differ by more than a fraction `threshold` of the larger in some band,
//! and solve again on the refined mesh ([`crate::mesh::refinement`] keeps it conforming). Shadow
//! boundaries, penumbrae and the dark strips along contact edges draw the splits;
//! evenly lit regions keep their patches. Patches that received no light at all
//! (hidden under a block) are left alone: the step at their edge is geometry, not a
//! badly resolved radiosity.

use std::collections::HashMap;
use std::ops::ControlFlow;

use super::progressive::{ProgressiveState, Start};
use super::{RadiosityError, Solution, SolveEvent, solve_start};
use crate::mesh::meshed_scene::RadiosityScene;
use crate::mesh::refinement::{RefinedScene, Refinement};
use crate::output::display::SMOOTH_ANGLE_DEG;
use crate::settings::RadiositySettings;
use crate::visibility::Visibility;
use radiant_render::light::{Light, SceneSphere};

/// Radiosities below this fraction of the band's area-weighted mean count as this much
/// when contrasts are measured, so that nearly black regions do not draw endless splits
/// for differences nobody can see.
const DARK_FRACTION: f64 = 1e-2;

/// Relative contrast `|B_i - B_k| / max(B_i, B_k, floor)` of every pair of front patches
/// that share an edge on the same surface, the larger over the bands; a patch is marked
/// when any of its pairs exceeds `threshold`.
pub fn contrast_marks(
    scene: &RadiosityScene,
    radiosity: &[[f64; 3]],
    irradiance: &[[f64; 3]],
    threshold: f64,
) -> Vec<bool> {
    let set = &scene.patches;
    let front = scene.front_count;
    let lit = |i: usize| {
        irradiance[i].iter().any(|&h| h > 0.0) || set.patches[i].emission.iter().any(|&e| e > 0.0)
    };
    let mut area = 0.0;
    let mut weighted = [0.0; 3];
    for i in (0..front).filter(|&i| lit(i)) {
        area += set.patches[i].area;
        for b in 0..3 {
            weighted[b] += set.patches[i].area * radiosity[i][b];
        }
    }
    let floor: [f64; 3] =
        std::array::from_fn(|b| DARK_FRACTION * weighted[b] / area.max(f64::MIN_POSITIVE));
    let mut by_edge: HashMap<(u32, u32), u32> = HashMap::with_capacity(4 * front);
    for (i, p) in set.patches[..front].iter().enumerate() {
        let c = &p.corners[..p.corner_count as usize];
        for k in 0..c.len() {
            by_edge.insert((c[k], c[(k + 1) % c.len()]), i as u32);
        }
    }
    let cos_limit = SMOOTH_ANGLE_DEG.to_radians().cos();
    let mut marked = vec![false; set.len()];
    for (i, p) in set.patches[..front].iter().enumerate() {
        if !lit(i) {
            continue;
        }
        let c = &p.corners[..p.corner_count as usize];
        for k in 0..c.len() {
            let Some(&other) = by_edge.get(&(c[(k + 1) % c.len()], c[k])) else {
                continue;
            };
            let j = other as usize;
            // Each pair once, from its lower index.
            if j < i || !lit(j) {
                continue;
            }
            let (ti, tj) = (scene.tag(i), scene.tag(j));
            if ti.material != tj.material
                || (ti.emission == [0.0; 3]) != (tj.emission == [0.0; 3])
                || p.normal.dot(set.patches[j].normal) < cos_limit
            {
                continue;
            }
            let contrast = (0..3)
                .map(|b| {
                    let (x, y) = (radiosity[i][b], radiosity[j][b]);
                    (x - y).abs() / x.max(y).max(floor[b]).max(f64::MIN_POSITIVE)
                })
                .fold(0.0, f64::max);
            if contrast > threshold {
                marked[i] = true;
                marked[j] = true;
            }
        }
    }
    marked
}

/// What an adaptive solve produced: the refined scene (`None` when nothing was split,
/// so the caller's scene is the one solved) and its solution, whose `iterations` and
/// `seconds` count all passes.
pub struct AdaptiveSolution {
    pub scene: Option<RadiosityScene>,
    pub solution: Solution,
    /// Refinement passes that split something.
    pub passes: u32,
}

impl AdaptiveSolution {
    /// The scene the solution belongs to.
    pub fn scene<'a>(&'a self, unrefined: &'a RadiosityScene) -> &'a RadiosityScene {
        self.scene.as_ref().unwrap_or(unrefined)
    }
}

/// Grades the mesh towards contact edges when asked, solves it, then up to
/// `settings.refine` times splits the patches of strong contrast and solves again.
/// `make_vis` builds the shadow-ray visibility of each mesh (it depends on the
/// patches). Progressive shots report a `fraction_done` that runs from 0 to 1 over all
/// passes.
pub fn solve_adaptive<V: Visibility>(
    scene: &RadiosityScene,
    lights: &[Light],
    sphere: SceneSphere,
    settings: &RadiositySettings,
    make_vis: impl Fn(&RadiosityScene) -> V,
    on_event: impl FnMut(SolveEvent<'_>) -> ControlFlow<()>,
) -> Result<AdaptiveSolution, RadiosityError> {
    solve_adaptive_from(scene, lights, sphere, settings, make_vis, None, on_event)
}

/// [`solve_adaptive`] whose first solve continues from a saved progressive state (of
/// the contact-graded mesh, before any refinement pass: a state saved in a later pass
/// belongs to a mesh this does not rebuild).
pub fn solve_adaptive_from<V: Visibility>(
    scene: &RadiosityScene,
    lights: &[Light],
    sphere: SceneSphere,
    settings: &RadiositySettings,
    make_vis: impl Fn(&RadiosityScene) -> V,
    resume: Option<&ProgressiveState>,
    mut on_event: impl FnMut(SolveEvent<'_>) -> ControlFlow<()>,
) -> Result<AdaptiveSolution, RadiosityError> {
    let start = std::time::Instant::now();
    let passes = settings.refine;
    let mut iterations = 0;
    let mut refinement: Option<Refinement> = None;
    // The refined mesh with the leaf cell of each patch (none yet: `scene` itself),
    // and the radiosities carried over from the previous pass.
    let mut current: Option<RefinedScene> = None;
    let mut guess: Option<Vec<[f64; 3]>> = None;
    if settings.contact_grading > 0 {
        let forest = refinement.insert(Refinement::new(scene.clone()));
        if forest.grade_contacts(settings.contact_grading, CONTACT_REACH) > 0 {
            current = Some(forest.scene());
        }
    }
    let mut done = 0;
    loop {
        let mesh = current.as_ref().map_or(scene, |r| &r.scene);
        let vis = make_vis(mesh);
        let share = 1.0 / (passes + 1) as f64;
        let offset = done as f64 * share;
        let start_from = match (&guess, resume) {
            (Some(g), _) => Start::Guess(g),
            (None, Some(state)) => Start::Resume(state),
            (None, None) => Start::Emission,
        };
        let solution =
            solve_start(
                mesh,
                lights,
                sphere,
                settings,
                &vis,
                start_from,
                |event| match event {
                    SolveEvent::Shot {
                        scene,
                        state,
                        fraction_done,
                    } => on_event(SolveEvent::Shot {
                        scene,
                        state,
                        fraction_done: offset + share * fraction_done,
                    }),
                    other => on_event(other),
                },
            )?;
        iterations += solution.iterations;
        let finish = |current: Option<RefinedScene>, mut solution: Solution, done| {
            // Shots and seconds of all passes (meshing included).
            solution.iterations = iterations;
            solution.seconds = start.elapsed().as_secs_f64();
            Ok(AdaptiveSolution {
                scene: current.map(|r| r.scene),
                solution,
                passes: done,
            })
        };
        if done == passes || solution.interrupted {
            return finish(current, solution, done);
        }
        let display = solution.display_radiosity(&mesh.patches);
        let marked = contrast_marks(
            mesh,
            &display,
            &solution.irradiance,
            settings.refine_threshold,
        );
        let forest = refinement.get_or_insert_with(|| Refinement::new(scene.clone()));
        // The mesh just solved as the forest sees it (the unrefined scene is its roots).
        let solved_base = current.is_none();
        let before = current.take().unwrap_or_else(|| forest.scene());
        let mut cells: Vec<u32> = marked
            .iter()
            .enumerate()
            .filter(|(_, m)| **m)
            .map(|(i, _)| before.patch_cell[i])
            .collect();
        cells.sort_unstable();
        cells.dedup();
        // Contact grading may have gone deeper; passes add levels on top of it.
        let deepest = settings.contact_grading + passes;
        if cells.is_empty() || forest.split(&cells, deepest) == 0 {
            return finish((!solved_base).then_some(before), solution, done);
        }
        let after = forest.scene();
        guess = Some(forest.carry(&before, &display, &after));
        current = Some(after);
        done += 1;
    }
}

/// Contact grading splits elements closer to a contact than this fraction of their
/// longest edge: the row touching the contact line at every level, so rows halve
/// towards it.
pub const CONTACT_REACH: f64 = 0.5;
