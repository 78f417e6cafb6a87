//! `Material`, `MakeNamedMaterial`, `NamedMaterial` and `Texture`.
//!
//! - `"diffuse"`: `reflectance` (spectrum or spectrum texture, default 0.5).
//! - `"dielectric"`: `eta` (float or spectrum; default 1.5; named glasses become their
//!   d-line index).
//! - `"conductor"`: `reflectance` (an artist's mirror colour), else `eta` and `k`
//!   (spectra; default copper, `metal-Cu-eta` / `metal-Cu-k`).
//! - `"thindielectric"`: `eta` as for `dielectric` (default 1.5).
//! - `"diffusetransmission"`: `reflectance` and `transmittance` (spectra or spectrum
//!   textures, default 0.25), both multiplied by `scale` (float, default 1).
//! - `"mix"`: `materials` (two named materials, defined before the mix) and `amount`
//!   (float or float texture, default 0.5): the probability of the second material at
//!   a hit.
//! - `"interface"` (also `""`, `"none"`): no surface.
//! - `dielectric` and `conductor` take pbrt-v4's microfacet roughness: `roughness`
//!   (default 0) sets both `uroughness` and `vroughness` unless they are given, and
//!   `remaproughness` (default true) maps each to the Trowbridge–Reitz alpha as
//!   alpha = sqrt(roughness); with it false the values are alphas already. Any
//!   non-zero alpha gives `RoughDielectric` / `RoughConductor` (the renderer keeps
//!   alphas below its smooth threshold a delta BSDF). Roughness may be a float
//!   texture.
//! - `"coateddiffuse"`: a dielectric coat over a Lambertian base: `reflectance`
//!   (0.5, or a spectrum texture), the coat's `roughness` / `uroughness` / `vroughness` (0) and
//!   `remaproughness` as above, `eta` (1.5, as for `dielectric`), and the slab between:
//!   `thickness` (0.01), medium `albedo` (0) and Henyey–Greenstein `g` (0), random
//!   walk `maxdepth` (10) and `nsamples` (1).
//! - `"coatedconductor"`: the same coat and slab parameters prefixed `interface.`
//!   (`interface.roughness`, `interface.eta`, ...; `thickness`, `albedo`, `g`,
//!   `maxdepth`, `nsamples` without prefix) over a conductor read as `conductor`
//!   reads it, its parameters prefixed `conductor.` (`conductor.eta` / `conductor.k`,
//!   default copper, or `reflectance`; `conductor.roughness`, ...).
//! - Textures may give the layered materials' roughnesses, `thickness`, `albedo` and
//!   `g`, and a conductor's `reflectance`, `eta` and `k`.
//! - Any material takes `displacement` (a float texture: bump mapping) or
//!   `normalmap` (an image file, relative to the scene file); see
//!   [`crate::ShadingNormalDesc`].
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
use crate::texture::{
    FloatParam, RoughnessDesc, ShadingNormalDesc, TexturedCoatDesc, TexturedConductorDesc,
    TexturedMaterialDesc, TexturedParam,
};
use radiant_math::color::Rgb;

/// pbrt-v4's material types that radiant replaces by diffuse 0.5.
const FALLBACK_TYPES: [&str; 3] = ["hair", "measured", "subsurface"];

/// The d line (nm), where glass catalogues quote their index.
const D_LINE_NM: f64 = 587.6;

impl Parser {
    /// `Material "type" params`: an anonymous material that becomes current.
    pub(super) fn material(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (ty, _) = self.string_arg("Material")?;
        let ps = with_defaults(self.param_list()?, &self.gs.defaults.material);
        self.require_world("Material", loc)?;
        let owner = format!("Material \"{ty}\"");
        let normal = self.shading_normal_param(&ps)?;
        let m = self.build_material(&ty, &ps, loc, &owner)?;
        self.report_unused(&ps, &owner);
        let id = self.push_material(m);
        self.set_shading_normal(id, normal);
        self.gs.material = Some(id);
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
        let normal = self.shading_normal_param(&ps)?;
        let m = self.build_material(&ty, &ps, loc, &owner)?;
        self.report_unused(&ps, &owner);
        let id = self.push_material(m);
        self.set_shading_normal(id, normal);
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

    /// `normalmap` (an image file) or `displacement` (a float texture; a constant
    /// displacement moves the surface without tilting it, so it is dropped). A normal
    /// map wins over a displacement, as in pbrt-v4.
    fn shading_normal_param(
        &mut self,
        ps: &ParamSet,
    ) -> Result<Option<ShadingNormalDesc>, SceneError> {
        let displacement = self.float_texture_param(ps, "displacement", 0.0)?;
        if let Some((names, at)) = ps.strings("normalmap")? {
            let [written] = names else {
                return Err(SceneError::at(at, "\"string normalmap\" needs one value"));
            };
            if written.is_empty() {
                return Ok(None);
            }
            let at = at.clone();
            let filename = self.resolve_path(written);
            if let Some(why) = super::not_a_file(&filename) {
                return Err(SceneError::at(
                    &at,
                    format!("normal map '{}' {why}", filename.display()),
                ));
            }
            return Ok(Some(ShadingNormalDesc::NormalMap { filename }));
        }
        Ok(match displacement {
            TexturedParam::Texture(displacement) => Some(ShadingNormalDesc::Bump { displacement }),
            TexturedParam::Constant(_) => None,
        })
    }

    fn set_shading_normal(&mut self, id: MaterialId, normal: Option<ShadingNormalDesc>) {
        if normal.is_none() {
            return;
        }
        let i = id as usize;
        if self.shading_normals.len() <= i {
            self.shading_normals.resize(i + 1, None);
        }
        self.shading_normals[i] = normal;
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
                let alpha = self.microfacet_alpha(ps, "")?;
                let eta = self.dielectric_eta(ps, "eta", owner)?;
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
                let alpha = self.microfacet_alpha(ps, "")?;
                let conductor = self.conductor_desc(ps, "")?;
                match (alpha, constant_conductor(&conductor)) {
                    (Alpha::Smooth, Some(conductor)) => MaterialDesc::Conductor(conductor),
                    (Alpha::Constant(alpha_u, alpha_v), Some(conductor)) => {
                        MaterialDesc::RoughConductor {
                            conductor,
                            alpha_u,
                            alpha_v,
                        }
                    }
                    (alpha, _) => MaterialDesc::Textured(TexturedMaterialDesc::RoughConductor {
                        conductor,
                        roughness: alpha.roughness(),
                    }),
                }
            }
            "coateddiffuse" => {
                let reflectance = self.spectrum_texture_param(
                    ps,
                    "reflectance",
                    SpectrumUse::Albedo,
                    Rgb::splat(0.5),
                )?;
                let coat = self.coat_desc(ps, "", loc, owner)?;
                match (reflectance, coat.constant()) {
                    (TexturedParam::Constant(reflectance), Some(coat)) => {
                        MaterialDesc::CoatedDiffuse { reflectance, coat }
                    }
                    (reflectance, _) => {
                        MaterialDesc::Textured(TexturedMaterialDesc::CoatedDiffuse {
                            reflectance,
                            coat,
                        })
                    }
                }
            }
            "coatedconductor" => {
                let coat = self.coat_desc(ps, "interface.", loc, owner)?;
                let roughness = self.microfacet_alpha(ps, "conductor.")?.roughness();
                let conductor = self.conductor_desc(ps, "conductor.")?;
                let alphas = match (roughness.u, roughness.v) {
                    (TexturedParam::Constant(u), TexturedParam::Constant(v)) => {
                        Some(roughness.alphas(u, v))
                    }
                    _ => None,
                };
                match (alphas, constant_conductor(&conductor), coat.constant()) {
                    (Some((alpha_u, alpha_v)), Some(conductor), Some(coat)) => {
                        MaterialDesc::CoatedConductor {
                            conductor,
                            alpha_u,
                            alpha_v,
                            coat,
                        }
                    }
                    _ => MaterialDesc::Textured(TexturedMaterialDesc::CoatedConductor {
                        conductor,
                        roughness,
                        coat,
                    }),
                }
            }
            "thindielectric" => MaterialDesc::ThinDielectric {
                eta: self.dielectric_eta(ps, "eta", owner)?,
            },
            "diffusetransmission" => {
                let quarter = Rgb::splat(0.25);
                let r =
                    self.spectrum_texture_param(ps, "reflectance", SpectrumUse::Albedo, quarter)?;
                let t =
                    self.spectrum_texture_param(ps, "transmittance", SpectrumUse::Albedo, quarter)?;
                let scale = ps.finite_float("scale", 1.0)?;
                match (r, t) {
                    (TexturedParam::Constant(r), TexturedParam::Constant(t)) => {
                        MaterialDesc::DiffuseTransmission {
                            reflectance: r * scale,
                            transmittance: t * scale,
                        }
                    }
                    (reflectance, transmittance) => {
                        MaterialDesc::Textured(TexturedMaterialDesc::DiffuseTransmission {
                            reflectance,
                            transmittance,
                            scale,
                        })
                    }
                }
            }
            "mix" => self.mix_material(ps, loc, owner)?,
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

    /// `mix`: the two named materials (which must be defined already, as the file is
    /// read in order) and the probability `amount` of the second.
    fn mix_material(
        &mut self,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<MaterialDesc, SceneError> {
        let materials = match ps.strings("materials")? {
            Some(([a, b], at)) => {
                let at = at.clone();
                let mut id = |name: &str| match self.named_materials.get(name) {
                    Some(&id) => Ok(id),
                    None if name.is_empty() || name == "none" => {
                        Ok(self.push_material(MaterialDesc::Interface))
                    }
                    None => Err(SceneError::at(
                        &at,
                        format!("{owner}: unknown named material \"{name}\" in \"materials\""),
                    )),
                };
                [id(a)?, id(b)?]
            }
            Some((_, at)) => {
                return Err(SceneError::at(
                    at,
                    format!("{owner}: \"string materials\" needs two names"),
                ));
            }
            None => {
                return Err(SceneError::at(
                    loc,
                    format!("{owner} needs \"string materials\" with two names"),
                ));
            }
        };
        let amount = self.float_texture_param(ps, "amount", 0.5)?;
        Ok(MaterialDesc::Mix { materials, amount })
    }

    /// A conductor's `reflectance`, else its `eta` and `k` (default copper), these
    /// two named with `prefix` (pbrt-v4 names a coated conductor's colour
    /// `reflectance`, its index `conductor.eta`); each may be a spectrum texture.
    fn conductor_desc(
        &mut self,
        ps: &ParamSet,
        prefix: &str,
    ) -> Result<TexturedConductorDesc, SceneError> {
        let name = |n: &str| format!("{prefix}{n}");
        if ps.has("reflectance") {
            let r =
                self.spectrum_texture_param(ps, "reflectance", SpectrumUse::Albedo, Rgb::WHITE)?;
            ps.lookup(&name("eta"));
            ps.lookup(&name("k"));
            return Ok(TexturedConductorDesc::Reflectance(r));
        }
        let cu_eta = metal_spectrum("metal-Cu-eta").expect("built-in table");
        let cu_k = metal_spectrum("metal-Cu-k").expect("built-in table");
        Ok(TexturedConductorDesc::EtaK {
            eta: self.spectrum_texture_param(ps, &name("eta"), SpectrumUse::Unbounded, cu_eta)?,
            k: self.spectrum_texture_param(ps, &name("k"), SpectrumUse::Unbounded, cu_k)?,
        })
    }

    /// The coat (roughness and index named with `prefix`) and slab of a layered
    /// material, with pbrt-v4's defaults; roughness, `thickness`, `albedo` and `g` may
    /// be textures (constant values are checked here).
    fn coat_desc(
        &mut self,
        ps: &ParamSet,
        prefix: &str,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<TexturedCoatDesc, SceneError> {
        let roughness = self.microfacet_alpha(ps, prefix)?.roughness();
        let eta = self.dielectric_eta(ps, &format!("{prefix}eta"), owner)?;
        let thickness = self.float_texture_param(ps, "thickness", 0.01)?;
        if let TexturedParam::Constant(thickness) = thickness
            && thickness <= 0.0
        {
            let at = ps
                .lookup("thickness")
                .map_or(loc.clone(), |p| p.loc.clone());
            return Err(SceneError::at(
                &at,
                format!("\"thickness\" {thickness} must be positive"),
            ));
        }
        let g = self.float_texture_param(ps, "g", 0.0)?;
        if let TexturedParam::Constant(g) = g
            && !(g > -1.0 && g < 1.0)
        {
            let at = ps.lookup("g").map_or(loc.clone(), |p| p.loc.clone());
            return Err(SceneError::at(
                &at,
                format!("\"g\" {g} must lie in (-1, 1)"),
            ));
        }
        let albedo = self.spectrum_texture_param(ps, "albedo", SpectrumUse::Albedo, Rgb::BLACK)?;
        let max_depth = ps.count("maxdepth", 10)?;
        let samples = ps.count("nsamples", 1)?;
        for (name, v) in [("maxdepth", max_depth), ("nsamples", samples)] {
            if v == 0 || v > u16::MAX as u32 {
                let at = ps.lookup(name).map_or(loc.clone(), |p| p.loc.clone());
                return Err(SceneError::at(
                    &at,
                    format!("\"{name}\" {v} must lie in 1..=65535"),
                ));
            }
        }
        Ok(TexturedCoatDesc {
            eta,
            roughness,
            thickness,
            albedo,
            g,
            max_depth,
            samples,
        })
    }

    /// The microfacet alphas (u, v) of a dielectric or conductor: smooth when both
    /// are the constant zero. pbrt-v4: `roughness` stands for `uroughness` and
    /// `vroughness` where they are absent; `remaproughness` (default true) turns each
    /// roughness into alpha = sqrt(roughness). Any textured roughness keeps all three
    /// as written, for the renderer to remap per hit. Each name but `remaproughness`
    /// carries `prefix` (`interface.`, `conductor.` for the layered materials).
    fn microfacet_alpha(&mut self, ps: &ParamSet, prefix: &str) -> Result<Alpha, SceneError> {
        let remap = ps.bool("remaproughness", true)?;
        let read = |p: &mut Parser, name: &str| -> Result<Option<FloatParam>, SceneError> {
            let name = &format!("{prefix}{name}");
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
        Ok(Alpha::Constant(alpha_u, alpha_v))
    }

    fn dielectric_eta(
        &mut self,
        ps: &ParamSet,
        name: &str,
        owner: &str,
    ) -> Result<f32, SceneError> {
        let Some(p) = ps.lookup(name) else {
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
                        format!("spectrum \"{name}\" needs finite (wavelength, value) pairs"),
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
                    format!("{owner}: textures are not supported; eta = 1.5"),
                );
                1.5
            }
            other => {
                return Err(SceneError::at(
                    &loc,
                    format!(
                        "parameter \"{name}\" has type \"{}\" or the wrong count; expected one float or a spectrum",
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

impl Alpha {
    /// The roughness as a (possibly textured) description; constants as alphas.
    fn roughness(self) -> RoughnessDesc {
        let alphas = |u: f32, v: f32| RoughnessDesc {
            u: TexturedParam::Constant(u),
            v: TexturedParam::Constant(v),
            remap: false,
        };
        match self {
            Alpha::Smooth => alphas(0.0, 0.0),
            Alpha::Constant(u, v) => alphas(u, v),
            Alpha::Textured(r) => r,
        }
    }
}

/// The conductor when none of its parameters is a texture.
fn constant_conductor(c: &TexturedConductorDesc) -> Option<ConductorDesc> {
    match *c {
        TexturedConductorDesc::Reflectance(r) => Some(ConductorDesc::Reflectance(r.constant()?)),
        TexturedConductorDesc::EtaK { eta, k } => Some(ConductorDesc::EtaK {
            eta: eta.constant()?,
            k: k.constant()?,
        }),
    }
}
