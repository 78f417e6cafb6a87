//! Textures evaluated at a shading point: float and spectrum textures of the scene
//! (one closed set, see [`radiant_scene::TextureKind`]), their mappings, image
//! pyramids and filters, and the step from a textured material description to the
//! concrete [`Material`] at a hit.
//!
//! Float textures are evaluated as grey RGB and read through their first channel,
//! which for an RGB image is its red channel, as pbrt-v4 reads float image textures.

pub mod bench;
pub mod filter;
pub mod image;
pub mod mapping;
pub mod noise;
pub mod procedural;

use std::sync::Arc;

use glam::{Vec2, Vec3};
use radiant_math::color::Rgb;
use radiant_scene::{
    FloatParam, MaterialDesc, SceneDesc, SceneError, SpectrumParam, TextureKind,
    TexturedMaterialDesc, TexturedParam,
};

use crate::material::Material;
use crate::world::SurfaceHit;
use filter::Footprint;
use image::{ImageCache, MipMap};

/// What a texture sees of a shading point: position and normal (render space), the
/// surface's (u, v), and how position and (u, v) change from one pixel to the next in
/// x and y. Zero derivatives mean a point lookup (the finest level).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TextureEvalContext {
    pub p: Vec3,
    pub dpdx: Vec3,
    pub dpdy: Vec3,
    pub n: Vec3,
    pub uv: Vec2,
    pub dudx: f32,
    pub dudy: f32,
    pub dvdx: f32,
    pub dvdy: f32,
}

impl TextureEvalContext {
    /// The context of a hit, (u, v) derivatives from its position derivatives: the
    /// least-squares solution of dp = ∂p/∂u du + ∂p/∂v dv (exact when dp lies in the
    /// tangent plane, as the footprint's projection puts it).
    pub fn from_hit(hit: &SurfaceHit) -> TextureEvalContext {
        let (a, b) = (hit.dpdu, hit.dpdv);
        let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
        let det = aa * bb - ab * ab;
        let solve = |d: Vec3| {
            if !(det.abs() > 1e-20 && det.is_finite()) || d == Vec3::ZERO {
                return (0.0, 0.0);
            }
            let (da, db) = (a.dot(d), b.dot(d));
            let du = (bb * da - ab * db) / det;
            let dv = (aa * db - ab * da) / det;
            if du.is_finite() && dv.is_finite() {
                (du, dv)
            } else {
                (0.0, 0.0)
            }
        };
        let (dudx, dvdx) = solve(hit.dpdx);
        let (dudy, dvdy) = solve(hit.dpdy);
        TextureEvalContext {
            p: hit.p,
            dpdx: hit.dpdx,
            dpdy: hit.dpdy,
            n: hit.ns,
            uv: hit.uv,
            dudx,
            dudy,
            dvdx,
            dvdy,
        }
    }

    /// A point lookup at (u, v) (no footprint), for tests and averages.
    pub fn at_uv(uv: Vec2) -> TextureEvalContext {
        TextureEvalContext {
            uv,
            n: Vec3::Z,
            ..TextureEvalContext::default()
        }
    }
}

/// The scene's textures ready to evaluate: the descriptions and, for image maps, the
/// shared pyramid.
#[derive(Clone, Debug, Default)]
pub struct TextureSet {
    kinds: Vec<TextureKind>,
    images: Vec<Option<Arc<MipMap>>>,
}

impl TextureSet {
    /// Reads every image map's file (once per file and encoding). Errors name the
    /// texture's directive.
    pub fn build(desc: &SceneDesc) -> Result<TextureSet, SceneError> {
        let mut cache = ImageCache::default();
        let mut images = Vec::with_capacity(desc.textures.len());
        for t in &desc.textures {
            images.push(match &t.kind {
                TextureKind::ImageMap { image, .. } => {
                    Some(cache.get(&image.filename, image.encoding).map_err(|e| {
                        SceneError::at(&t.loc, format!("Texture \"{}\": {e}", t.name))
                    })?)
                }
                _ => None,
            });
        }
        Ok(TextureSet {
            kinds: desc.textures.iter().map(|t| t.kind.clone()).collect(),
            images,
        })
    }

    pub fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    pub fn spectrum(&self, p: SpectrumParam, ctx: &TextureEvalContext) -> Rgb {
        match p {
            TexturedParam::Constant(c) => c,
            TexturedParam::Texture(id) => self.eval(id, ctx),
        }
    }

    pub fn float(&self, p: FloatParam, ctx: &TextureEvalContext) -> f32 {
        match p {
            TexturedParam::Constant(v) => v,
            TexturedParam::Texture(id) => self.eval(id, ctx).r,
        }
    }

    /// Texture `id` at `ctx`. Textures refer only to textures defined before them, so
    /// the recursion ends.
    pub fn eval(&self, id: u32, ctx: &TextureEvalContext) -> Rgb {
        let mix = |a: SpectrumParam, b: SpectrumParam, w: f32| {
            // Skip the operand whose weight is zero (it may be costly, an image).
            if w <= 0.0 {
                self.spectrum(a, ctx)
            } else if w >= 1.0 {
                self.spectrum(b, ctx)
            } else {
                self.spectrum(a, ctx) * (1.0 - w) + self.spectrum(b, ctx) * w
            }
        };
        match &self.kinds[id as usize] {
            TextureKind::Constant(c) => *c,
            TextureKind::Scale { tex, scale } => {
                let s = self.float(*scale, ctx);
                if s == 0.0 {
                    Rgb::BLACK
                } else {
                    self.spectrum(*tex, ctx) * s
                }
            }
            TextureKind::Mix { tex1, tex2, amount } => mix(*tex1, *tex2, self.float(*amount, ctx)),
            TextureKind::DirectionMix { tex1, tex2, dir } => {
                let a = ctx.n.normalize_or_zero().dot(*dir).abs();
                mix(*tex2, *tex1, a)
            }
            TextureKind::Checkerboard2D {
                mapping: m,
                tex1,
                tex2,
            } => mix(
                *tex1,
                *tex2,
                procedural::checkerboard_2d_weight(&mapping::map_2d(m, ctx)),
            ),
            TextureKind::Checkerboard3D {
                mapping: m,
                tex1,
                tex2,
            } => mix(
                *tex1,
                *tex2,
                procedural::checkerboard_3d_weight(&mapping::map_3d(m, ctx)),
            ),
            TextureKind::Bilerp {
                mapping: m,
                v00,
                v01,
                v10,
                v11,
            } => procedural::bilerp(mapping::map_2d(m, ctx).st, *v00, *v01, *v10, *v11),
            TextureKind::Dots {
                mapping: m,
                inside,
                outside,
            } => {
                if procedural::inside_dot(mapping::map_2d(m, ctx).st) {
                    self.spectrum(*inside, ctx)
                } else {
                    self.spectrum(*outside, ctx)
                }
            }
            TextureKind::Fbm {
                mapping: m,
                octaves,
                roughness,
            } => Rgb::splat(procedural::fbm_value(
                &mapping::map_3d(m, ctx),
                *octaves,
                *roughness,
            )),
            TextureKind::Wrinkled {
                mapping: m,
                octaves,
                roughness,
            } => Rgb::splat(procedural::wrinkled_value(
                &mapping::map_3d(m, ctx),
                *octaves,
                *roughness,
            )),
            TextureKind::Windy { mapping: m } => {
                Rgb::splat(procedural::windy_value(&mapping::map_3d(m, ctx)))
            }
            TextureKind::Marble {
                mapping: m,
                octaves,
                roughness,
                scale,
                variation,
            } => procedural::marble_value(
                &mapping::map_3d(m, ctx),
                *octaves,
                *roughness,
                *scale,
                *variation,
            ),
            TextureKind::ImageMap { mapping: m, image } => {
                let mip = self.images[id as usize]
                    .as_ref()
                    .expect("image maps have their pyramid");
                let c = mapping::map_2d(m, ctx);
                // Images are stored top row first; t grows upwards.
                let st = Vec2::new(c.st.x, 1.0 - c.st.y);
                let fp = Footprint {
                    dst0: Vec2::new(c.dsdx, -c.dtdx),
                    dst1: Vec2::new(c.dsdy, -c.dtdy),
                };
                let v = filter::lookup(mip, image.filter, st, fp, image.max_anisotropy, image.wrap)
                    * image.scale;
                if image.invert {
                    (Rgb::WHITE - v).clamp_min(0.0)
                } else {
                    v
                }
            }
        }
    }

    /// The concrete material of a textured description at `ctx`.
    pub fn material(&self, desc: &TexturedMaterialDesc, ctx: &TextureEvalContext) -> Material {
        concrete_material(desc, |p| self.float(p, ctx), |p| self.spectrum(p, ctx))
    }

    /// The mean of a float parameter over the (u, v) square, as
    /// [`uv_average`](Self::uv_average).
    pub fn uv_average_float(&self, p: FloatParam, n: u32) -> f32 {
        match p {
            TexturedParam::Constant(v) => v,
            TexturedParam::Texture(id) => self.uv_average(TexturedParam::Texture(id), n).r,
        }
    }

    /// The mean of a spectrum parameter over the (u, v) square, from an n × n grid of
    /// point lookups at cell centres (for radiosity, whose patches carry one
    /// reflectance, and for the representative material of a textured one).
    pub fn uv_average(&self, p: SpectrumParam, n: u32) -> Rgb {
        if let TexturedParam::Constant(c) = p {
            return c;
        }
        let mut sum = Rgb::BLACK;
        for j in 0..n {
            for i in 0..n {
                let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                sum += self.spectrum(p, &TextureEvalContext::at_uv(uv));
            }
        }
        sum / (n * n) as f32
    }
}

/// Builds the plain material a textured description stands for once its parameters
/// have values.
pub fn concrete_material(
    desc: &TexturedMaterialDesc,
    float: impl Fn(FloatParam) -> f32,
    spectrum: impl Fn(SpectrumParam) -> Rgb,
) -> Material {
    let plain = match desc {
        TexturedMaterialDesc::Diffuse { reflectance } => MaterialDesc::Diffuse {
            reflectance: spectrum(*reflectance),
        },
        TexturedMaterialDesc::RoughDielectric { eta, roughness } => {
            let (alpha_u, alpha_v) = roughness.alphas(float(roughness.u), float(roughness.v));
            MaterialDesc::RoughDielectric {
                eta: *eta,
                alpha_u,
                alpha_v,
            }
        }
        TexturedMaterialDesc::RoughConductor {
            conductor,
            roughness,
        } => {
            let (alpha_u, alpha_v) = roughness.alphas(float(roughness.u), float(roughness.v));
            MaterialDesc::RoughConductor {
                conductor: conductor.concrete(&spectrum),
                alpha_u,
                alpha_v,
            }
        }
        TexturedMaterialDesc::DiffuseTransmission {
            reflectance,
            transmittance,
            scale,
        } => MaterialDesc::DiffuseTransmission {
            reflectance: spectrum(*reflectance) * *scale,
            transmittance: spectrum(*transmittance) * *scale,
        },
        TexturedMaterialDesc::CoatedDiffuse { reflectance, coat } => MaterialDesc::CoatedDiffuse {
            reflectance: spectrum(*reflectance),
            coat: coat.concrete(&float, &spectrum),
        },
        TexturedMaterialDesc::CoatedConductor {
            conductor,
            roughness,
            coat,
        } => {
            let (alpha_u, alpha_v) = roughness.alphas(float(roughness.u), float(roughness.v));
            MaterialDesc::CoatedConductor {
                conductor: conductor.concrete(&spectrum),
                alpha_u,
                alpha_v,
                coat: coat.concrete(&float, &spectrum),
            }
        }
    };
    Material::from_desc(&plain)
}
