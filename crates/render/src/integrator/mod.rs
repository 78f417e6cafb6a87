//! Integrators: the path tracer (reference) and the photon mappers, behind one
//! [`Integrator`] interface that radiosity implements too, from its own crate.
//!
//! Every integrator renders from a [`RenderContext`] into a [`Film`] made by the
//! context, so the sensor, the non-finite sample accounting, snapshots and partial
//! images on cancellation work the same way for all of them. The path tracer, the
//! photon mapper's eye pass and the radiosity display are per-pixel estimators driven
//! by one pass loop ([`passes`]); SPPM runs its own iterations and writes its
//! estimates into the film.

pub mod adaptive;
pub mod direct;
pub mod footprint;
pub mod passes;
pub mod path;
pub mod photon;
pub mod specular;
pub mod sppm;
pub mod state;

use std::any::Any;
use std::fmt;

pub use passes::{PixelEstimator, PixelId, fold, render_passes};
pub use path::{PathIntegrator, PathSettings};
pub use photon::{PhotonMapIntegrator, PhotonMapStats, PhotonSettings, Visualize};
pub use sppm::{SppmIntegrator, SppmSettings, SppmStats};
pub use state::{
    AdaptivePlan, CheckpointHook, IntegratorState, PhotonEstimate, SppmPixel, StateKind,
};

use crate::context::{Progress, RenderContext};
use radiant_image::Film;

/// A rendering method (pbrt-v4's `Integrator::Render`). `Any` lets code that knows the
/// concrete integrator (tests, the radiosity command) look at it.
pub trait Integrator: Any + Send + Sync {
    /// The name it is chosen by (`Integrator "name"`, `--integrator name`).
    fn name(&self) -> &'static str;

    /// Renders `ctx.spp` samples per pixel (SPPM: iterations) into a film made by
    /// `ctx.new_film()`. Stops early when `control.progress` is cancelled, and then
    /// returns the film as far as it got (`interrupted`, with the samples every pixel
    /// actually received).
    fn render(&self, ctx: &RenderContext, control: &mut RenderControl<'_>) -> RenderOutput;

    /// The kind of state it saves at checkpoints and resumes from
    /// ([`RenderControl::resume`]).
    fn state_kind(&self) -> StateKind {
        StateKind::Film
    }

    /// Renders to the end, unobserved.
    fn render_unobserved(&self, ctx: &RenderContext) -> RenderOutput {
        let progress = Progress::default();
        self.render(ctx, &mut RenderControl::new(&progress, &mut |_, _| {}))
    }
}

/// Sees the film after a pass with the samples per pixel done ([`RenderControl::pass`]).
pub type PassWatch<'a> = dyn FnMut(u32, &Film) + 'a;

/// What a running render reports to, and is stopped by.
pub struct RenderControl<'a> {
    pub progress: &'a Progress,
    /// Called with the film each time the samples per pixel (SPPM: iterations)
    /// completed in every pixel reach a power of two.
    pub snapshot: &'a mut dyn FnMut(u32, &Film),
    /// A state to continue from (of the integrator's [`Integrator::state_kind`]; the
    /// caller checks it belongs to the same scene and settings).
    pub resume: Option<IntegratorState>,
    /// Sees every pass boundary; when set, the render also returns its final state
    /// ([`RenderOutput::state`]), finished or interrupted.
    pub checkpoint: Option<&'a mut CheckpointHook<'a>>,
    /// Sees the film after every pass (SPPM: iteration) with the samples per pixel
    /// done: live views, partial images, error curves.
    pub pass: Option<&'a mut PassWatch<'a>>,
}

impl<'a> RenderControl<'a> {
    pub fn new(progress: &'a Progress, snapshot: &'a mut dyn FnMut(u32, &Film)) -> Self {
        RenderControl {
            progress,
            snapshot,
            resume: None,
            checkpoint: None,
            pass: None,
        }
    }

    /// True when someone watches every pass (the film must then be made each time).
    pub fn watches_passes(&self) -> bool {
        self.pass.is_some()
    }

    /// Shows the film after a pass with `done` samples per pixel to the pass watcher.
    pub fn after_pass(&mut self, done: u32, film: &Film) {
        if let Some(watch) = self.pass.as_mut() {
            watch(done, film);
        }
    }

    /// Calls the checkpoint hook, if any, at a boundary with `done` samples per pixel.
    pub fn boundary(&mut self, done: u32, state: &dyn Fn() -> IntegratorState) {
        if let Some(hook) = self.checkpoint.as_mut()
            && hook(done, state).is_break()
        {
            self.progress
                .cancel
                .store(true, std::sync::atomic::Ordering::SeqCst);
        }
    }

    /// The state to return with an output, when checkpoints are asked for.
    pub fn final_state(&self, state: impl FnOnce() -> IntegratorState) -> Option<IntegratorState> {
        self.checkpoint.is_some().then(state)
    }
}

/// A finished (or interrupted) render.
pub struct RenderOutput {
    pub film: Film,
    pub seconds: f64,
    pub rays: u64,
    /// Samples per pixel (SPPM: iterations) completed in every pixel.
    pub spp_done: u32,
    pub interrupted: bool,
    /// The state to resume from (or to save as the finished render's), when
    /// checkpoints were asked for ([`RenderControl::checkpoint`]).
    pub state: Option<IntegratorState>,
    /// What the integrator reports beyond the image (photon counts, radii, timings).
    pub stats: Stats,
    /// For a sample range that starts past sample 0 ([`crate::WorkUnit`]): the film of
    /// each sample block it covers, in order (`film` is their sum). Empty otherwise.
    pub blocks: Vec<Film>,
}

/// An integrator's report: printable, and readable as its own type by those who know it.
pub trait IntegratorReport: fmt::Display + fmt::Debug + Any + Send + Sync {}

impl<T: fmt::Display + fmt::Debug + Any + Send + Sync> IntegratorReport for T {}

/// The report of a render, if its integrator makes one.
#[derive(Debug, Default)]
pub struct Stats(Option<Box<dyn IntegratorReport>>);

impl Stats {
    pub fn new(report: impl IntegratorReport) -> Stats {
        Stats(Some(Box::new(report)))
    }

    /// The report as the integrator's own type (`out.stats.get::<SppmStats>()`).
    pub fn get<T: Any>(&self) -> Option<&T> {
        let report: &dyn Any = self.0.as_deref()?;
        report.downcast_ref()
    }
}

impl fmt::Display for Stats {
    /// Info lines for the command line (empty for integrators without a report).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            Some(report) => report.fmt(f),
            None => Ok(()),
        }
    }
}
