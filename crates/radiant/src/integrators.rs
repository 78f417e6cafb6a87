//! The integrators by name: the one table from `Integrator "name"` (or
//! `--integrator name`) to an implementation, above the render and radiosity layers.

use radiant_radiosity::RadiosityIntegrator;
use radiant_radiosity::settings::RadiositySettings;
use radiant_render::Integrator;
use radiant_render::integrator::{
    PathIntegrator, PathSettings, PhotonMapIntegrator, PhotonSettings, SppmIntegrator,
    SppmSettings, Visualize,
};
use radiant_scene::{IntegratorDesc, SceneDesc, SceneError, Warning};

/// Names accepted by `Integrator` and `--integrator`.
pub const INTEGRATOR_NAMES: [&str; 5] = ["path", "photonmap", "photonviz", "sppm", "radiosity"];

/// Chooses the integrator named by `desc` (usually `scene.integrator`, with a name
/// given on the command line put in). Names radiant does not implement fall back to
/// the path tracer with a warning; unused parameters are reported as warnings.
/// Radiosity meshes `scene` here.
pub fn integrator_from_desc(
    scene: &SceneDesc,
    desc: &IntegratorDesc,
) -> Result<(Box<dyn Integrator>, Vec<Warning>), SceneError> {
    let mut warnings = Vec::new();
    let path = |desc: &IntegratorDesc| -> Result<Box<dyn Integrator>, SceneError> {
        Ok(Box::new(PathIntegrator {
            settings: PathSettings::from_desc(desc)?,
        }))
    };
    let integrator: Box<dyn Integrator> = match desc.name.as_str() {
        "path" => path(desc)?,
        "photonmap" => Box::new(PhotonMapIntegrator {
            settings: PhotonSettings::from_desc(desc, Visualize::None)?,
        }),
        "photonviz" => Box::new(PhotonMapIntegrator {
            settings: PhotonSettings::from_desc(desc, Visualize::Density)?,
        }),
        "sppm" => Box::new(SppmIntegrator {
            settings: SppmSettings::from_desc(desc)?,
        }),
        "radiosity" => {
            let (radiosity, w) =
                RadiosityIntegrator::new(scene, RadiositySettings::for_scene(desc, scene)?)?;
            warnings.extend(w);
            Box::new(radiosity)
        }
        "volpath" => {
            warnings.push(Warning {
                loc: desc.loc.clone(),
                message:
                    "integrator \"volpath\": participating media are not supported; using \"path\""
                        .into(),
            });
            path(desc)?
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
            path(desc)?
        }
    };
    let owner = format!("Integrator \"{}\"", desc.name);
    warnings.extend(desc.params.unused_warnings(&owner));
    Ok((integrator, warnings))
}
