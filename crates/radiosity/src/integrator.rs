//! Radiosity as an integrator: mesh the scene when it is chosen, solve when asked to
//! render (refining as the settings ask, with progress and cancellation through the
//! session's [`Progress`]), then show the solution through the shared pass loop.

use std::ops::ControlFlow;
use std::sync::atomic::Ordering;
use std::time::Instant;

use crate::mesh::meshed_scene::RadiosityScene;
use crate::output::shading::Shading;
use crate::settings::{RadiositySettings, VisibilitySource};
use crate::solve::adaptive::{AdaptiveSolution, solve_adaptive_from};
use crate::solve::progressive::ProgressiveState;
use crate::solve::{EscapeContext, RadiosityError, RadiosityStats, SolveEvent};
use crate::visibility::bvh::{FaceVisibility, SceneVisibility, WorldVisibility};
use radiant_render::integrator::{Integrator, RenderControl, RenderOutput, Stats, render_passes};
use radiant_render::world::World;
use radiant_render::{Progress, RenderContext};
use radiant_scene::{SceneDesc, SceneError, Warning};

/// `Integrator "radiosity"`: the meshed scene and the solver's settings.
pub struct RadiosityIntegrator {
    pub scene: RadiosityScene,
    pub settings: RadiositySettings,
}

impl RadiosityIntegrator {
    /// Meshes `desc` into patches as `settings` ask; returns the meshing's warnings
    /// (materials reduced to their diffuse part, shapes that cannot be meshed).
    pub fn new(
        desc: &SceneDesc,
        settings: RadiositySettings,
    ) -> Result<(RadiosityIntegrator, Vec<Warning>), SceneError> {
        let scene = RadiosityScene::from_desc(desc, &settings)?;
        let warnings = scene.warnings.clone();
        Ok((RadiosityIntegrator { scene, settings }, warnings))
    }
}

impl Integrator for RadiosityIntegrator {
    fn name(&self) -> &'static str {
        "radiosity"
    }

    /// Solves (refining as the settings ask), then renders the image; snapshots see it
    /// at every power-of-two samples per pixel, as for the other per-pixel integrators.
    fn render(&self, ctx: &RenderContext, control: &mut RenderControl<'_>) -> RenderOutput {
        let start = Instant::now();
        let settings = &self.settings;
        let solved = match solve_session_observed(
            &ctx.world,
            &self.scene,
            settings,
            control.progress,
            |_| {},
        ) {
            Ok(solved) => solved,
            Err(e) => {
                // No image of a failed solve: the caller finds the failure in the stats
                // and reports it instead of writing a black picture.
                return RenderOutput {
                    film: ctx.new_film(),
                    seconds: start.elapsed().as_secs_f64(),
                    rays: 0,
                    spp_done: 0,
                    interrupted: false,
                    state: None,
                    stats: Stats::new(RadiosityFailure(e.to_string())),
                    blocks: Vec::new(),
                };
            }
        };
        let scene = solved.scene(&self.scene);
        let solution = &solved.solution;
        let display = solution.display_radiosity(&scene.patches);
        let shading = Shading::new(
            scene,
            &ctx.world,
            &display,
            &solution.irradiance,
            settings.final_gather,
        )
        .with_specular_depth(settings.max_depth);
        control.progress.done.store(0, Ordering::Relaxed);
        let mut out = render_passes(ctx, &shading, control);
        out.seconds = start.elapsed().as_secs_f64();
        out.stats = Stats::new(RadiosityStats {
            patches: scene.patches.len(),
            escape: EscapeContext::of(settings, &ctx.world.lights),
            iterations: solution.iterations,
            converged: solution.converged,
            solve_seconds: solution.seconds,
            balance: solution.balance,
        });
        out
    }
}

/// The report of a radiosity render whose solve failed (diverged): the reason.
#[derive(Clone, Debug)]
pub struct RadiosityFailure(pub String);

impl std::fmt::Display for RadiosityFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Shadow-ray visibility for the solve, as chosen by the settings.
pub fn scene_visibility<'a>(
    scene: &RadiosityScene,
    world: &'a World,
    settings: &RadiositySettings,
) -> SceneVisibility<'a> {
    match settings.visibility {
        VisibilitySource::Patches => SceneVisibility::Faces(Box::new(FaceVisibility::new(scene))),
        VisibilitySource::World => {
            SceneVisibility::World(WorldVisibility::new(world, &scene.patches))
        }
    }
}

/// Solves the session's radiosity scene (refining it as the settings ask), reporting
/// progress in thousandths of the way to convergence on `progress` and stopping on its
/// cancel flag.
pub fn solve_session(
    world: &World,
    scene: &RadiosityScene,
    settings: &RadiositySettings,
    progress: &Progress,
) -> AdaptiveSolution {
    solve_session_observed(world, scene, settings, progress, |_| {})
        // Settings were validated when the session was built (hemi-cube resolution) and
        // the patch set and its solver inputs come from one scene; what remains is a
        // solve that diverged, which callers that cannot report errors must not show.
        .unwrap_or_else(|e| panic!("{e}"))
}

/// [`solve_session`], showing every solver event to `observe` as well (the CLI writes
/// the progressive sequence from it).
pub fn solve_session_observed(
    world: &World,
    scene: &RadiosityScene,
    settings: &RadiositySettings,
    progress: &Progress,
    observe: impl FnMut(&SolveEvent<'_>),
) -> Result<AdaptiveSolution, RadiosityError> {
    solve_session_resumed(world, scene, settings, progress, None, observe)
}

/// [`solve_session_observed`] continuing from a saved progressive state (see
/// [`solve_adaptive_from`]). The cancel flag is read before `observe` sees an event,
/// so an observer that finds it set has seen the state the solve stops in.
pub fn solve_session_resumed(
    world: &World,
    scene: &RadiosityScene,
    settings: &RadiositySettings,
    progress: &Progress,
    resume: Option<&ProgressiveState>,
    mut observe: impl FnMut(&SolveEvent<'_>),
) -> Result<AdaptiveSolution, RadiosityError> {
    progress.total.store(1000, Ordering::Relaxed);
    progress.done.store(0, Ordering::Relaxed);
    let sphere = world.scene_sphere();
    solve_adaptive_from(
        scene,
        &world.lights,
        sphere,
        settings,
        |mesh| scene_visibility(mesh, world, settings),
        resume,
        |event| {
            let done = match event {
                SolveEvent::Shot { fraction_done, .. } => Some((1000.0 * fraction_done) as u64),
                SolveEvent::Factors { done, total } => Some((900 * done / total.max(1)) as u64),
                SolveEvent::Sweep { .. } => Some(900),
                // Within a shot: the bar stays where the last shot left it.
                SolveEvent::ShotFactors { .. } => None,
            };
            if let Some(done) = done {
                progress.done.store(done, Ordering::Relaxed);
            }
            let stop = progress.cancelled();
            observe(&event);
            if stop {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    )
}
