//! Integrators: the path tracer (reference), and the photon mappers and radiosity
//! built on the same world. `Integrator` is chosen by name from the scene (or the
//! command line) and reads its own parameters.

pub mod direct;
pub mod footprint;
pub mod path;
pub mod photon;
pub mod specular;
pub mod sppm;

pub use path::PathSettings;
pub use photon::{PhotonMapStats, PhotonSettings, Visualize};
pub use sppm::{SppmSettings, SppmStats};

use crate::radiosity::settings::RadiositySettings;
use crate::radiosity::solve::RadiosityStats;
use crate::scene::{IntegratorDesc, SceneError, Warning};

/// The integrators radiant implements, with their settings.
#[derive(Clone, Debug, PartialEq)]
pub enum Integrator {
    Path(PathSettings),
    /// Two-pass photon mapping with final gathering (`photonmap`; `photonviz` is the
    /// same with `visualize "density"` by default).
    PhotonMap(PhotonSettings),
    /// Stochastic progressive photon mapping.
    Sppm(SppmSettings),
    /// Finite-element diffuse transport on a patch mesh (`crate::radiosity`).
    Radiosity(RadiositySettings),
}

/// What an integrator reports beyond the image (photon counts, radii, timings).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum IntegratorStats {
    #[default]
    None,
    PhotonMap(PhotonMapStats),
    Sppm(SppmStats),
    Radiosity(RadiosityStats),
}

impl std::fmt::Display for IntegratorStats {
    /// Info lines for the command line (empty for integrators without statistics).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IntegratorStats::None => Ok(()),
            IntegratorStats::PhotonMap(s) => s.fmt(f),
            IntegratorStats::Sppm(s) => s.fmt(f),
            IntegratorStats::Radiosity(s) => s.fmt(f),
        }
    }
}

/// Names accepted by `Integrator` and `--integrator`.
pub const INTEGRATOR_NAMES: [&str; 5] = ["path", "photonmap", "photonviz", "sppm", "radiosity"];

impl Integrator {
    /// Chooses the integrator from a scene's `Integrator` directive. Names radiant does
    /// not implement fall back to the path tracer with a warning; unused parameters are
    /// reported as warnings.
    pub fn from_desc(desc: &IntegratorDesc) -> Result<(Integrator, Vec<Warning>), SceneError> {
        let mut warnings = Vec::new();
        let integrator = match desc.name.as_str() {
            "path" => Integrator::Path(PathSettings::from_desc(desc)?),
            "photonmap" => Integrator::PhotonMap(PhotonSettings::from_desc(desc, Visualize::None)?),
            "photonviz" => {
                Integrator::PhotonMap(PhotonSettings::from_desc(desc, Visualize::Density)?)
            }
            "sppm" => Integrator::Sppm(SppmSettings::from_desc(desc)?),
            "radiosity" => Integrator::Radiosity(RadiositySettings::from_desc(desc)?),
            "volpath" => {
                warnings.push(Warning {
                    loc: desc.loc.clone(),
                    message: "integrator \"volpath\": participating media are not supported; using \"path\"".into(),
                });
                Integrator::Path(PathSettings::from_desc(desc)?)
            }
            other => {
                warnings.push(Warning {
                    loc: desc.loc.clone(),
                    message: format!(
                        "integrator \"{other}\" is not supported (radiant has: {}); using \"path\"",
                        INTEGRATOR_NAMES.join(", ")
                    ),
                });
                // Read what the path tracer shares (maxdepth) so it is not reported unused.
                Integrator::Path(PathSettings::from_desc(desc)?)
            }
        };
        let owner = format!("Integrator \"{}\"", desc.name);
        warnings.extend(desc.params.unused_warnings(&owner));
        Ok((integrator, warnings))
    }

    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Path(_) => "path",
            Integrator::PhotonMap(s) if s.visualize != Visualize::None => "photonviz",
            Integrator::PhotonMap(_) => "photonmap",
            Integrator::Sppm(_) => "sppm",
            Integrator::Radiosity(_) => "radiosity",
        }
    }
}
