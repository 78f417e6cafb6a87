//! `Integrator "photonmap"` parameters, documented where they are read.

use radiant_scene::{IntegratorDesc, SceneError};

/// Density-estimation kernel of the radiance estimate. The classic Gaussian of
/// Jensen's book is not offered: with a support radius equal to the search radius its
/// normalisation under-estimates by almost half.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// Uniform disc: every photon counts fully. With a k-nearest radius the farthest
    /// photon (on the boundary) is left out, giving the (k−1)/(πr²) estimator that is
    /// unbiased for a uniform density.
    Disc,
    /// Jensen's cone filter with slope 1: weight 1 − d/r, normalised by 1 − 2/3.
    Cone,
    /// Epanechnikov: weight 1 − d²/r², normalised by 1/2.
    Epanechnikov,
}

/// What the photon mapper shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visualize {
    /// The full solution: direct light, caustics, final gathering.
    None,
    /// Dots where stored photons lie (both maps), coloured by their power.
    Photons,
    /// Radiance estimate from the caustic map only.
    Caustic,
    /// Radiance estimate from the global (indirect) map only.
    Global,
    /// Radiance estimate from every stored photon, direct ones included: the photon
    /// map read directly, without next-event estimation or final gathering.
    Density,
}

/// Settings of the two-pass photon mapper (Jensen 1996).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonSettings {
    /// `"integer photons" [200000]`: photons emitted for the global (indirect) map.
    pub photons: u32,
    /// `"integer causticphotons" [2000000]`: photons emitted for the caustic map (aimed
    /// at specular objects when `projectionmaps` is on). See [`PhotonSettings::default`]
    /// for how this, `lookup` and `finalgathersamples` were chosen.
    pub caustic_photons: u32,
    /// `"integer lookup" [50]`: photons in a caustic radiance estimate (k nearest).
    pub lookup: u32,
    /// `"integer globallookup" [200]`: photons in each precomputed irradiance estimate
    /// of the global map.
    pub global_lookup: u32,
    /// `"float maxradius"` (scene units; default 1/20 of the scene's bounding-sphere
    /// radius): the largest search radius of any estimate.
    pub max_radius: Option<f32>,
    /// `"integer finalgathersamples" [8]`: gather rays per camera sample at the first
    /// diffuse vertex (0 turns final gathering off: the global map is read directly).
    pub final_gather_samples: u32,
    /// `"bool projectionmaps" [true]`: aim caustic photons only at specular objects.
    pub projection_maps: bool,
    /// `"integer maxdepth" [5]`: the most scattering events of a photon path, and of a
    /// camera path's specular chain.
    pub max_depth: u32,
    /// `"string kernel" ["cone"]`: `"disc"`, `"cone"` or `"epanechnikov"`.
    pub kernel: Kernel,
    /// `"string visualize" ["none"]`: `"none"`, `"photons"`, `"caustic"`, `"global"`,
    /// `"density"`.
    pub visualize: Visualize,
    /// `"integer seed"` (default: the sampler's seed): photon paths.
    pub seed: Option<u64>,
}

/// The defaults were chosen by CPU time to error on cornell-caustics (docs/speed.md,
/// 256 × 256, two seeds and more, against the reference). The caustic estimate's blur
/// is a bias that no number of camera samples removes: its squared relative error on
/// the caustic crop grows as `lookup` / `causticphotons` (4.5e-3 at 100 / 500k, above
/// the crop's 4e-3 target on its own; 0.8e-3 at 50 / 2M, for about 1.2 CPU-s more
/// photon tracing). What remains is camera-side noise, about (0.085 + 0.19 / FG) / spp
/// on the crop and (0.015 + 0.072 / FG) / spp on the whole image, against a cost of
/// about (0.55 + 0.058 FG) CPU-s per sample per pixel of the 256² image: 6 to 8 gather
/// rays minimise time to either error (64 made each sample four times dearer for
/// little), and 0 is both slower (each camera sample reads the global map) and biased.
impl Default for PhotonSettings {
    fn default() -> Self {
        PhotonSettings {
            photons: 200_000,
            caustic_photons: 2_000_000,
            lookup: 50,
            global_lookup: 200,
            max_radius: None,
            final_gather_samples: 8,
            projection_maps: true,
            max_depth: 5,
            kernel: Kernel::Cone,
            visualize: Visualize::None,
            seed: None,
        }
    }
}

impl PhotonSettings {
    /// Reads the parameters; `visualize_default` is `Density` for the `photonviz` name.
    ///
    /// ```text
    /// Integrator "photonmap" "integer photons" [200000] "integer causticphotons" [2000000]
    ///     "integer lookup" [50] "float maxradius" [25] "integer finalgathersamples" [8]
    ///     "bool projectionmaps" [true] "integer maxdepth" [5] "string kernel" ["cone"]
    ///     "string visualize" ["none"]
    /// ```
    pub fn from_desc(
        desc: &IntegratorDesc,
        visualize_default: Visualize,
    ) -> Result<PhotonSettings, SceneError> {
        let d = PhotonSettings::default();
        let p = &desc.params;
        let max_radius = if p.has("maxradius") {
            let r = p.finite_float("maxradius", 1.0)?;
            if r <= 0.0 {
                return Err(SceneError::at(
                    &desc.loc,
                    format!("\"maxradius\" must be positive, got {r}"),
                ));
            }
            Some(r)
        } else {
            None
        };
        let kernel = match p.string("kernel", "cone".into())?.as_str() {
            "disc" => Kernel::Disc,
            "cone" => Kernel::Cone,
            "epanechnikov" => Kernel::Epanechnikov,
            other => {
                return Err(SceneError::at(
                    &desc.loc,
                    format!("unknown kernel \"{other}\" (expected disc, cone, epanechnikov)"),
                ));
            }
        };
        let default_viz = match visualize_default {
            Visualize::Density => "density",
            _ => "none",
        };
        let visualize = match p.string("visualize", default_viz.into())?.as_str() {
            "none" => Visualize::None,
            "photons" => Visualize::Photons,
            "caustic" => Visualize::Caustic,
            "global" => Visualize::Global,
            "density" => Visualize::Density,
            other => {
                return Err(SceneError::at(
                    &desc.loc,
                    format!(
                        "unknown visualize mode \"{other}\" (expected none, photons, caustic, global, density)"
                    ),
                ));
            }
        };
        let seed = if p.has("seed") {
            Some(p.count("seed", 0)? as u64)
        } else {
            None
        };
        let photons = p.count("photons", d.photons)?;
        let caustic_photons = p.count("causticphotons", d.caustic_photons)?;
        let max_depth = p.count("maxdepth", d.max_depth)?;
        // The maps before they are traced: each emitted photon is stored at its diffuse
        // hits — on average 1/(1 - albedo) under Russian roulette, about 2.5 in a closed
        // room of albedo 0.6, at most `maxdepth` — held twice while the per-thread
        // buffers are merged, plus the kd-tree's split axes.
        let stored_per_emitted = (max_depth as f64).clamp(1.0, 2.5);
        let bytes = (photons as f64 + caustic_photons as f64)
            * stored_per_emitted
            * (2 * std::mem::size_of::<super::record::Photon>() + 1) as f64;
        if let Err(over) = crate::budget::check(bytes) {
            let name = if p.has("photons") {
                "photons"
            } else {
                "causticphotons"
            };
            let loc = p.lookup(name).map_or(&desc.loc, |q| &q.loc);
            return Err(SceneError::at(
                loc,
                format!(
                    "{photons} photons and {caustic_photons} caustic photons would make maps of {over}"
                ),
            ));
        }
        Ok(PhotonSettings {
            photons,
            caustic_photons,
            lookup: p.count("lookup", d.lookup)?.max(1),
            global_lookup: p.count("globallookup", d.global_lookup)?.max(1),
            max_radius,
            final_gather_samples: p.count("finalgathersamples", d.final_gather_samples)?,
            projection_maps: p.bool("projectionmaps", d.projection_maps)?,
            max_depth,
            kernel,
            visualize,
            seed,
        })
    }
}
