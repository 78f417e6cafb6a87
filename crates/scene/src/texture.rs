//! Textures as the scene describes them (pbrt-v4's `Texture` directive) and the
//! texture-valued material parameters that refer to them.
//!
//! A texture is plain data: its class with the parameters it was given, operands that
//! are constants or other textures (by index into [`crate::SceneDesc::textures`]), and
//! a mapping from the shading point to texture coordinates. Evaluation lives in the
//! renderer. Float and spectrum textures share one enum; a float texture's values are
//! grey (all channels equal) so that one evaluator serves both.

use std::path::PathBuf;

use glam::Vec3;

use crate::desc::{CoatDesc, ConductorDesc};
use crate::error::FileLoc;
use radiant_math::Transform;
use radiant_math::color::Rgb;

/// Index into `SceneDesc::textures`.
pub type TextureId = u32;

/// The two texture namespaces of pbrt-v4: a parameter takes one or the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureType {
    Float,
    Spectrum,
}

impl TextureType {
    pub fn name(self) -> &'static str {
        match self {
            TextureType::Float => "float",
            TextureType::Spectrum => "spectrum",
        }
    }
}

/// A parameter that is either a constant or the value of a texture at the hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TexturedParam<T> {
    Constant(T),
    Texture(TextureId),
}

impl<T: Copy> TexturedParam<T> {
    /// The constant, `None` for a texture.
    pub fn constant(&self) -> Option<T> {
        match self {
            TexturedParam::Constant(v) => Some(*v),
            TexturedParam::Texture(_) => None,
        }
    }
}

/// A float parameter or float texture.
pub type FloatParam = TexturedParam<f32>;
/// A spectrum parameter (as RGB) or spectrum texture.
pub type SpectrumParam = TexturedParam<Rgb>;

/// One `Texture "name" "float"|"spectrum" "class" …`.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureDesc {
    pub name: String,
    pub ty: TextureType,
    pub kind: TextureKind,
    pub loc: FileLoc,
}

/// How a shading point becomes 2D texture coordinates (s, t).
#[derive(Clone, Debug, PartialEq)]
pub enum Mapping2D {
    /// The surface's (u, v): s = su u + du, t = sv v + dv.
    Uv { su: f32, sv: f32, du: f32, dv: f32 },
    /// Spherical angles about the texture-space origin: s = θ/π, t = φ/2π.
    Spherical { texture_from_render: Transform },
    /// Cylinder about the texture-space z axis: s = (π + atan2(y, x)) / 2π, t = z.
    Cylindrical { texture_from_render: Transform },
    /// Projection onto two texture-space vectors: s = ds + p·vs, t = dt + p·vt.
    Planar {
        texture_from_render: Transform,
        vs: Vec3,
        vt: Vec3,
        ds: f32,
        dt: f32,
    },
}

/// Solid textures read the shading point in texture space.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapping3D {
    pub texture_from_render: Transform,
}

/// pbrt-v4's `filter` of `imagemap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFilter {
    Point,
    Bilinear,
    Trilinear,
    Ewa,
}

/// Lookups outside [0, 1]²: pbrt-v4's `wrap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WrapMode {
    Repeat,
    Black,
    Clamp,
    /// The equal-area octahedral square: crossing an edge mirrors about its midpoint.
    OctahedralSphere,
}

/// How stored 8-bit values map to linear ones (`encoding`); float images are linear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorEncoding {
    Linear,
    Srgb,
    /// value = encoded^gamma.
    Gamma(f32),
}

/// An `imagemap` texture's image and how it is read.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageMapDesc {
    /// Resolved against the scene file's folder.
    pub filename: PathBuf,
    pub filter: ImageFilter,
    pub wrap: WrapMode,
    pub scale: f32,
    pub invert: bool,
    /// `None`: the file's own (sRGB for 8-bit images, linear for float ones).
    pub encoding: Option<ColorEncoding>,
    /// Longest over shortest axis of the EWA ellipse; longer ones are widened.
    pub max_anisotropy: f32,
}

/// The closed set of texture classes. Operands are spectrum-valued for spectrum
/// textures and grey for float textures.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureKind {
    /// `value`.
    Constant(Rgb),
    /// `tex * scale`.
    Scale {
        tex: SpectrumParam,
        scale: FloatParam,
    },
    /// `(1 − amount) tex1 + amount tex2`.
    Mix {
        tex1: SpectrumParam,
        tex2: SpectrumParam,
        amount: FloatParam,
    },
    /// Mix by the shading normal's alignment with `dir` (render space, unit):
    /// `a tex1 + (1 − a) tex2`, a = |n·dir|.
    DirectionMix {
        tex1: SpectrumParam,
        tex2: SpectrumParam,
        dir: Vec3,
    },
    /// Alternating `tex1` / `tex2` on unit squares of (s, t).
    Checkerboard2D {
        mapping: Mapping2D,
        tex1: SpectrumParam,
        tex2: SpectrumParam,
    },
    /// Alternating `tex1` / `tex2` on unit cubes of texture space.
    Checkerboard3D {
        mapping: Mapping3D,
        tex1: SpectrumParam,
        tex2: SpectrumParam,
    },
    /// Bilinear interpolation of four corner values over (s, t) ∈ [0, 1]².
    Bilerp {
        mapping: Mapping2D,
        v00: Rgb,
        v01: Rgb,
        v10: Rgb,
        v11: Rgb,
    },
    /// Polka dots of noise-jittered position and radius, one per (s, t) cell.
    Dots {
        mapping: Mapping2D,
        inside: SpectrumParam,
        outside: SpectrumParam,
    },
    /// Fractional Brownian motion of Perlin noise.
    Fbm {
        mapping: Mapping3D,
        octaves: u32,
        roughness: f32,
    },
    /// Turbulence: fBm of |noise|.
    Wrinkled {
        mapping: Mapping3D,
        octaves: u32,
        roughness: f32,
    },
    /// Wind-swept waves: turbulence scaled by a low-frequency fBm.
    Windy { mapping: Mapping3D },
    /// A sine of turbulence-displaced height looked up in a marble colour ramp.
    Marble {
        mapping: Mapping3D,
        octaves: u32,
        roughness: f32,
        scale: f32,
        variation: f32,
    },
    ImageMap {
        mapping: Mapping2D,
        image: ImageMapDesc,
    },
}

/// A material with at least one texture-valued parameter: the renderer evaluates the
/// textures at each hit and builds the concrete BSDF there. Materials whose
/// parameters are all constant stay in the plain [`crate::MaterialDesc`] variants.
#[derive(Clone, Debug, PartialEq)]
pub enum TexturedMaterialDesc {
    /// Lambertian with a textured `reflectance` (clamped to [0, 1] per channel).
    Diffuse { reflectance: SpectrumParam },
    /// Dielectric of index `eta` with textured roughness.
    RoughDielectric { eta: f32, roughness: RoughnessDesc },
    /// Conductor with textured roughness or textured `reflectance` / `eta` / `k`
    /// (a zero roughness is the smooth conductor).
    RoughConductor {
        conductor: TexturedConductorDesc,
        roughness: RoughnessDesc,
    },
    /// `diffusetransmission` with a textured `reflectance` or `transmittance`, each
    /// multiplied by `scale` (then clamped to [0, 1]).
    DiffuseTransmission {
        reflectance: SpectrumParam,
        transmittance: SpectrumParam,
        scale: f32,
    },
    /// `coateddiffuse` with a textured base `reflectance` (clamped to [0, 1]) or
    /// textured coat parameters.
    CoatedDiffuse {
        reflectance: SpectrumParam,
        coat: TexturedCoatDesc,
    },
    /// `coatedconductor` with a textured conductor, conductor roughness or coat.
    CoatedConductor {
        conductor: TexturedConductorDesc,
        roughness: RoughnessDesc,
        coat: TexturedCoatDesc,
    },
}

/// A conductor's colour (`reflectance`) or complex index (`eta`, `k`), each possibly
/// textured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TexturedConductorDesc {
    Reflectance(SpectrumParam),
    EtaK {
        eta: SpectrumParam,
        k: SpectrumParam,
    },
}

impl TexturedConductorDesc {
    /// The conductor once its parameters have values.
    pub fn concrete(&self, spectrum: impl Fn(SpectrumParam) -> Rgb) -> ConductorDesc {
        match *self {
            TexturedConductorDesc::Reflectance(r) => ConductorDesc::Reflectance(spectrum(r)),
            TexturedConductorDesc::EtaK { eta, k } => ConductorDesc::EtaK {
                eta: spectrum(eta),
                k: spectrum(k),
            },
        }
    }
}

/// The coat and slab of a layered material as written: pbrt-v4 lets the coat's
/// roughness, the slab's `thickness`, `albedo` and `g` be textures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexturedCoatDesc {
    pub eta: f32,
    pub roughness: RoughnessDesc,
    pub thickness: FloatParam,
    pub albedo: SpectrumParam,
    pub g: FloatParam,
    pub max_depth: u32,
    pub samples: u32,
}

/// The largest |g| a textured asymmetry is clamped to (Henyey–Greenstein needs |g| < 1).
const MAX_ABS_G: f32 = 0.999;

impl TexturedCoatDesc {
    /// The coat once its parameters have values: albedo clamped to [0, 1], `g` into
    /// (-1, 1), the thickness kept positive (constant values were checked when read).
    pub fn concrete(
        &self,
        float: impl Fn(FloatParam) -> f32,
        spectrum: impl Fn(SpectrumParam) -> Rgb,
    ) -> CoatDesc {
        let (alpha_u, alpha_v) = self
            .roughness
            .alphas(float(self.roughness.u), float(self.roughness.v));
        let thickness = float(self.thickness);
        let g = float(self.g);
        CoatDesc {
            eta: self.eta,
            alpha_u,
            alpha_v,
            thickness: if thickness > f32::MIN_POSITIVE {
                thickness
            } else {
                f32::MIN_POSITIVE
            },
            albedo: spectrum(self.albedo).map(|c| c.clamp(0.0, 1.0)),
            g: if g.is_nan() {
                0.0
            } else {
                g.clamp(-MAX_ABS_G, MAX_ABS_G)
            },
            max_depth: self.max_depth,
            samples: self.samples,
        }
    }

    /// The coat when no parameter is a texture.
    pub fn constant(&self) -> Option<CoatDesc> {
        let textured = [self.roughness.u, self.roughness.v, self.thickness, self.g]
            .iter()
            .any(|p| p.constant().is_none())
            || self.albedo.constant().is_none();
        (!textured).then(|| {
            self.concrete(
                |p| p.constant().unwrap_or(0.0),
                |p| p.constant().unwrap_or(Rgb::BLACK),
            )
        })
    }
}

/// How a material tilts the shading normal before its BSDF is evaluated.
#[derive(Clone, Debug, PartialEq)]
pub enum ShadingNormalDesc {
    /// `displacement`: a float texture read as a height along the shading normal; the
    /// normal is that of the displaced surface, from finite differences in (u, v)
    /// (Blinn 1978, "Simulation of wrinkled surfaces").
    Bump { displacement: TextureId },
    /// `normalmap`: an image (read as linear) whose RGB in [0, 1] encodes a unit normal
    /// in the tangent frame (∂p/∂u, n × ∂p/∂u, n) as 2 RGB − 1, looked up at (u, 1 − v).
    NormalMap { filename: PathBuf },
}

/// Microfacet roughness along the two tangent axes, possibly textured. With
/// `remap` the values are pbrt's roughness and alpha = √roughness; otherwise they are
/// alphas already.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughnessDesc {
    pub u: FloatParam,
    pub v: FloatParam,
    pub remap: bool,
}

impl RoughnessDesc {
    /// The Trowbridge–Reitz alphas for roughness values (u, v).
    pub fn alphas(&self, u: f32, v: f32) -> (f32, f32) {
        let to_alpha = |r: f32| {
            let r = r.max(0.0);
            if self.remap { r.sqrt() } else { r }
        };
        (to_alpha(u), to_alpha(v))
    }
}
