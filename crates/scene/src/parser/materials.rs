//! `Material`, `MakeNamedMaterial`, `NamedMaterial` and `Texture`.
//!
//! - `"diffuse"`: `reflectance` (spectrum or spectrum texture, default 0.5).
//! - `"dielectric"`: `eta` (float or spectrum; default 1.5; named glasses become their
//!   d-line index).
//! - `"conductor"`: `reflectance` (an artist's mirror colour), else `eta` and `k`
//!   (spectra; default copper, `metal-Cu-eta` / `metal-Cu-k`).
//! - `"interface"` (also `""`, `"none"`): no surface.
//! - `dielectric` and `conductor` take pbrt-v4's microfacet roughness: `roughness`
//!   (default 0) sets both `uroughness` and `vroughness` unless they are given, and
//!   `remaproughness` (default true) maps each to the Trowbridge–Reitz alpha as
//!   alpha = sqrt(roughness); with it false the values are alphas already. Any
//!   non-zero alpha gives `RoughDielectric` / `RoughConductor` (the renderer keeps
//!   alphas below its smooth threshold a delta BSDF). Roughness may be a float
//!   texture.
//! - A material with a texture-valued parameter becomes [`MaterialDesc::Textured`];
//!   one whose parameters are all constant keeps its plain variant.
//! - Other material types render as diffuse 0.5 with a warning.

use super::Parser;
use super::spectrum_param::SpectrumUse;
use super::state::with_defaults;
use crate::desc::{ConductorDesc, MaterialDesc, MaterialId};
use crate::error::{FileLoc, SceneError};
use crate::named_spectra::{glass_eta, metal_spectrum};
use crate::params::{ParamSet, ParamValue};
use crate::spectrum::{interpolate, pairs_from_flat};
use crate::texture::{FloatParam, RoughnessDesc, TexturedMaterialDesc, TexturedParam};
use radiant_math::color::Rgb;

/// pbrt-v4's material types that radiant replaces by diffuse 0.5.
const FALLBACK_TYPES: [&str; 8] = [
    "coateddiffuse",
    "coatedconductor",
    "diffusetransmission",
    "hair",
    "measured",
    "mix",
    "subsurface",
    "thindielectric",
];

/// The d line (nm), where glass catalogues quote their index.
const D_LINE_NM: f64 = 587.6;

impl Parser {
    /// `Material "type" params`: an anonymous material that becomes current.
    pub(super) fn material(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (ty, _) = self.string_arg("Material")?;
        let ps = with_defaults(self.param_list()?, &self.gs.defaults.material);
        self.require_world("Material", loc)?;
        let owner = format!("Material \"{ty}\"");
        let m = self.build_material(&ty, &ps, loc, &owner)?;
        self.report_unused(&ps, &owner);
        self.gs.material = Some(self.push_material(m));
        Ok(())
    }

    /// `MakeNamedMaterial "name" "string type" "…" params`.
    pub(super) fn make_named_material(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("MakeNamedMaterial")?;
        let ps = with_defaults(self.param_list()?, &self.gs.defaults.material);
        self.require_world("MakeNamedMaterial", loc)?;
        let owner = format!("MakeNamedMaterial \"{name}\"");
        let ty = match ps.strings("type")? {
            Some(([t], _)) => t.clone(),
            Some((_, at)) => return Err(SceneError::at(at, "\"string type\" needs one value")),
            None => {
                return Err(SceneError::at(
                    loc,
                    format!("{owner} needs \"string type\""),
                ));
            }
        };
        if self.named_materials.contains_key(&name) {
            return Err(SceneError::at(
                loc,
                format!("named material \"{name}\" is defined twice"),
            ));
        }
        let m = self.build_material(&ty, &ps, loc, &owner)?;
        self.report_unused(&ps, &owner);
        let id = self.push_material(m);
        self.named_materials.insert(name, id);
        Ok(())
    }

    pub(super) fn named_material(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("NamedMaterial")?;
        self.require_world("NamedMaterial", loc)?;
        if name.is_empty() || name == "none" {
            let id = self.push_material(MaterialDesc::Interface);
            self.gs.material = Some(id);
            return Ok(());
        }
        match self.named_materials.get(&name) {
            Some(&id) => {
                self.gs.material = Some(id);
                Ok(())
            }
            None => Err(SceneError::at(
                loc,
                format!("unknown named material \"{name}\""),
            )),
        }
    }

    fn push_material(&mut self, m: MaterialDesc) -> MaterialId {
        self.materials.push(m);
        (self.materials.len() - 1) as MaterialId
    }

    /// The current material, creating pbrt's default (diffuse 0.5) on first need.
    pub(super) fn current_material(&mut self) -> MaterialId {
        if let Some(id) = self.gs.material {
            return id;
        }
        match self.default_material {
            Some(id) => id,
            None => {
                let id = self.push_material(MaterialDesc::Diffuse {
                    reflectance: Rgb::splat(0.5),
                });
                self.default_material = Some(id);
                id
            }
        }
    }

    fn build_material(
        &mut self,
        ty: &str,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<MaterialDesc, SceneError> {
        for unsupported in ["displacement", "normalmap"] {
            if let Some(p) = ps.lookup(unsupported) {
                let at = p.loc.clone();
                self.warn(
                    &at,
                    format!("{owner}: \"{unsupported}\" is not supported; ignored"),
                );
            }
        }
        Ok(match ty {
            "diffuse" => match self.spectrum_texture_param(
                ps,
                "reflectance",
                SpectrumUse::Albedo,
                Rgb::splat(0.5),
            )? {
                TexturedParam::Constant(reflectance) => MaterialDesc::Diffuse { reflectance },
                reflectance => {
                    MaterialDesc::Textured(TexturedMaterialDesc::Diffuse { reflectance })
                }
            },
            "dielectric" => {
                let alpha = self.microfacet_alpha(ps, loc, owner)?;
                let eta = self.dielectric_eta(ps, owner)?;
                match alpha {
                    Alpha::Smooth => MaterialDesc::Dielectric { eta },
                    Alpha::Constant(alpha_u, alpha_v) => MaterialDesc::RoughDielectric {
                        eta,
                        alpha_u,
                        alpha_v,
                    },
                    Alpha::Textured(roughness) => {
                        MaterialDesc::Textured(TexturedMaterialDesc::RoughDielectric {
                            eta,
                            roughness,
                        })
                    }
                }
            }
            "conductor" => {
                let alpha = self.microfacet_alpha(ps, loc, owner)?;
                let conductor = if ps.has("reflectance") {
                    let r = self.spectrum_or(
                        ps,
                        "reflectance",
                        SpectrumUse::Albedo,
                        Rgb::WHITE,
                        owner,
                    )?;
                    ps.lookup("eta");
                    ps.lookup("k");
                    MaterialDesc::Conductor(ConductorDesc::Reflectance(r))
                } else {
                    let cu_eta = metal_spectrum("metal-Cu-eta").expect("built-in table");
                    let cu_k = metal_spectrum("metal-Cu-k").expect("built-in table");
                    MaterialDesc::Conductor(ConductorDesc::EtaK {
                        eta: self.spectrum_or(ps, "eta", SpectrumUse::Unbounded, cu_eta, owner)?,
                        k: self.spectrum_or(ps, "k", SpectrumUse::Unbounded, cu_k, owner)?,
                    })
                };
                match (alpha, conductor) {
                    (Alpha::Smooth, c) => c,
                    (Alpha::Constant(alpha_u, alpha_v), MaterialDesc::Conductor(conductor)) => {
                        MaterialDesc::RoughConductor {
                            conductor,
                            alpha_u,
                            alpha_v,
                        }
                    }
                    (Alpha::Textured(roughness), MaterialDesc::Conductor(conductor)) => {
                        MaterialDesc::Textured(TexturedMaterialDesc::RoughConductor {
                            conductor,
                            roughness,
                        })
                    }
                    (_, _) => unreachable!("conductors build a Conductor desc"),
                }
            }
            "interface" | "" | "none" => MaterialDesc::Interface,
            _ if FALLBACK_TYPES.contains(&ty) => {
                ps.mark_all_used();
                self.warn(loc, format!("{owner}: material type \"{ty}\" is not supported; rendered as diffuse with reflectance 0.5"));
                MaterialDesc::Diffuse {
                    reflectance: Rgb::splat(0.5),
                }
            }
            _ => {
                return Err(SceneError::at(
                    loc,
                    format!("unknown material type \"{ty}\""),
                ));
            }
        })
    }

    /// The microfacet alphas (u, v) of a dielectric or conductor: smooth when both
    /// are the constant zero. pbrt-v4: `roughness` stands for `uroughness` and
    /// `vroughness` where they are absent; `remaproughness` (default true) turns each
    /// roughness into alpha = sqrt(roughness). Any textured roughness keeps all three
    /// as written, for the renderer to remap per hit.
    fn microfacet_alpha(
        &mut self,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<Alpha, SceneError> {
        let remap = ps.bool("remaproughness", true)?;
        let read = |p: &mut Parser, name: &str| -> Result<Option<FloatParam>, SceneError> {
            if !ps.has(name) {
                return Ok(None);
            }
            let r = p.float_texture_param(ps, name, 0.0)?;
            if let TexturedParam::Constant(v) = r
                && v < 0.0
            {
                return Err(SceneError::at(
                    &ps.lookup(name).expect("present").loc,
                    format!("\"{name}\" {v} must be finite and >= 0"),
                ));
            }
            Ok(Some(r))
        };
        let both = read(self, "roughness")?.unwrap_or(TexturedParam::Constant(0.0));
        let u = read(self, "uroughness")?.unwrap_or(both);
        let v = read(self, "vroughness")?.unwrap_or(both);
        let roughness = RoughnessDesc { u, v, remap };
        let (alpha_u, alpha_v) = match (u, v) {
            (TexturedParam::Constant(u), TexturedParam::Constant(v)) => roughness.alphas(u, v),
            _ => return Ok(Alpha::Textured(roughness)),
        };
        if alpha_u == 0.0 && alpha_v == 0.0 {
            return Ok(Alpha::Smooth);
        }
        if alpha_u != alpha_v {
            self.warn(
                loc,
                format!(
                    "{owner}: anisotropic roughness is oriented along an arbitrary tangent of the shading normal, not the surface's u direction"
                ),
            );
        }
        Ok(Alpha::Constant(alpha_u, alpha_v))
    }

    fn dielectric_eta(&mut self, ps: &ParamSet, owner: &str) -> Result<f32, SceneError> {
        let Some(p) = ps.lookup("eta") else {
            return Ok(1.5);
        };
        let loc = p.loc.clone();
        let eta = match &p.value {
            ParamValue::Float(v) if v.len() == 1 => v[0],
            ParamValue::SpectrumNamed(v) if v.len() == 1 => {
                let eta = glass_eta(&v[0])
                    .ok_or_else(|| SceneError::at(&loc, format!("unknown glass \"{}\"", v[0])))?;
                self.warn(
                    &loc,
                    format!(
                        "{owner}: \"{}\" rendered without dispersion, eta = {eta}",
                        v[0]
                    ),
                );
                eta
            }
            ParamValue::SpectrumSamples(v) => {
                let pairs = pairs_from_flat(v).ok_or_else(|| {
                    SceneError::at(
                        &loc,
                        "spectrum \"eta\" needs finite (wavelength, value) pairs",
                    )
                })?;
                let eta = interpolate(&pairs, D_LINE_NM) as f32;
                self.warn(
                    &loc,
                    format!(
                        "{owner}: spectral eta rendered without dispersion, eta = {eta} (587.6 nm)"
                    ),
                );
                eta
            }
            ParamValue::Texture(_) => {
                self.warn(
                    &loc,
                    format!("{owner}: a texture for \"eta\" is not supported; eta = 1.5"),
                );
                1.5
            }
            other => {
                return Err(SceneError::at(
                    &loc,
                    format!(
                        "parameter \"eta\" has type \"{}\" or the wrong count; expected one float or a spectrum",
                        other.type_name()
                    ),
                ));
            }
        };
        if !(eta.is_finite() && eta > 0.0) {
            return Err(SceneError::at(&loc, format!("eta {eta} must be positive")));
        }
        Ok(eta)
    }
}

/// A microfacet material's roughness as read.
enum Alpha {
    Smooth,
    /// Alphas (u, v), already remapped.
    Constant(f32, f32),
    Textured(RoughnessDesc),
}
