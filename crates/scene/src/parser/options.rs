//! Scene-wide options, before `WorldBegin`: camera, film, sampler, pixel filter,
//! integrator (and the directives radiant accepts but has no use for).
//!
//! Parameters and defaults (pbrt-v4):
//! - `Camera "perspective"`: `float fov` 90 (degrees, shorter image axis),
//!   `float lensradius` 0, `float focaldistance` 1e6, `float screenwindow[4]`,
//!   `float frameaspectratio`. `"orthographic"`: the same without `fov`.
//!   `"realistic"`: `string lensfile` (required, relative to the scene file),
//!   `float aperturediameter` 1.0 mm, `float focusdistance` 10.0 m.
//! - `Film "rgb"`: `integer xresolution` 1280, `yresolution` 720,
//!   `string filename` "pbrt.exr", `float diagonal` 35 mm, `float iso` 100,
//!   `float maxcomponentvalue` (infinite), `string sensor` "cie1931" (camera sensors
//!   are read as it, with a warning), `float whitebalance` 0 (none; 6500 K for a
//!   camera sensor).
//! - `Sampler`: `integer pixelsamples` 16, `integer seed` 0; `"stratified"` uses
//!   `xsamples` × `ysamples` (4 × 4) and `bool jitter` true; `"halton"` and `"sobol"`
//!   read `string randomization` (`permutedigits` and `fastowen` by default).
//! - `PixelFilter`: `float xradius`/`yradius`; box 0.5, gaussian 1.5 (`sigma` 0.5),
//!   triangle 2.

use glam::Vec2;

use super::Parser;
use crate::desc::*;
use crate::error::{FileLoc, SceneError};
use crate::params::ParamSet;

impl Parser {
    pub(super) fn camera(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("Camera")?;
        let ps = self.param_list()?;
        self.require_options("Camera", loc)?;
        let camera_from_world = self.gs.ctm;
        if !camera_from_world.is_invertible() {
            return Err(SceneError::at(
                loc,
                "Camera: the current transform is singular (the camera needs its inverse)",
            ));
        }
        self.named_coord_systems
            .insert("camera".into(), camera_from_world.inverse());
        let kind = match name.as_str() {
            "perspective" => {
                let fov_deg = ps.finite_float("fov", 90.0)?;
                if !(fov_deg > 0.0 && fov_deg < 180.0) {
                    let at = &ps.lookup("fov").map_or(loc, |p| &p.loc).clone();
                    return Err(SceneError::at(
                        at,
                        format!("fov {fov_deg} must lie in (0, 180) degrees"),
                    ));
                }
                CameraKind::Perspective {
                    fov_deg,
                    lens_radius: lens_radius(&ps)?,
                    focal_distance: focal_distance(&ps)?,
                    screen_window: screen_window(&ps)?,
                }
            }
            "orthographic" => CameraKind::Orthographic {
                lens_radius: lens_radius(&ps)?,
                focal_distance: focal_distance(&ps)?,
                screen_window: screen_window(&ps)?,
            },
            "realistic" => {
                let lens = ps.string("lensfile", String::new())?;
                let at = ps.lookup("lensfile").map_or(loc, |p| &p.loc).clone();
                if lens.is_empty() {
                    return Err(SceneError::at(
                        &at,
                        "Camera \"realistic\" needs \"string lensfile\"",
                    ));
                }
                let lens_file = self.resolve_path(&lens);
                if let Some(why) = super::not_a_file(&lens_file) {
                    return Err(SceneError::at(
                        &at,
                        format!("lens file '{}' {why}", lens_file.display()),
                    ));
                }
                if ps.has("aperture") {
                    ps.lookup("aperture");
                    self.warn(&at, "Camera \"realistic\": custom aperture shapes are not supported; a circular stop is used");
                }
                CameraKind::Realistic {
                    lens_file,
                    aperture_diameter_mm: ps.finite_float("aperturediameter", 1.0)?,
                    focus_distance: ps.finite_float("focusdistance", 10.0)?,
                }
            }
            "spherical" => {
                ps.mark_all_used();
                self.warn(
                    loc,
                    "Camera \"spherical\" is not supported; using a perspective camera with fov 90",
                );
                CameraKind::Perspective {
                    fov_deg: 90.0,
                    lens_radius: 0.0,
                    focal_distance: 1e6,
                    screen_window: None,
                }
            }
            _ => return Err(SceneError::at(loc, format!("unknown camera \"{name}\""))),
        };
        let exposure_time =
            ps.finite_float("shutterclose", 1.0)? - ps.finite_float("shutteropen", 0.0)?;
        if exposure_time.is_nan() || exposure_time <= 0.0 {
            return Err(SceneError::at(
                loc,
                format!(
                    "Camera: the shutter never opens (\"shutterclose\" − \"shutteropen\" = {exposure_time} s); the image would be black"
                ),
            ));
        }
        self.report_unused(&ps, &format!("Camera \"{name}\""));
        self.camera = Some(CameraDesc {
            camera_from_world,
            kind,
            exposure_time,
            loc: loc.clone(),
        });
        Ok(())
    }

    pub(super) fn film(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("Film")?;
        let ps = self.param_list()?;
        self.require_options("Film", loc)?;
        let mut gbuffer = None;
        match name.as_str() {
            "rgb" => {}
            "gbuffer" => {
                gbuffer = Some(
                    match ps.string("coordinatesystem", "camera".into())?.as_str() {
                        "camera" => GBufferSpace::Camera,
                        "world" => GBufferSpace::World,
                        other => {
                            let at = ps
                                .lookup("coordinatesystem")
                                .map_or(loc, |p| &p.loc)
                                .clone();
                            return Err(SceneError::at(
                                &at,
                                format!(
                                    "coordinatesystem \"{other}\": expected \"camera\" or \"world\""
                                ),
                            ));
                        }
                    },
                );
            }
            "spectral" => {
                ps.lookup("coordinatesystem");
                for p in ["nbuckets", "lambdamin", "lambdamax"] {
                    ps.lookup(p);
                }
                self.warn(
                    loc,
                    format!("Film \"{name}\" is rendered as an \"rgb\" film"),
                );
            }
            _ => return Err(SceneError::at(loc, format!("unknown film \"{name}\""))),
        }
        let resolution = |key: &str, default: u32| -> Result<u32, SceneError> {
            let v = ps.count(key, default)?;
            if v == 0 {
                let at = &ps.lookup(key).map_or(loc, |p| &p.loc).clone();
                return Err(SceneError::at(at, format!("{key} must be positive")));
            }
            Ok(v)
        };
        let film = FilmDesc {
            xresolution: resolution("xresolution", 1280)?,
            yresolution: resolution("yresolution", 720)?,
            filename: Some(ps.string("filename", "pbrt.exr".into())?),
            diagonal_mm: ps.float_where("diagonal", 35.0, "must be positive (mm)", |d| d > 0.0)?,
            iso: ps.float_where("iso", 100.0, "must be positive", |iso| iso > 0.0)?,
            gbuffer,
            max_component_value: film_max_component(&ps)?,
            white_balance: None,
            loc: loc.clone(),
        };
        let film = FilmDesc {
            white_balance: self.film_sensor(&ps)?,
            ..film
        };
        for (key, skip) in [
            ("savefp16", false),
            ("exposuretime", false),
            ("cropwindow", false),
            ("pixelbounds", false),
        ] {
            if let Some(p) = ps.lookup(key)
                && !skip
            {
                let at = p.loc.clone();
                self.warn(
                    &at,
                    format!("Film: parameter \"{key}\" is not supported; ignored"),
                );
            }
        }
        self.report_unused(&ps, &format!("Film \"{name}\""));
        self.film = Some(film);
        Ok(())
    }

    /// `sensor` and `whitebalance`. radiant renders RGB, so every sensor records
    /// through the CIE 1931 observer (pbrt-v4's default `cie1931`); a named camera
    /// sensor is read as that with a warning, and, as pbrt-v4 does for camera sensors,
    /// white-balanced to 6500 K unless `whitebalance` says otherwise. Returns the white
    /// balance temperature.
    fn film_sensor(&mut self, ps: &ParamSet) -> Result<Option<f32>, SceneError> {
        let mut camera_sensor = false;
        if let Some((names, at)) = ps.strings("sensor")? {
            let [name] = names else {
                return Err(SceneError::at(at, "\"string sensor\" needs one value"));
            };
            let at = at.clone();
            if name != "cie1931" {
                camera_sensor = true;
                let message = if CAMERA_SENSORS.contains(&name.as_str()) {
                    format!(
                        "Film: sensor \"{name}\" is rendered through the CIE 1931 observer (radiant renders RGB, not the camera's spectral response)"
                    )
                } else {
                    format!(
                        "Film: unknown sensor \"{name}\" (pbrt-v4 knows cie1931 and {}); rendered through the CIE 1931 observer",
                        CAMERA_SENSORS.join(", ")
                    )
                };
                self.warn(&at, message);
            }
        }
        let t = ps.finite_float("whitebalance", 0.0)?;
        if t < 0.0 {
            let at = ps.lookup("whitebalance").expect("present").loc.clone();
            return Err(SceneError::at(
                &at,
                "\"whitebalance\" must be positive (K) or 0 for none",
            ));
        }
        Ok(if t > 0.0 {
            Some(t)
        } else if camera_sensor {
            Some(6500.0)
        } else {
            None
        })
    }

    pub(super) fn sampler(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("Sampler")?;
        let ps = self.param_list()?;
        self.require_options("Sampler", loc)?;
        let at = |param: &str| {
            ps.lookup(param)
                .map_or_else(|| loc.clone(), |p| p.loc.clone())
        };
        let randomization = |default: &str| -> Result<DigitRandomization, SceneError> {
            match ps.string("randomization", default.into())?.as_str() {
                "none" => Ok(DigitRandomization::None),
                "permutedigits" => Ok(DigitRandomization::PermuteDigits),
                "owen" | "fastowen" => Ok(DigitRandomization::Owen),
                other => Err(SceneError::at(
                    &at("randomization"),
                    format!(
                        "unknown randomization \"{other}\" (none, permutedigits, fastowen, owen)"
                    ),
                )),
            }
        };
        let (kind, pixel_samples) = match name.as_str() {
            "independent" => (SamplerKind::Independent, ps.count("pixelsamples", 16)?),
            "halton" => (
                SamplerKind::Halton {
                    randomization: randomization("permutedigits")?,
                },
                ps.count("pixelsamples", 16)?,
            ),
            "stratified" => {
                let x = ps.count("xsamples", 4)?;
                let y = ps.count("ysamples", 4)?;
                let jitter = ps.bool("jitter", true)?;
                let n = x.checked_mul(y).unwrap_or(0);
                (SamplerKind::Stratified { x, y, jitter }, n)
            }
            _ => {
                let r = randomization("fastowen")?;
                if name != "sobol" && name != "paddedsobol" {
                    self.warn(
                        loc,
                        format!("Sampler \"{name}\": rendered with radiant's Owen-scrambled Sobol sampler"),
                    );
                }
                if r != DigitRandomization::Owen {
                    self.warn(
                        &at("randomization"),
                        format!(
                            "Sampler \"{name}\": radiant's Sobol points are always Owen-scrambled; \"randomization\" ignored"
                        ),
                    );
                }
                (SamplerKind::Sobol, ps.count("pixelsamples", 16)?)
            }
        };
        if pixel_samples == 0 {
            return Err(SceneError::at(
                loc,
                "Sampler: the number of samples per pixel must be positive (and fit 32 bits)",
            ));
        }
        let seed = ps.int("seed", 0)?;
        self.report_unused(&ps, &format!("Sampler \"{name}\""));
        self.sampler = Some(SamplerDesc {
            kind,
            pixel_samples,
            // Negative seeds are valid in pbrt; keep their bits.
            seed: u64::from(seed as u32),
            loc: loc.clone(),
        });
        Ok(())
    }

    pub(super) fn pixel_filter(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("PixelFilter")?;
        let ps = self.param_list()?;
        self.require_options("PixelFilter", loc)?;
        let (kind, default_radius) = match name.as_str() {
            "box" => (FilterKind::Box, 0.5),
            "triangle" => (FilterKind::Triangle, 2.0),
            "gaussian" => (
                FilterKind::Gaussian {
                    sigma: ps.finite_float("sigma", 0.5)?,
                },
                1.5,
            ),
            "mitchell" => (
                FilterKind::Mitchell {
                    b: ps.finite_float("B", 1.0 / 3.0)?,
                    c: ps.finite_float("C", 1.0 / 3.0)?,
                },
                2.0,
            ),
            "sinc" => (
                FilterKind::LanczosSinc {
                    tau: ps.float_where("tau", 3.0, "must be positive", |t| t > 0.0)?,
                },
                4.0,
            ),
            _ => {
                ps.mark_all_used();
                self.warn(loc, format!("PixelFilter \"{name}\" is not supported; using a gaussian filter (sigma 0.5, radius 1.5)"));
                self.filter = Some(FilterDesc {
                    kind: FilterKind::Gaussian { sigma: 0.5 },
                    radius: Vec2::splat(1.5),
                    loc: loc.clone(),
                });
                return Ok(());
            }
        };
        let radius = Vec2::new(
            ps.finite_float("xradius", default_radius)?,
            ps.finite_float("yradius", default_radius)?,
        );
        if radius.min_element() <= 0.0 {
            return Err(SceneError::at(loc, "PixelFilter: radii must be positive"));
        }
        if let FilterKind::Gaussian { sigma } = kind
            && sigma <= 0.0
        {
            return Err(SceneError::at(loc, "PixelFilter: sigma must be positive"));
        }
        self.report_unused(&ps, &format!("PixelFilter \"{name}\""));
        self.filter = Some(FilterDesc {
            kind,
            radius,
            loc: loc.clone(),
        });
        Ok(())
    }

    /// The integrator's parameters stay unread here: the integrator the lead builds
    /// from them reads them and reports the unused ones.
    pub(super) fn integrator(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("Integrator")?;
        let params = self.param_list()?;
        self.require_options("Integrator", loc)?;
        self.integrator = Some(IntegratorDesc {
            name,
            params,
            loc: loc.clone(),
        });
        Ok(())
    }

    /// `Accelerator "bvh"|"kdtree"`: radiant always builds its own BVH. The directive
    /// is accepted (pbrt-v4 scenes name one), but a k-d tree or any parameter is
    /// ignored with a warning; an unknown type is an error, as it is in pbrt-v4.
    pub(super) fn accelerator(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("Accelerator")?;
        let ps = self.param_list()?;
        self.require_options("Accelerator", loc)?;
        if name != "bvh" && name != "kdtree" {
            return Err(SceneError::at(
                loc,
                format!("unknown accelerator \"{name}\" (pbrt-v4 has \"bvh\" and \"kdtree\")"),
            ));
        }
        ps.mark_all_used();
        let params: Vec<String> = ps
            .params
            .iter()
            .map(|p| format!("\"{} {}\"", p.value.type_name(), p.name))
            .collect();
        if name == "kdtree" || !params.is_empty() {
            let ignored = match params.len() {
                0 => String::new(),
                1 => format!("; its parameter {} is ignored", params[0]),
                _ => format!("; its parameters {} are ignored", params.join(", ")),
            };
            self.warn(
                loc,
                format!("Accelerator \"{name}\": radiant always builds its own BVH{ignored}"),
            );
        }
        Ok(())
    }

    pub(super) fn color_space(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("ColorSpace")?;
        if name != "srgb" {
            self.warn(
                loc,
                format!(
                    "ColorSpace \"{name}\" is not supported; RGB values are read as linear sRGB"
                ),
            );
        }
        Ok(())
    }

    pub(super) fn option(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let ps: ParamSet = self.param_list()?;
        for p in &ps.params {
            self.warnings.push(crate::error::Warning {
                loc: p.loc.clone(),
                message: format!("Option \"{}\" is ignored", p.name),
            });
        }
        if ps.params.is_empty() {
            return Err(SceneError::at(loc, "Option needs a parameter"));
        }
        Ok(())
    }
}

/// `screenwindow`, or the window implied by `frameaspectratio` (pbrt: [-a, a] × [-1, 1]
/// for a > 1, else [-1, 1] × [-1/a, 1/a]); `None` leaves it to the film's aspect ratio.
fn screen_window(ps: &ParamSet) -> Result<Option<[f32; 4]>, SceneError> {
    if let Some((values, at)) = ps.floats("screenwindow")? {
        let [a, b, c, d] = values else {
            return Err(SceneError::at(
                at,
                format!("screenwindow needs 4 numbers, found {}", values.len()),
            ));
        };
        if values.iter().any(|v| !v.is_finite()) || a >= b || c >= d {
            return Err(SceneError::at(
                at,
                "screenwindow must be finite with xmin < xmax and ymin < ymax",
            ));
        }
        ps.lookup("frameaspectratio");
        return Ok(Some([*a, *b, *c, *d]));
    }
    match ps.floats("frameaspectratio")? {
        None => Ok(None),
        Some((&[a], _)) if a.is_finite() && a > 0.0 => Ok(Some(if a > 1.0 {
            [-a, a, -1.0, 1.0]
        } else {
            [-1.0, 1.0, -1.0 / a, 1.0 / a]
        })),
        Some((_, at)) => Err(SceneError::at(
            at,
            "frameaspectratio must be one positive number",
        )),
    }
}

/// The camera sensors whose spectral responses pbrt-v4 ships.
const CAMERA_SENSORS: [&str; 17] = [
    "canon_eos_100d",
    "canon_eos_1dx_mkii",
    "canon_eos_200d",
    "canon_eos_200d_mkii",
    "canon_eos_5d",
    "canon_eos_5d_mkii",
    "canon_eos_5d_mkiii",
    "canon_eos_5d_mkiv",
    "canon_eos_5ds",
    "canon_eos_m",
    "hasselblad_l1d_20c",
    "nikon_d810",
    "nikon_d850",
    "sony_a6400",
    "sony_a7m3",
    "sony_a7rm3",
    "sony_a9",
];

/// The thin lens's `lensradius` (0, a pinhole, by default).
fn lens_radius(ps: &ParamSet) -> Result<f32, SceneError> {
    ps.float_where("lensradius", 0.0, "must not be negative", |r| r >= 0.0)
}

/// The distance of the plane in focus, `focaldistance` (pbrt's default 10⁶).
fn focal_distance(ps: &ParamSet) -> Result<f32, SceneError> {
    ps.float_where("focaldistance", 1e6, "must be positive", |d| d > 0.0)
}

/// `maxcomponentvalue` (default infinite), which must be positive.
fn film_max_component(ps: &ParamSet) -> Result<f32, SceneError> {
    let Some(p) = ps.lookup("maxcomponentvalue") else {
        return Ok(f32::INFINITY);
    };
    let at = p.loc.clone();
    let v = ps.float("maxcomponentvalue", f32::INFINITY)?;
    if v > 0.0 && !v.is_nan() {
        Ok(v)
    } else {
        Err(SceneError::at(
            &at,
            "\"maxcomponentvalue\" must be positive",
        ))
    }
}
