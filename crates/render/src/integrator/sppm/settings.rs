//! `Integrator "sppm"` parameters (pbrt-v4's names), documented where they are read.

use radiant_scene::{IntegratorDesc, SceneError};

/// Settings of stochastic progressive photon mapping. The number of iterations is the
/// sampler's `pixelsamples` (as in pbrt-v4).
///
/// The defaults were checked by time to error on cornell-caustics (docs/speed.md): a
/// smaller radius with more photons reaches a caustic's error sooner, a larger one the
/// diffuse interreflection's; none of the settings tried wins both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppmSettings {
    /// `"float radius"` (scene units): the initial gather radius of every pixel.
    /// Default: two pixel footprints at the distance of the scene's centre (printed
    /// and returned in the statistics).
    pub radius: Option<f32>,
    /// `"integer photonsperiteration" [-1]`: photons traced per iteration; -1 (or
    /// absent) means the number of pixels.
    pub photons_per_iteration: Option<u32>,
    /// `"integer maxdepth" [5]`: the most scattering events of a photon path, and of a
    /// camera path's specular chain.
    pub max_depth: u32,
    /// `"integer seed"` (default: the sampler's seed).
    pub seed: Option<u64>,
    /// `"float alpha" [0.666667]`: the share of new photons kept per iteration
    /// (Hachisuka et al. 2008); in (0, 1).
    pub alpha: f32,
}

impl Default for SppmSettings {
    fn default() -> Self {
        SppmSettings {
            radius: None,
            photons_per_iteration: None,
            max_depth: 5,
            seed: None,
            alpha: 2.0 / 3.0,
        }
    }
}

impl SppmSettings {
    /// ```text
    /// Integrator "sppm" "float radius" [5] "integer photonsperiteration" [65536]
    ///     "integer maxdepth" [5] "integer seed" [0] "float alpha" [0.666667]
    /// Sampler "sobol" "integer pixelsamples" [256]   # = iterations
    /// ```
    pub fn from_desc(desc: &IntegratorDesc) -> Result<SppmSettings, SceneError> {
        let p = &desc.params;
        let d = SppmSettings::default();
        let radius = if p.has("radius") {
            let r = p.finite_float("radius", 1.0)?;
            if r <= 0.0 {
                return Err(SceneError::at(
                    &desc.loc,
                    format!("\"radius\" must be positive, got {r}"),
                ));
            }
            Some(r)
        } else {
            None
        };
        let photons = p.int("photonsperiteration", -1)?;
        let photons_per_iteration = match photons {
            -1 => None,
            n if n > 0 => Some(n as u32),
            n => {
                return Err(SceneError::at(
                    &desc.loc,
                    format!("\"photonsperiteration\" must be positive or -1, got {n}"),
                ));
            }
        };
        let alpha = p.finite_float("alpha", d.alpha)?;
        if !(alpha > 0.0 && alpha < 1.0) {
            return Err(SceneError::at(
                &desc.loc,
                format!("\"alpha\" must lie in (0, 1), got {alpha}"),
            ));
        }
        let seed = if p.has("seed") {
            Some(p.count("seed", 0)? as u64)
        } else {
            None
        };
        Ok(SppmSettings {
            radius,
            photons_per_iteration,
            max_depth: p.count("maxdepth", d.max_depth)?,
            seed,
            alpha,
        })
    }
}
