//! `Texture "name" "float"|"spectrum" "class" params` and texture-valued parameters.
//!
//! Classes and their parameters (pbrt-v4's names and defaults): `constant` (`value`),
//! `scale` (`tex`, `scale`), `mix` (`tex1`, `tex2`, `amount`), `directionmix` (`tex1`,
//! `tex2`, `dir`), `checkerboard` (`dimension` 2 or 3, `tex1`, `tex2`), `bilerp` (`v00`,
//! `v01`, `v10`, `v11`), `dots` (`inside`, `outside`), `fbm` and `wrinkled` (`octaves`,
//! `roughness`), `windy`, `marble` (`octaves`, `roughness`, `scale`, `variation`) and
//! `imagemap` (`filename`, `filter`, `wrap`, `scale`, `invert`, `encoding`,
//! `maxanisotropy`). 2D classes take `mapping` (`uv` with `uscale`, `vscale`,
//! `udelta`, `vdelta`; `spherical`; `cylindrical`; `planar` with `v1`, `v2`, `udelta`,
//! `vdelta`); the mapping and the solid classes work in the texture's space, the
//! current transform at the directive. `ptex` is read as a constant with a warning.
//!
//! A parameter that names a texture must name one already defined, of its own type
//! (a float parameter, a float texture); anything else is a located error.

use std::collections::hash_map::Entry;

use glam::Vec3;

use super::Parser;
use super::spectrum_param::{SpectrumUse, SpectrumValue};
use super::state::with_defaults;
use crate::error::{FileLoc, SceneError};
use crate::params::{ParamSet, ParamValue};
use crate::texture::{
    ColorEncoding, FloatParam, ImageFilter, ImageMapDesc, Mapping2D, Mapping3D, SpectrumParam,
    TextureDesc, TextureId, TextureKind, TextureType, TexturedParam, WrapMode,
};
use radiant_math::color::Rgb;

impl Parser {
    pub(super) fn texture(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("Texture")?;
        let (ty_name, ty_loc) = self.string_arg("Texture")?;
        let (class, _) = self.string_arg("Texture")?;
        let ps = with_defaults(self.param_list()?, &self.gs.defaults.texture);
        self.require_world("Texture", loc)?;
        let ty = match ty_name.as_str() {
            "float" => TextureType::Float,
            // pbrt-v3 wrote "color".
            "spectrum" | "color" => TextureType::Spectrum,
            other => {
                return Err(SceneError::at(
                    &ty_loc,
                    format!("texture type \"{other}\" is neither \"float\" nor \"spectrum\""),
                ));
            }
        };
        let owner = format!("Texture \"{name}\" (\"{class}\")");
        let kind = self.texture_kind(ty, &class, &ps, loc, &owner)?;
        if !self.gs.ctm.is_invertible() && maps_through_the_transform(&kind) {
            return Err(SceneError::at(
                loc,
                format!(
                    "{owner}: the current transform is singular, and this mapping needs its inverse"
                ),
            ));
        }
        self.report_unused(&ps, &owner);
        let id = self.textures.len() as TextureId;
        match self.named_textures.entry((ty, name.clone())) {
            Entry::Occupied(_) => {
                return Err(SceneError::at(
                    loc,
                    format!("{} texture \"{name}\" is defined twice", ty.name()),
                ));
            }
            Entry::Vacant(v) => {
                v.insert(id);
            }
        }
        self.textures.push(TextureDesc {
            name,
            ty,
            kind,
            loc: loc.clone(),
        });
        Ok(())
    }

    fn texture_kind(
        &mut self,
        ty: TextureType,
        class: &str,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<TextureKind, SceneError> {
        let operand =
            |p: &mut Parser, name: &str, default: f32| -> Result<SpectrumParam, SceneError> {
                p.texture_operand(ty, ps, name, default)
            };
        let solid = |p: &Parser| Mapping3D {
            texture_from_render: p.gs.ctm.inverse(),
        };
        Ok(match class {
            "constant" => match operand(self, "value", 1.0)? {
                TexturedParam::Constant(c) => TextureKind::Constant(c),
                TexturedParam::Texture(_) => {
                    return Err(SceneError::at(
                        loc,
                        format!("{owner}: \"value\" must be a constant"),
                    ));
                }
            },
            "scale" => TextureKind::Scale {
                tex: operand(self, "tex", 1.0)?,
                scale: self.float_texture_param(ps, "scale", 1.0)?,
            },
            "mix" => TextureKind::Mix {
                tex1: operand(self, "tex1", 0.0)?,
                tex2: operand(self, "tex2", 1.0)?,
                amount: self.float_texture_param(ps, "amount", 0.5)?,
            },
            "directionmix" => {
                let dir = ps.vector3("dir", Vec3::Y)?;
                let dir = self.gs.ctm.vector(dir).normalize_or_zero();
                if dir == Vec3::ZERO || !dir.is_finite() {
                    let at = ps.lookup("dir").map_or(loc, |p| &p.loc).clone();
                    return Err(SceneError::at(
                        &at,
                        format!("{owner}: \"dir\" must be a non-zero vector"),
                    ));
                }
                TextureKind::DirectionMix {
                    tex1: operand(self, "tex1", 0.0)?,
                    tex2: operand(self, "tex2", 1.0)?,
                    dir,
                }
            }
            "checkerboard" => {
                let dimension = ps.int("dimension", 2)?;
                let (tex1, tex2) = (operand(self, "tex1", 1.0)?, operand(self, "tex2", 0.0)?);
                match dimension {
                    2 => TextureKind::Checkerboard2D {
                        mapping: self.mapping_2d(ps, owner)?,
                        tex1,
                        tex2,
                    },
                    3 => TextureKind::Checkerboard3D {
                        mapping: solid(self),
                        tex1,
                        tex2,
                    },
                    d => {
                        let at = ps.lookup("dimension").map_or(loc, |p| &p.loc).clone();
                        return Err(SceneError::at(
                            &at,
                            format!("{owner}: \"dimension\" {d} must be 2 or 3"),
                        ));
                    }
                }
            }
            "bilerp" => {
                let corner =
                    |p: &mut Parser, name: &str, default: f32| match operand(p, name, default)? {
                        TexturedParam::Constant(c) => Ok(c),
                        TexturedParam::Texture(_) => Err(SceneError::at(
                            &ps.lookup(name).expect("present").loc,
                            format!("{owner}: \"{name}\" must be a constant"),
                        )),
                    };
                TextureKind::Bilerp {
                    v00: corner(self, "v00", 0.0)?,
                    v01: corner(self, "v01", 1.0)?,
                    v10: corner(self, "v10", 0.0)?,
                    v11: corner(self, "v11", 1.0)?,
                    mapping: self.mapping_2d(ps, owner)?,
                }
            }
            "dots" => TextureKind::Dots {
                inside: operand(self, "inside", 1.0)?,
                outside: operand(self, "outside", 0.0)?,
                mapping: self.mapping_2d(ps, owner)?,
            },
            "fbm" | "wrinkled" => {
                let octaves = octaves(ps)?;
                let roughness = ps.finite_float("roughness", 0.5)?;
                self.float_only(ty, class, loc)?;
                let mapping = solid(self);
                if class == "fbm" {
                    TextureKind::Fbm {
                        mapping,
                        octaves,
                        roughness,
                    }
                } else {
                    TextureKind::Wrinkled {
                        mapping,
                        octaves,
                        roughness,
                    }
                }
            }
            "windy" => {
                self.float_only(ty, class, loc)?;
                TextureKind::Windy {
                    mapping: solid(self),
                }
            }
            "marble" => {
                if ty != TextureType::Spectrum {
                    return Err(SceneError::at(
                        loc,
                        "\"marble\" is a spectrum texture; it has no float form",
                    ));
                }
                TextureKind::Marble {
                    octaves: octaves(ps)?,
                    roughness: ps.finite_float("roughness", 0.5)?,
                    scale: ps.finite_float("scale", 1.0)?,
                    variation: ps.finite_float("variation", 0.2)?,
                    mapping: solid(self),
                }
            }
            "imagemap" => TextureKind::ImageMap {
                image: self.image_map(ps, loc, owner)?,
                mapping: self.mapping_2d(ps, owner)?,
            },
            "ptex" => {
                ps.mark_all_used();
                self.warn(
                    loc,
                    format!("{owner}: ptex textures are not supported; read as the constant 0.5"),
                );
                TextureKind::Constant(Rgb::splat(0.5))
            }
            other => {
                return Err(SceneError::at(
                    loc,
                    format!("unknown texture class \"{other}\""),
                ));
            }
        })
    }

    fn float_only(&self, ty: TextureType, class: &str, loc: &FileLoc) -> Result<(), SceneError> {
        if ty == TextureType::Float {
            Ok(())
        } else {
            Err(SceneError::at(
                loc,
                format!("\"{class}\" is a float texture; it has no spectrum form"),
            ))
        }
    }

    fn image_map(
        &mut self,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<ImageMapDesc, SceneError> {
        let written = match ps.strings("filename")? {
            Some(([f], _)) => f.clone(),
            Some((_, at)) => {
                return Err(SceneError::at(at, "\"string filename\" needs one value"));
            }
            None => {
                return Err(SceneError::at(
                    loc,
                    format!("{owner} needs \"string filename\""),
                ));
            }
        };
        let file_loc = ps.lookup("filename").expect("present").loc.clone();
        let filename = self.resolve_path(&written);
        if let Some(why) = super::not_a_file(&filename) {
            return Err(SceneError::at(
                &file_loc,
                format!("image '{}' {why}", filename.display()),
            ));
        }
        let at = |name: &str| ps.lookup(name).map(|p| p.loc.clone());
        let filter = match ps.string("filter", "bilinear".into())?.as_str() {
            "point" => ImageFilter::Point,
            "bilinear" => ImageFilter::Bilinear,
            "trilinear" => ImageFilter::Trilinear,
            "ewa" | "EWA" => ImageFilter::Ewa,
            other => {
                return Err(SceneError::at(
                    &at("filter").expect("present"),
                    format!("unknown image filter \"{other}\" (point, bilinear, trilinear, ewa)"),
                ));
            }
        };
        let wrap = match ps.string("wrap", "repeat".into())?.as_str() {
            "repeat" => WrapMode::Repeat,
            "black" => WrapMode::Black,
            "clamp" => WrapMode::Clamp,
            "octahedralsphere" => WrapMode::OctahedralSphere,
            other => {
                return Err(SceneError::at(
                    &at("wrap").expect("present"),
                    format!(
                        "unknown wrap mode \"{other}\" (repeat, black, clamp, octahedralsphere)"
                    ),
                ));
            }
        };
        let encoding = match ps.strings("encoding")? {
            None => None,
            Some(([e], eloc)) => Some(parse_encoding(e).ok_or_else(|| {
                SceneError::at(
                    eloc,
                    format!("unknown color encoding \"{e}\" (sRGB, linear, \"gamma G\")"),
                )
            })?),
            Some((_, eloc)) => {
                return Err(SceneError::at(eloc, "\"string encoding\" needs one value"));
            }
        };
        let max_anisotropy = ps.finite_float("maxanisotropy", 8.0)?;
        if max_anisotropy < 1.0 {
            return Err(SceneError::at(
                &at("maxanisotropy").expect("present"),
                format!("\"maxanisotropy\" {max_anisotropy} must be >= 1"),
            ));
        }
        Ok(ImageMapDesc {
            filename,
            filter,
            wrap,
            scale: ps.finite_float("scale", 1.0)?,
            invert: ps.bool("invert", false)?,
            encoding,
            max_anisotropy,
        })
    }

    fn mapping_2d(&mut self, ps: &ParamSet, owner: &str) -> Result<Mapping2D, SceneError> {
        let texture_from_render = self.gs.ctm.inverse();
        let du = ps.finite_float("udelta", 0.0)?;
        let dv = ps.finite_float("vdelta", 0.0)?;
        Ok(match ps.string("mapping", "uv".into())?.as_str() {
            "uv" => Mapping2D::Uv {
                su: ps.finite_float("uscale", 1.0)?,
                sv: ps.finite_float("vscale", 1.0)?,
                du,
                dv,
            },
            "spherical" => Mapping2D::Spherical {
                texture_from_render,
            },
            "cylindrical" => Mapping2D::Cylindrical {
                texture_from_render,
            },
            "planar" => Mapping2D::Planar {
                texture_from_render,
                vs: ps.vector3("v1", Vec3::X)?,
                vt: ps.vector3("v2", Vec3::Y)?,
                ds: du,
                dt: dv,
            },
            other => {
                let at = ps.lookup("mapping").expect("present").loc.clone();
                return Err(SceneError::at(
                    &at,
                    format!(
                        "{owner}: unknown mapping \"{other}\" (uv, spherical, cylindrical, planar)"
                    ),
                ));
            }
        })
    }

    /// An operand of a texture of type `ty`: a constant or a texture of that type.
    fn texture_operand(
        &mut self,
        ty: TextureType,
        ps: &ParamSet,
        name: &str,
        default: f32,
    ) -> Result<SpectrumParam, SceneError> {
        Ok(match ty {
            TextureType::Spectrum => {
                self.spectrum_texture_param(ps, name, SpectrumUse::Unbounded, Rgb::splat(default))?
            }
            TextureType::Float => match self.float_texture_param(ps, name, default)? {
                TexturedParam::Constant(v) => TexturedParam::Constant(Rgb::splat(v)),
                TexturedParam::Texture(t) => TexturedParam::Texture(t),
            },
        })
    }

    /// A spectrum parameter that may name a spectrum texture.
    pub(super) fn spectrum_texture_param(
        &mut self,
        ps: &ParamSet,
        name: &str,
        usage: SpectrumUse,
        default: Rgb,
    ) -> Result<SpectrumParam, SceneError> {
        Ok(match self.spectrum_param(ps, name, usage)? {
            None => TexturedParam::Constant(default),
            Some((SpectrumValue::Rgb(c), _)) => TexturedParam::Constant(c),
            Some((SpectrumValue::Texture(t), loc)) => {
                TexturedParam::Texture(self.texture_ref(&t, TextureType::Spectrum, name, &loc)?)
            }
        })
    }

    /// A float parameter that may name a float texture.
    pub(super) fn float_texture_param(
        &mut self,
        ps: &ParamSet,
        name: &str,
        default: f32,
    ) -> Result<FloatParam, SceneError> {
        let Some(p) = ps.lookup(name) else {
            return Ok(TexturedParam::Constant(default));
        };
        let loc = p.loc.clone();
        match &p.value {
            ParamValue::Float(v) if v.len() == 1 => {
                if v[0].is_finite() {
                    Ok(TexturedParam::Constant(v[0]))
                } else {
                    Err(SceneError::at(&loc, format!("\"{name}\" must be finite")))
                }
            }
            ParamValue::Texture(v) if v.len() == 1 => {
                let t = v[0].clone();
                Ok(TexturedParam::Texture(self.texture_ref(
                    &t,
                    TextureType::Float,
                    name,
                    &loc,
                )?))
            }
            other => Err(SceneError::at(
                &loc,
                format!(
                    "parameter \"{name}\" has type \"{}\" or the wrong count; expected one float or a float texture",
                    other.type_name()
                ),
            )),
        }
    }

    /// The id of texture `texture` of type `ty`, named by parameter `param`.
    fn texture_ref(
        &self,
        texture: &str,
        ty: TextureType,
        param: &str,
        loc: &FileLoc,
    ) -> Result<TextureId, SceneError> {
        if let Some(&id) = self.named_textures.get(&(ty, texture.to_string())) {
            return Ok(id);
        }
        let other = match ty {
            TextureType::Float => TextureType::Spectrum,
            TextureType::Spectrum => TextureType::Float,
        };
        if self
            .named_textures
            .contains_key(&(other, texture.to_string()))
        {
            return Err(SceneError::at(
                loc,
                format!(
                    "\"{param}\" needs a {} texture, but \"{texture}\" is a {} texture",
                    ty.name(),
                    other.name()
                ),
            ));
        }
        Err(SceneError::at(
            loc,
            format!(
                "\"{param}\" names undefined {} texture \"{texture}\"",
                ty.name()
            ),
        ))
    }
}

fn octaves(ps: &ParamSet) -> Result<u32, SceneError> {
    let n = ps.int("octaves", 8)?;
    if (1..=32).contains(&n) {
        Ok(n as u32)
    } else {
        Err(SceneError::at(
            &ps.lookup("octaves").expect("present").loc,
            format!("\"octaves\" {n} must be in 1..=32"),
        ))
    }
}

/// pbrt-v4's encoding names: `sRGB`, `linear`, `gamma G`.
fn parse_encoding(s: &str) -> Option<ColorEncoding> {
    match s {
        "sRGB" | "srgb" => Some(ColorEncoding::Srgb),
        "linear" => Some(ColorEncoding::Linear),
        _ => {
            let g: f32 = s.strip_prefix("gamma")?.trim().parse().ok()?;
            (g.is_finite() && g > 0.0).then_some(ColorEncoding::Gamma(g))
        }
    }
}

/// Whether a texture's mapping reads the point through the inverse of the transform
/// it was defined under (solid textures and the non-uv 2D mappings).
fn maps_through_the_transform(kind: &TextureKind) -> bool {
    let two_d = |m: &Mapping2D| !matches!(m, Mapping2D::Uv { .. });
    match kind {
        TextureKind::Checkerboard3D { .. }
        | TextureKind::Fbm { .. }
        | TextureKind::Wrinkled { .. }
        | TextureKind::Windy { .. }
        | TextureKind::Marble { .. } => true,
        TextureKind::Checkerboard2D { mapping, .. }
        | TextureKind::Bilerp { mapping, .. }
        | TextureKind::Dots { mapping, .. }
        | TextureKind::ImageMap { mapping, .. } => two_d(mapping),
        TextureKind::Constant(_)
        | TextureKind::Scale { .. }
        | TextureKind::Mix { .. }
        | TextureKind::DirectionMix { .. } => false,
    }
}
