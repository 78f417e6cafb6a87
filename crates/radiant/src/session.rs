//! A render session: a scene prepared for rendering — its render context and the
//! integrator it names (or the command line names).

use radiant_image::Film;
use radiant_render::integrator::{CheckpointHook, IntegratorState, PassWatch};
use radiant_render::{Integrator, Overrides, Progress, RenderContext, RenderControl, RenderOutput};
use radiant_scene::{SceneDesc, SceneError, Warning};

use crate::checkpoint::{CheckpointError, RunKey, scene_hash, settings_hash};
use crate::integrators::integrator_from_desc;

pub struct Session {
    pub ctx: RenderContext,
    pub integrator: Box<dyn Integrator>,
    /// Name and parameter hash of the integrator's description in effect (the
    /// scene's, with an override's name), for checkpoints.
    integrator_key: (String, u64),
    /// Warnings from preparing the session (the parser's are in the scene).
    pub warnings: Vec<Warning>,
}

impl Session {
    pub fn new(desc: &SceneDesc, overrides: &Overrides) -> Result<Session, SceneError> {
        // The context first: the world reads the integrator's light-sampler parameter,
        // which must count as used when the integrator's parameters are checked.
        let (ctx, mut warnings) = RenderContext::new(desc, overrides)?;
        let mut integrator_desc = desc.integrator.clone();
        if let Some(name) = &overrides.integrator {
            integrator_desc.name = name.clone();
        }
        let (integrator, w) = integrator_from_desc(desc, &integrator_desc)?;
        warnings.extend(w);
        Ok(Session {
            ctx,
            integrator,
            integrator_key: (
                integrator_desc.name.clone(),
                settings_hash(&integrator_desc),
            ),
            warnings,
        })
    }

    /// What identifies this render in a checkpoint (`desc` is the scene it was made
    /// from).
    pub fn run_key(&self, desc: &SceneDesc) -> RunKey {
        RunKey {
            scene: scene_hash(desc),
            integrator: self.integrator_key.0.clone(),
            settings: self.integrator_key.1,
            seed: self.ctx.seed,
            spp: self.ctx.spp,
            resolution: self.ctx.resolution,
            adaptive: self.ctx.adaptive,
        }
    }

    /// The integrator as its concrete type, when it is one (`session.integrator_as::<
    /// RadiosityIntegrator>()` reads the meshed scene).
    pub fn integrator_as<T: Integrator>(&self) -> Option<&T> {
        let any: &dyn std::any::Any = self.integrator.as_ref();
        any.downcast_ref()
    }

    /// Renders the image. Rayon's current thread pool sets the parallelism.
    pub fn render(&self, progress: &Progress) -> RenderOutput {
        self.render_with_snapshots(progress, &mut |_, _| {})
    }

    /// Renders the image, calling `snapshot(n, film)` each time the samples per pixel
    /// completed (SPPM: iterations) reach a power of two n.
    pub fn render_with_snapshots(
        &self,
        progress: &Progress,
        snapshot: &mut dyn FnMut(u32, &Film),
    ) -> RenderOutput {
        self.integrator
            .render(&self.ctx, &mut RenderControl::new(progress, snapshot))
    }

    /// Renders the image from `resume` (a state of this session's integrator, checked
    /// against the run by the caller with [`RunKey::check`]), calling `checkpoint` at
    /// every pass boundary; an interrupted render returns its state to save.
    pub fn render_resumable<'a>(
        &self,
        progress: &'a Progress,
        snapshot: &'a mut dyn FnMut(u32, &Film),
        resume: Option<IntegratorState>,
        checkpoint: Option<&'a mut CheckpointHook<'a>>,
    ) -> Result<RenderOutput, CheckpointError> {
        self.render_watched(progress, snapshot, resume, checkpoint, None)
    }

    /// [`Session::render_resumable`], with `pass` seeing the film after every pass
    /// (SPPM: iteration) and the samples per pixel done.
    pub fn render_watched<'a>(
        &self,
        progress: &'a Progress,
        snapshot: &'a mut dyn FnMut(u32, &Film),
        resume: Option<IntegratorState>,
        checkpoint: Option<&'a mut CheckpointHook<'a>>,
        pass: Option<&'a mut PassWatch<'a>>,
    ) -> Result<RenderOutput, CheckpointError> {
        if let Some(state) = &resume {
            let wanted = self.integrator.state_kind();
            if state.kind() != wanted {
                return Err(CheckpointError::Kind {
                    found: state.kind().name(),
                    wanted: wanted.name(),
                });
            }
            if state.resolution() != self.ctx.film_size() {
                return Err(CheckpointError::Payload(format!(
                    "a {}x{} image for a {}x{} render",
                    state.resolution().0,
                    state.resolution().1,
                    self.ctx.film_size().0,
                    self.ctx.film_size().1
                )));
            }
        }
        let mut control = RenderControl::new(progress, snapshot);
        control.resume = resume;
        control.checkpoint = checkpoint;
        control.pass = pass;
        Ok(self.integrator.render(&self.ctx, &mut control))
    }
}
