//! A render session: a scene prepared for rendering — its render context and the
//! integrator it names (or the command line names).

use radiant_image::Film;
use radiant_render::{Integrator, Overrides, Progress, RenderContext, RenderControl, RenderOutput};
use radiant_scene::{SceneDesc, SceneError, Warning};

use crate::integrators::integrator_from_desc;

pub struct Session {
    pub ctx: RenderContext,
    pub integrator: Box<dyn Integrator>,
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
            warnings,
        })
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
}
