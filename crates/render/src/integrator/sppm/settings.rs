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
    /// `"float radius"` (scene units): the initial gather radius of every pixel's
    /// global estimate (photons that scattered off a non-specular surface first).
    /// Default: [`super::GLOBAL_RADIUS_PIXELS`] pixel footprints at the distance of the
    /// scene's centre (printed and returned in the statistics).
    pub radius: Option<f32>,
    /// `"integer photonsperiteration" [-1]`: photons traced per iteration for the
    /// global estimate; -1 (or absent) means the number of pixels.
    pub photons_per_iteration: Option<u32>,
    /// `"float causticradius"` (scene units): the initial radius of the caustic
    /// estimate (photons that reached the surface through specular surfaces only).
    /// Default: `radius` where that is given, else [`super::CAUSTIC_RADIUS_PIXELS`]
    /// pixel footprints.
    pub caustic_radius: Option<f32>,
    /// `"integer causticphotonsperiteration" [-1]`: photons aimed at specular objects
    /// by projection maps per iteration, for the caustic estimate; -1 means
    /// [`super::CAUSTIC_PHOTONS_PER_PHOTON`] times `photonsperiteration`; 0 turns the separate estimate off, and the global photons
    /// then carry caustics too (the single estimate of Hachisuka & Jensen 2009).
    pub caustic_photons_per_iteration: Option<u32>,
    /// `"integer sharpdirectsamples" [4]`: camera samples per iteration for the direct
    /// light of pixels that see a mirror, glass or an emitter (`visible::
    /// sees_sharp_direct_light`); the visible point comes from the first. 1 takes one
    /// everywhere.
    pub sharp_direct_samples: u32,
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
            caustic_radius: None,
            caustic_photons_per_iteration: None,
            sharp_direct_samples: 4,
            max_depth: 5,
            seed: None,
            alpha: 2.0 / 3.0,
        }
    }
}

impl SppmSettings {
    /// ```text
    /// Integrator "sppm" "float radius" [5] "integer photonsperiteration" [65536]
    ///     "float causticradius" [2] "integer causticphotonsperiteration" [131072]
    ///     "integer sharpdirectsamples" [4]
    ///     "integer maxdepth" [5] "integer seed" [0] "float alpha" [0.666667]
    /// Sampler "sobol" "integer pixelsamples" [256]   # = iterations
    /// ```
    pub fn from_desc(desc: &IntegratorDesc) -> Result<SppmSettings, SceneError> {
        let p = &desc.params;
        let d = SppmSettings::default();
        let positive_radius = |name: &str| -> Result<Option<f32>, SceneError> {
            if !p.has(name) {
                return Ok(None);
            }
            let r = p.finite_float(name, 1.0)?;
            if r <= 0.0 {
                return Err(SceneError::at(
                    &desc.loc,
                    format!("\"{name}\" must be positive, got {r}"),
                ));
            }
            Ok(Some(r))
        };
        let radius = positive_radius("radius")?;
        let caustic_radius = positive_radius("causticradius")?;
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
        let caustic_photons = p.int("causticphotonsperiteration", -1)?;
        let caustic_photons_per_iteration = match caustic_photons {
            -1 => None,
            n if n >= 0 => Some(n as u32),
            n => {
                return Err(SceneError::at(
                    &desc.loc,
                    format!("\"causticphotonsperiteration\" must be at least -1, got {n}"),
                ));
            }
        };
        let sharp_direct_samples = p.count("sharpdirectsamples", d.sharp_direct_samples)?;
        if sharp_direct_samples == 0 {
            return Err(SceneError::at(
                &desc.loc,
                "\"sharpdirectsamples\" must be at least 1, got 0",
            ));
        }
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
            caustic_radius,
            caustic_photons_per_iteration,
            sharp_direct_samples,
            max_depth: p.count("maxdepth", d.max_depth)?,
            seed,
            alpha,
        })
    }
}
