//! `LightSource` and `AreaLightSource`.
//!
//! Radiometry follows pbrt-v4: an `rgb` emission renders as that RGB × `scale`;
//! `blackbody` and sampled spectra are normalised to luminance 1 first. `power`
//! (point, spot, area) and `illuminance` (distant, infinite) rescale the emission so
//! that its luminance-weighted power (or illuminance) equals the number given —
//! pbrt-v4 normalises only the spectrum's illuminant there and ignores the RGB
//! multiplier, so the two agree exactly for white and differ by the RGB's luminance
//! otherwise.
//!
//! - `"point"`: `I` (white), `from` (0,0,0), `scale`, `power`.
//! - `"spot"`: `I`, `from` (0,0,0), `to` (0,0,1), `coneangle` 30° (in (0°, 180°]),
//!   `conedeltaangle` 5° (in [0, `coneangle`]; by default at most the cone, so that a
//!   cone narrower than 5° falls off over its whole width), `scale`, `power`.
//! - `"distant"`: `L`, `from` (0,0,0), `to` (0,0,1), `scale`, `illuminance`.
//! - `"infinite"`: `L` (constant) or `filename` (a square equal-area octahedral image:
//!   EXR, PFM or PNG), `scale`, `illuminance`; `portal` is read and ignored.
//! - `"goniometric"`: `I`, `scale`, `power`, `filename` (a square equal-area
//!   octahedral image; its RGB channels are averaged).
//! - `"projection"`: `filename`, `fov` 90°, `scale`, `power`.
//! - `AreaLightSource "diffuse"`: `L` or `filename` (an image looked up at the
//!   surface's (u, 1 − v)), `scale`, `twosided` (false), `power`.
//!
//! `power` and `illuminance` set the emission before `scale`, which multiplies the
//! result (pbrt-v4 multiplies its scale by power / k_e). A `scale` may not be negative;
//! a `power` or `illuminance` that is not positive is ignored, as pbrt-v4 ignores it,
//! with a warning.

use glam::Vec3;

use super::Parser;
use super::spectrum_param::SpectrumUse;
use super::state::{AreaLightState, with_defaults};
use crate::desc::{EnvironmentImage, LightDesc, LightImage};
use crate::error::{FileLoc, SceneError};
use crate::params::{ParamSet, ParamValue};
use radiant_math::PI;
use radiant_math::color::Rgb;

/// Factor that gives `emission` the luminance `target` (1 when either is not positive).
fn photometric_factor(emission: Rgb, target: f32) -> f32 {
    let y = emission.luminance();
    if target > 0.0 && y > 0.0 {
        target / y
    } else {
        1.0
    }
}

/// The power a light whose emission includes `scale` must have so that `power` applies
/// to the emission before `scale`, as in pbrt-v4 (which multiplies its scale by
/// power / k_e): the scale then multiplies the normalised light (exact for pbrt-v4's
/// float `scale`; a pbrt-v3 spectral scale counts by its luminance).
fn scaled_target(power: Option<f32>, scale: Rgb) -> Option<f32> {
    power.map(|phi| phi * scale.luminance())
}

impl Parser {
    /// pbrt-v4's `float scale`; pbrt-v3's spectral `scale` is accepted too.
    fn light_scale(&mut self, ps: &ParamSet, owner: &str) -> Result<Rgb, SceneError> {
        let Some(p) = ps.lookup("scale") else {
            return Ok(Rgb::WHITE);
        };
        let s = match &p.value {
            ParamValue::Float(v) if v.len() == 1 => Rgb::splat(v[0]),
            ParamValue::Rgb(v) if v.len() == 1 => {
                let at = p.loc.clone();
                self.warn(
                    &at,
                    format!("{owner}: a spectral \"scale\" is pbrt-v3 syntax; applied per channel"),
                );
                v[0]
            }
            other => {
                return Err(SceneError::at(
                    &p.loc,
                    format!(
                        "parameter \"scale\" has type \"{}\" or the wrong count; expected one float",
                        other.type_name()
                    ),
                ));
            }
        };
        if !s.is_finite() {
            return Err(SceneError::at(&p.loc, "light \"scale\" must be finite"));
        }
        if s.min_component() < 0.0 {
            return Err(SceneError::at(
                &p.loc,
                format!(
                    "{owner}: \"scale\" must not be negative (a light cannot emit negative radiance)"
                ),
            ));
        }
        Ok(s)
    }

    /// An optional positive number (`power`, `illuminance`). pbrt's default is -1, off,
    /// and pbrt-v4 ignores any value that is not positive: so does radiant, but a value
    /// written in the file that is ignored is reported.
    fn optional_positive(
        &mut self,
        ps: &ParamSet,
        name: &str,
        owner: &str,
    ) -> Result<Option<f32>, SceneError> {
        let v = ps.finite_float(name, -1.0)?;
        if v <= 0.0
            && let Some(p) = ps.lookup(name)
        {
            let at = p.loc.clone();
            self.warn(
                &at,
                format!("{owner}: \"{name}\" {v} is not positive; ignored (the emission is used as given)"),
            );
        }
        Ok((v > 0.0).then_some(v))
    }

    /// The spot light's `coneangle` and `conedeltaangle` (degrees): the cone must have
    /// a width, and its falloff must lie inside it, or the light has no solid angle to
    /// spread its power over.
    fn spot_cone(ps: &ParamSet) -> Result<(f32, f32), SceneError> {
        let cone = ps.float_where("coneangle", 30.0, "must lie in (0, 180] degrees", |c| {
            c > 0.0 && c <= 180.0
        })?;
        let delta = ps.float_where(
            "conedeltaangle",
            5.0f32.min(cone),
            &format!("must lie in [0, coneangle = {cone}] degrees"),
            |d| (0.0..=cone).contains(&d),
        )?;
        Ok((cone, delta))
    }

    pub(super) fn light_source(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("LightSource")?;
        let ps = with_defaults(self.param_list()?, &self.gs.defaults.light);
        self.require_world("LightSource", loc)?;
        let owner = format!("LightSource \"{name}\"");
        if self.object.is_some() {
            ps.mark_all_used();
            self.warn(
                loc,
                format!("{owner} inside an object definition is ignored"),
            );
            return Ok(());
        }
        let ctm = self.gs.ctm;
        let light = match name.as_str() {
            "point" | "spot" => {
                let scale = self.light_scale(&ps, &owner)?;
                let written =
                    self.spectrum_or(&ps, "I", SpectrumUse::Illuminant, Rgb::WHITE, &owner)?;
                let i = written * scale;
                let power = self.optional_positive(&ps, "power", &owner)?;
                let from = ps.point3("from", Vec3::ZERO)?;
                let position = ctm.point(from);
                if name == "point" {
                    LightDesc::Point {
                        position,
                        // Φ = 4π I for an isotropic point light.
                        intensity: power
                            .map_or(i, |phi| i * photometric_factor(written, phi / (4.0 * PI))),
                        loc: loc.clone(),
                    }
                } else {
                    let to = ps.point3("to", Vec3::Z)?;
                    let direction = ctm.vector(to - from).normalize_or_zero();
                    if direction == Vec3::ZERO || !direction.is_finite() {
                        return Err(SceneError::at(
                            loc,
                            format!("{owner}: \"from\" and \"to\" coincide"),
                        ));
                    }
                    let (cone, delta) = Self::spot_cone(&ps)?;
                    let cos_total_width = cone.to_radians().cos();
                    let cos_falloff_start = (cone - delta).to_radians().cos();
                    // Φ = 2π I [(1 - cos_start) + (cos_start - cos_end) / 2]: full
                    // intensity inside the inner cone, and the smoothstep falloff
                    // integrates to half its width in cos θ (it is symmetric about its
                    // midpoint).
                    let solid_angle = 2.0
                        * PI
                        * ((1.0 - cos_falloff_start) + 0.5 * (cos_falloff_start - cos_total_width));
                    LightDesc::Spot {
                        position,
                        direction,
                        intensity: power
                            .map_or(i, |phi| i * photometric_factor(written, phi / solid_angle)),
                        cos_falloff_start,
                        cos_total_width,
                        loc: loc.clone(),
                    }
                }
            }
            "distant" | "infinite" => {
                let scale = self.light_scale(&ps, &owner)?;
                let written =
                    self.spectrum_or(&ps, "L", SpectrumUse::Illuminant, Rgb::WHITE, &owner)?;
                let l = written * scale;
                let e = self.optional_positive(&ps, "illuminance", &owner)?;
                if name == "distant" {
                    let from = ps.point3("from", Vec3::ZERO)?;
                    let to = ps.point3("to", Vec3::Z)?;
                    let direction = ctm.vector(to - from).normalize_or_zero();
                    if direction == Vec3::ZERO || !direction.is_finite() {
                        return Err(SceneError::at(
                            loc,
                            format!("{owner}: \"from\" and \"to\" coincide"),
                        ));
                    }
                    LightDesc::Distant {
                        direction,
                        // A distant light's "radiance" is the irradiance it delivers
                        // on a surface facing it.
                        radiance: e.map_or(l, |e| l * photometric_factor(written, e)),
                        loc: loc.clone(),
                    }
                } else {
                    self.infinite_light(&ps, written, scale, e, &owner, loc)?
                }
            }
            "goniometric" => {
                let scale = self.light_scale(&ps, &owner)?;
                let i = self.spectrum_or(&ps, "I", SpectrumUse::Illuminant, Rgb::WHITE, &owner)?
                    * scale;
                let power = scaled_target(self.optional_positive(&ps, "power", &owner)?, scale);
                let image = self.light_image(&ps)?;
                if image.is_none() {
                    self.warn(
                        loc,
                        format!("{owner}: no \"filename\"; the light is isotropic"),
                    );
                }
                LightDesc::Goniometric {
                    render_from_light: ctm,
                    intensity: i,
                    power,
                    image,
                    loc: loc.clone(),
                }
            }
            "projection" => {
                let scale = self.light_scale(&ps, &owner)?;
                let power = scaled_target(self.optional_positive(&ps, "power", &owner)?, scale);
                let fov = ps.finite_float("fov", 90.0)?;
                if !(fov > 0.0 && fov < 180.0) {
                    let at = ps.lookup("fov").map_or(loc.clone(), |p| p.loc.clone());
                    return Err(SceneError::at(
                        &at,
                        format!("{owner}: \"fov\" must lie between 0 and 180 degrees"),
                    ));
                }
                let Some(image) = self.light_image(&ps)? else {
                    return Err(SceneError::at(loc, format!("{owner} needs a \"filename\"")));
                };
                LightDesc::Projection {
                    render_from_light: ctm,
                    scale,
                    fov,
                    power,
                    image,
                    loc: loc.clone(),
                }
            }
            _ => return Err(SceneError::at(loc, format!("unknown light \"{name}\""))),
        };
        self.report_unused(&ps, &owner);
        self.lights.push(light);
        Ok(())
    }

    /// The light's `"string filename"`, resolved against the scene's folder.
    fn light_image(&mut self, ps: &ParamSet) -> Result<Option<LightImage>, SceneError> {
        let Some((names, at)) = ps.strings("filename")? else {
            return Ok(None);
        };
        let [written] = names else {
            return Err(SceneError::at(at, "\"filename\" needs one value"));
        };
        Ok(Some(LightImage {
            path: self.resolve_path(written),
            at: at.clone(),
        }))
    }

    /// `LightSource "infinite"`: constant `written` × `scale`, or the image of
    /// `filename` times `scale`; `e` the `illuminance` asked for (before `scale`).
    fn infinite_light(
        &mut self,
        ps: &ParamSet,
        written: Rgb,
        scale: Rgb,
        e: Option<f32>,
        owner: &str,
        loc: &FileLoc,
    ) -> Result<LightDesc, SceneError> {
        if let Some(p) = ps.lookup("portal") {
            let at = p.loc.clone();
            self.warn(
                &at,
                format!("{owner}: \"portal\" ignored (the whole environment is sampled)"),
            );
        }
        let Some((names, at)) = ps.strings("filename")? else {
            return Ok(LightDesc::Infinite {
                // Constant L over the upper hemisphere gives E = π L on an
                // upward-facing surface.
                radiance: e.map_or(written * scale, |e| {
                    written * scale * photometric_factor(written, e / PI)
                }),
                image: None,
                loc: loc.clone(),
            });
        };
        let [file] = names else {
            return Err(SceneError::at(at, "\"filename\" needs one value"));
        };
        let at = at.clone();
        if let Some(p) = ps.lookup("L") {
            return Err(SceneError::at(
                &p.loc,
                format!("{owner}: give either \"L\" or \"filename\", not both"),
            ));
        }
        Ok(LightDesc::Infinite {
            radiance: written * scale,
            image: Some(EnvironmentImage {
                path: self.resolve_path(file),
                at,
                illuminance: e,
                render_from_light: self.gs.ctm,
            }),
            loc: loc.clone(),
        })
    }

    pub(super) fn area_light_source(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("AreaLightSource")?;
        let ps = with_defaults(self.param_list()?, &self.gs.defaults.light);
        self.require_world("AreaLightSource", loc)?;
        let owner = format!("AreaLightSource \"{name}\"");
        if name != "diffuse" {
            return Err(SceneError::at(
                loc,
                format!("unknown area light \"{name}\""),
            ));
        }
        let scale = self.light_scale(&ps, &owner)?;
        let image = self.light_image(&ps)?;
        if image.is_some()
            && let Some(p) = ps.lookup("L")
        {
            return Err(SceneError::at(
                &p.loc,
                format!("{owner}: give either \"L\" or \"filename\", not both"),
            ));
        }
        let l = self.spectrum_or(&ps, "L", SpectrumUse::Illuminant, Rgb::WHITE, &owner)?;
        let state = AreaLightState {
            l,
            scale,
            two_sided: ps.bool("twosided", false)?,
            power: self.optional_positive(&ps, "power", &owner)?,
            image,
        };
        self.report_unused(&ps, &owner);
        self.gs.area_light = Some(state);
        Ok(())
    }
}
