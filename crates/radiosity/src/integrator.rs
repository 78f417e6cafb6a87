//! Radiosity as an integrator: mesh the scene when it is chosen, solve when asked to
//! render, then show the solution through the shared pass loop.

use std::sync::atomic::Ordering;
use std::time::Instant;

use crate::mesh::meshed_scene::RadiosityScene;
use crate::output::shading::{Shading, solve_session};
use crate::settings::RadiositySettings;
use crate::solve::RadiosityStats;
use radiant_render::RenderContext;
use radiant_render::integrator::{Integrator, RenderControl, RenderOutput, Stats, render_passes};
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
        let solved = solve_session(&ctx.world, &self.scene, settings, control.progress);
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
            iterations: solution.iterations,
            converged: solution.converged,
            solve_seconds: solution.seconds,
            balance: solution.balance,
        });
        out
    }
}
