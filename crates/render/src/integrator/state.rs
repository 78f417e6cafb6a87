//! What an integrator needs to continue a render where it stopped: the state a
//! checkpoint saves and a resumed render starts from.
//!
//! Every sample (SPPM: every iteration) is a pure function of the pixel, its index and
//! the seed, and each pixel sums its samples in index order. A render that starts from
//! a saved state and takes the remaining samples therefore adds the same numbers in
//! the same order as one done in one go: the images agree bit for bit, at any thread
//! count.

use std::ops::ControlFlow;

use radiant_image::Film;

/// One progressive photon estimate of a pixel (Hachisuka & Jensen 2009): f64 sums,
/// since thousands of iterations are accumulated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhotonEstimate {
    /// Accumulated flux τ (times f and the camera throughput), rescaled with the radius.
    pub tau: [f64; 3],
    /// Accumulated photon count N.
    pub n: f64,
    /// Squared gather radius R².
    pub r2: f64,
}

/// A pixel's SPPM statistics after some iterations: the direct light's sum and two
/// photon estimates, each with its own radius: `global` for photons that scattered
/// off a non-specular surface before arriving, `caustic` for those that came through
/// specular surfaces only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SppmPixel {
    /// Sum of direct light over the iterations.
    pub ld: [f64; 3],
    pub global: PhotonEstimate,
    pub caustic: PhotonEstimate,
}

/// Which kind of state an integrator saves and resumes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateKind {
    /// Film sums of the pass loop's per-pixel estimators.
    Film,
    /// SPPM's per-pixel statistics.
    Sppm,
}

impl StateKind {
    pub fn name(self) -> &'static str {
        match self {
            StateKind::Film => "film",
            StateKind::Sppm => "sppm",
        }
    }
}

/// A render's resumable state.
#[derive(Clone, Debug)]
pub enum IntegratorState {
    /// The film of a pass-loop integrator. Each pixel's sample count says where its
    /// samples continue, so a film stopped in the middle of a pass (some rows with
    /// more samples than others) resumes exactly too.
    Film(Film),
    /// The film of an adaptive render (with the second moments its pilot keeps) and its
    /// plan so far: during the pilot the rays each pixel traced, after it each pixel's
    /// target. The targets are chosen once, from the pilot alone, so a resumed render
    /// gives every pixel the samples the render done in one go gives it.
    AdaptiveFilm { film: Film, plan: AdaptivePlan },
    /// SPPM after `iterations` complete iterations: the photon stream of the next one
    /// is derived from its index, so these statistics are all it needs.
    Sppm {
        iterations: u32,
        width: u32,
        height: u32,
        pixels: Vec<SppmPixel>,
    },
}

impl IntegratorState {
    pub fn kind(&self) -> StateKind {
        match self {
            IntegratorState::Film(_) | IntegratorState::AdaptiveFilm { .. } => StateKind::Film,
            IntegratorState::Sppm { .. } => StateKind::Sppm,
        }
    }

    /// Samples per pixel (SPPM: iterations) complete in every pixel.
    pub fn done(&self) -> u32 {
        match self {
            IntegratorState::Film(film) | IntegratorState::AdaptiveFilm { film, .. } => {
                film.min_samples()
            }
            IntegratorState::Sppm { iterations, .. } => *iterations,
        }
    }

    pub fn resolution(&self) -> (u32, u32) {
        match self {
            IntegratorState::Film(film) | IntegratorState::AdaptiveFilm { film, .. } => {
                (film.width as u32, film.height as u32)
            }
            IntegratorState::Sppm { width, height, .. } => (*width, *height),
        }
    }
}

/// Where an adaptive render's allocation stands (see [`super::adaptive`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AdaptivePlan {
    /// Rays traced by each pixel's pilot samples so far, the cost side of the allocation.
    pub pilot_rays: Vec<u32>,
    /// Each pixel's sample count, once the pilot is done.
    pub targets: Option<Vec<u32>>,
}

/// Called at every pass (SPPM: iteration) boundary with the samples per pixel done and
/// a maker of the state there; it makes the state only when it saves it. `Break` asks
/// the render to stop as if cancelled.
pub type CheckpointHook<'a> = dyn FnMut(u32, &dyn Fn() -> IntegratorState) -> ControlFlow<()> + 'a;
