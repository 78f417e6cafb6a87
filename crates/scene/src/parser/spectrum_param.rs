//! Spectrum-valued parameters (`rgb`, `spectrum`, `blackbody`, a plain `float`, or a
//! `texture` name) reduced to RGB. See [`crate::spectrum`] for the conversions.

use super::Parser;
use crate::error::{FileLoc, SceneError};
use crate::named_spectra::{glass_eta, metal_spectrum};
use crate::params::{ParamSet, ParamValue};
use crate::spectrum::{band_average, blackbody_rgb, emission_rgb, interpolate, pairs_from_flat};
use radiant_math::color::Rgb;

/// What a spectrum describes; decides the conversion and the checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SpectrumUse {
    /// A reflectance in [0, 1].
    Albedo,
    /// A positive quantity without bound (`eta`, `k`).
    Unbounded,
    /// Emission: sampled and blackbody spectra are normalised to luminance 1.
    Illuminant,
}

/// A spectrum parameter's value.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum SpectrumValue {
    Rgb(Rgb),
    /// A `texture` parameter: the texture's name, for the caller to resolve.
    Texture(String),
}

fn single<'a, T>(values: &'a [T], name: &str, loc: &FileLoc) -> Result<&'a T, SceneError> {
    match values {
        [v] => Ok(v),
        _ => Err(SceneError::at(
            loc,
            format!(
                "parameter \"{name}\" needs exactly one value, found {}",
                values.len()
            ),
        )),
    }
}

impl Parser {
    /// The spectrum parameter `name` as RGB, `None` when absent.
    pub(super) fn spectrum_param(
        &mut self,
        ps: &ParamSet,
        name: &str,
        usage: SpectrumUse,
    ) -> Result<Option<(SpectrumValue, FileLoc)>, SceneError> {
        let Some(p) = ps.lookup(name) else {
            return Ok(None);
        };
        let loc = p.loc.clone();
        let rgb = match &p.value {
            ParamValue::Rgb(v) => *single(v, name, &loc)?,
            ParamValue::Float(v) => Rgb::splat(*single(v, name, &loc)?),
            ParamValue::Blackbody(v) => {
                // v4 writes [T]; v3 wrote [T scale].
                let (t, scale) = match v.as_slice() {
                    [t] => (*t, 1.0),
                    [t, s] => (*t, *s),
                    _ => {
                        return Err(SceneError::at(
                            &loc,
                            format!("blackbody \"{name}\" needs one temperature"),
                        ));
                    }
                };
                let c = blackbody_rgb(t).ok_or_else(|| {
                    SceneError::at(
                        &loc,
                        format!("blackbody temperature {t} K gives no visible light"),
                    )
                })?;
                c * scale
            }
            ParamValue::SpectrumSamples(v) => {
                let pairs = pairs_from_flat(v).ok_or_else(|| {
                    SceneError::at(
                        &loc,
                        format!("spectrum \"{name}\" needs finite (wavelength, value) pairs"),
                    )
                })?;
                self.sampled_to_rgb(&pairs, usage, &loc)?
            }
            ParamValue::SpectrumNamed(v) => {
                let spectrum_name = single(v, name, &loc)?.clone();
                self.named_to_rgb(&spectrum_name, usage, &loc)?
            }
            ParamValue::Texture(v) => {
                return Ok(Some((
                    SpectrumValue::Texture(single(v, name, &loc)?.clone()),
                    loc,
                )));
            }
            other => {
                return Err(SceneError::at(
                    &loc,
                    format!(
                        "parameter \"{name}\" has type \"{}\", expected a spectrum (rgb, spectrum, blackbody or texture)",
                        other.type_name()
                    ),
                ));
            }
        };
        if !rgb.is_finite() || rgb.min_component() < 0.0 {
            return Err(SceneError::at(
                &loc,
                format!("parameter \"{name}\" must be finite and non-negative"),
            ));
        }
        let rgb = if usage == SpectrumUse::Albedo && rgb.max_component() > 1.0 {
            self.warn(&loc, format!("reflectance \"{name}\" above 1 clamped to 1"));
            rgb.map(|c| c.min(1.0))
        } else {
            rgb
        };
        Ok(Some((SpectrumValue::Rgb(rgb), loc)))
    }

    fn sampled_to_rgb(
        &mut self,
        pairs: &[(f64, f64)],
        usage: SpectrumUse,
        loc: &FileLoc,
    ) -> Result<Rgb, SceneError> {
        Ok(match usage {
            // pbrt's piecewise-linear spectra are zero outside their samples.
            SpectrumUse::Illuminant => {
                let (lo, hi) = (pairs[0].0, pairs[pairs.len() - 1].0);
                let inside = |l: f64| {
                    if (lo..=hi).contains(&l) {
                        interpolate(pairs, l)
                    } else {
                        0.0
                    }
                };
                emission_rgb(inside)
                    .ok_or_else(|| SceneError::at(loc, "emission spectrum has no visible energy"))?
            }
            SpectrumUse::Albedo | SpectrumUse::Unbounded => band_average(pairs),
        })
    }

    fn named_to_rgb(
        &mut self,
        name: &str,
        usage: SpectrumUse,
        loc: &FileLoc,
    ) -> Result<Rgb, SceneError> {
        if let Some(c) = metal_spectrum(name) {
            return Ok(c);
        }
        if let Some(eta) = glass_eta(name) {
            return Ok(Rgb::splat(eta));
        }
        if name.starts_with("stdillum-") && usage == SpectrumUse::Illuminant {
            if name != "stdillum-D65" {
                self.warn(
                    loc,
                    format!("named spectrum \"{name}\" is rendered as D65 white"),
                );
            }
            return Ok(Rgb::WHITE);
        }
        // Not a built-in name: pbrt reads it as a file of (wavelength, value) pairs.
        let path = self.resolve_path(name);
        let text = std::fs::read_to_string(&path).map_err(|_| {
            SceneError::at(
                loc,
                format!(
                    "unknown named spectrum \"{name}\" (and no file '{}')",
                    path.display()
                ),
            )
        })?;
        let values: Result<Vec<f32>, _> = text
            .lines()
            .map(|l| l.split('#').next().unwrap_or(""))
            .flat_map(str::split_whitespace)
            .map(str::parse::<f32>)
            .collect();
        let pairs = values
            .ok()
            .as_deref()
            .and_then(pairs_from_flat)
            .ok_or_else(|| {
                SceneError::at(
                    loc,
                    format!(
                        "spectrum file '{}' must hold (wavelength, value) pairs",
                        path.display()
                    ),
                )
            })?;
        self.sampled_to_rgb(&pairs, usage, loc)
    }

    /// A spectrum with a default, for parameters that take no texture: a texture falls
    /// back to the default with a warning.
    pub(super) fn spectrum_or(
        &mut self,
        ps: &ParamSet,
        name: &str,
        usage: SpectrumUse,
        default: Rgb,
        owner: &str,
    ) -> Result<Rgb, SceneError> {
        match self.spectrum_param(ps, name, usage)? {
            None => Ok(default),
            Some((SpectrumValue::Rgb(c), _)) => Ok(c),
            Some((SpectrumValue::Texture(t), loc)) => {
                self.warn(
                    &loc,
                    format!(
                        "{owner}: a texture for \"{name}\" is not supported here; \"{t}\" is replaced by ({}, {}, {})",
                        default.r, default.g, default.b
                    ),
                );
                Ok(default)
            }
        }
    }
}
