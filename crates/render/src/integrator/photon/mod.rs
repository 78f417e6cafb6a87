//! Two-pass photon mapping (Jensen, "Global Illumination using Photon Maps", EGWR 1996;
//! *Realistic Image Synthesis Using Photon Mapping*, 2001).
//!
//! Pass 1 traces photons from the lights and stores them where they land on diffuse
//! surfaces, in two maps:
//! - the **caustic map**: photons whose path from the light was purely specular
//!   (L S+ D), emitted separately and aimed at specular objects by projection maps;
//! - the **global map**: every later diffuse hit (L (S|D)* D D) — the first diffuse
//!   hit is left out because camera paths compute direct light by next-event
//!   estimation and caustics from the caustic map.
//!
//! Pass 2 follows camera rays through specular chains to the first diffuse point x and
//! adds: emission seen along the chain; direct light by next-event estimation; caustics
//! by a radiance estimate from the caustic map; indirect diffuse light by final
//! gathering — rays sampled from the BSDF at x, whose first diffuse hit y reads the
//! light leaving y (direct by next-event estimation, the rest from precomputed
//! irradiance, Christensen 1999). The four parts split the light transport paths
//! without overlap: a gather ray that reaches an emitter (directly or through
//! specular surfaces) adds nothing, since next-event estimation and the caustic map
//! already count those paths.
//!
//! `visualize` modes show the maps themselves instead (see [`Visualize`]).

pub mod bench;
pub mod estimate;
pub mod eye;
mod integrator;
pub mod irradiance;
pub mod kdtree;
pub mod projection;
pub mod record;
pub mod settings;
pub mod trace;

use std::fmt;
use std::time::Instant;

use glam::Vec3;

pub use estimate::{EstimatePoint, PhotonMap, PhotonSearch};
pub use integrator::PhotonMapIntegrator;
pub use irradiance::IrradianceCache;
pub use kdtree::{KdPoint, KdTree, Neighbors};
pub use projection::ProjectionMaps;
pub use record::{CAUSTIC, FIRST_DIFFUSE, FROM_SPECULAR, Photon, RawPhoton};
pub use settings::{Kernel, PhotonSettings, Visualize};

use crate::Progress;
use crate::world::World;
use radiant_scene::SamplerKind;
use trace::{Landing, PhotonPass, PhotonStream};

/// Stream tags of the two photon passes.
const GLOBAL_PASS: u64 = 0x0091_06a1;
const CAUSTIC_PASS: u64 = 0x0ca0_571c;

/// What building the photon maps did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhotonMapStats {
    pub global_emitted: u64,
    pub global_stored: u64,
    pub caustic_emitted: u64,
    pub caustic_stored: u64,
    /// Share of the lights' power the projection maps aim at specular objects (None
    /// without projection maps or specular objects).
    pub projection_fraction: Option<f32>,
    pub irradiance_points: u64,
    /// Largest search radius (scene units).
    pub max_radius: f32,
    /// Rays traced by the photon passes.
    pub rays: u64,
    pub trace_seconds: f64,
    /// kd-tree builds (both maps).
    pub build_seconds: f64,
    /// Irradiance precomputation for final gathering.
    pub precompute_seconds: f64,
}

impl fmt::Display for PhotonMapStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "photon map: global {} emitted, {} stored; caustic {} emitted, {} stored{}",
            self.global_emitted,
            self.global_stored,
            self.caustic_emitted,
            self.caustic_stored,
            match self.projection_fraction {
                Some(p) => format!(" (projection maps aim {:.2} % of the power)", 100.0 * p),
                None => String::new(),
            }
        )?;
        write!(
            f,
            "photon map: max radius {:.4}, {} irradiance points; trace {:.3} s ({:.2} M photons/s), kd-trees {:.3} s, irradiance {:.3} s",
            self.max_radius,
            self.irradiance_points,
            self.trace_seconds,
            (self.global_emitted + self.caustic_emitted) as f64
                / self.trace_seconds.max(1e-9)
                / 1e6,
            self.build_seconds,
            self.precompute_seconds
        )
    }
}

/// The photon maps of a scene, ready for camera paths.
pub struct PhotonMaps {
    pub settings: PhotonSettings,
    pub global: PhotonMap,
    pub caustic: PhotonMap,
    /// Precomputed irradiance (when final gathering is on).
    pub irradiance: Option<IrradianceCache>,
    pub max_r2: f32,
    pub stats: PhotonMapStats,
}

impl PhotonMaps {
    /// The search of this render's estimates: every photon within the maximum radius,
    /// weighted by the settings' kernel.
    pub fn search(&self) -> PhotonSearch {
        PhotonSearch {
            max_r2: self.max_r2,
            kernel: self.settings.kernel,
            skip_flags: 0,
        }
    }

    /// Traces both photon passes and builds the maps. Deterministic for a given seed at
    /// any thread count. Stops early when `progress` is cancelled, and then leaves the maps
    /// empty: nothing is rendered from them.
    pub fn build(
        world: &World,
        settings: &PhotonSettings,
        kind: SamplerKind,
        seed: u64,
        progress: &Progress,
    ) -> PhotonMaps {
        let visualize = settings.visualize != Visualize::None;
        let max_radius = settings
            .max_radius
            .unwrap_or_else(|| 0.05 * world.scene_sphere().radius);
        let mut stats = PhotonMapStats {
            max_radius,
            ..Default::default()
        };
        let t0 = Instant::now();

        // Global pass: all paths; store indirect hits (everything when visualizing).
        let n_global = settings.photons as u64;
        let (global_raw, global_rays) = PhotonPass {
            world,
            stream: PhotonStream::new(kind, seed, &[GLOBAL_PASS]),
            photons: n_global,
            emitted_of: n_global as f64,
            projection: None,
            max_depth: settings.max_depth,
        }
        .trace(
            || progress.cancelled(),
            |l, out| {
                if visualize || !l.specular_chain {
                    out.push(raw_photon(l));
                }
                true
            },
        );

        // Caustic pass: paths stop at the first diffuse hit; only L S+ D is kept.
        let specular = !world.specular_bounds().is_empty();
        let projection = if specular && settings.projection_maps {
            ProjectionMaps::build(world)
        } else {
            None
        };
        let n_caustic = if specular {
            settings.caustic_photons as u64
        } else {
            0
        };
        let (caustic_raw, caustic_rays) = PhotonPass {
            world,
            stream: PhotonStream::new(kind, seed, &[CAUSTIC_PASS]),
            photons: n_caustic,
            emitted_of: n_caustic as f64,
            projection: projection.as_ref(),
            max_depth: settings.max_depth,
        }
        .trace(
            || progress.cancelled(),
            |l, out| {
                if l.specular_chain && l.bounces > 0 {
                    out.push(raw_photon(l));
                }
                false
            },
        );
        stats.trace_seconds = t0.elapsed().as_secs_f64();
        stats.global_emitted = n_global;
        stats.caustic_emitted = n_caustic;
        stats.projection_fraction = projection.as_ref().map(|p| p.covered_power_fraction);
        stats.rays = global_rays + caustic_rays;

        // Once stopped, nothing will be rendered from the maps: the trees and the
        // irradiance cache (tens of seconds at 10^8 photons) ask the flag as they go and
        // give up, leaving the maps empty.
        let stop = || progress.cancelled();
        let t1 = Instant::now();
        let global = PhotonMap::build_until(global_raw, &stop);
        let caustic = match global {
            Some(_) => PhotonMap::build_until(caustic_raw, &stop),
            None => {
                kdtree::release(caustic_raw);
                None
            }
        };
        let (global, caustic) = match (global, caustic) {
            (Some(g), Some(c)) => (g, c),
            (g, _) => {
                if let Some(g) = g {
                    g.discard();
                }
                Default::default()
            }
        };
        stats.build_seconds = t1.elapsed().as_secs_f64();
        stats.global_stored = global.len() as u64;
        stats.caustic_stored = caustic.len() as u64;

        let max_r2 = max_radius * max_radius;
        let t2 = Instant::now();
        let irradiance = if !visualize && settings.final_gather_samples > 0 && !stop() {
            IrradianceCache::build_until(
                &global,
                &caustic,
                settings.global_lookup,
                settings.lookup,
                max_r2,
                settings.kernel,
                &stop,
            )
        } else {
            None
        };
        stats.precompute_seconds = t2.elapsed().as_secs_f64();
        if stop() {
            // Stopped during (or just after) the irradiance cache: the gigabytes of a
            // large map go back off the caller's thread, which has an image to write.
            global.discard();
            caustic.discard();
            return PhotonMaps {
                settings: *settings,
                global: Default::default(),
                caustic: Default::default(),
                irradiance: None,
                max_r2,
                stats,
            };
        }
        stats.irradiance_points = irradiance.as_ref().map_or(0, |c| c.len() as u64);
        PhotonMaps {
            settings: *settings,
            global,
            caustic,
            irradiance,
            max_r2,
            stats,
        }
    }
}

fn raw_photon(l: &Landing) -> RawPhoton {
    let n = if l.hit.ng.dot(l.wi) >= 0.0 {
        l.hit.ng
    } else {
        -l.hit.ng
    };
    let mut flags = 0;
    if l.specular_chain {
        flags |= FIRST_DIFFUSE;
        if l.bounces > 0 {
            flags |= CAUSTIC;
        }
    }
    if l.first_specular {
        flags |= FROM_SPECULAR;
    }
    RawPhoton {
        p: l.hit.p,
        power: l.power,
        wi: l.wi,
        n,
        bounces: l.bounces.min(255) as u8,
        flags,
    }
}

/// Unit normal `n` turned to the side of `w`.
pub(crate) fn facing(n: Vec3, w: Vec3) -> Vec3 {
    if n.dot(w) >= 0.0 { n } else { -n }
}
