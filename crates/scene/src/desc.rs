//! The scene description: plain data produced by the pbrt parser or by the canonical
//! scenes in code, and consumed by `render` and `radiosity`.
//!
//! Geometry is kept in object space with its `render_from_object` transform (render
//! space = pbrt's world space). Radiometric values are final: light `scale` and `power`
//! have already been folded into `L` / `I`.

use std::path::PathBuf;

use glam::{Vec2, Vec3};

use super::error::{FileLoc, Warning};
use super::params::ParamSet;
use super::texture::{FloatParam, ShadingNormalDesc, TextureDesc, TexturedMaterialDesc};
use radiant_math::Transform;
use radiant_math::color::Rgb;

/// Everything needed to render one image.
#[derive(Clone, Debug)]
pub struct SceneDesc {
    pub camera: CameraDesc,
    pub film: FilmDesc,
    pub sampler: SamplerDesc,
    pub filter: FilterDesc,
    pub integrator: IntegratorDesc,
    pub materials: Vec<MaterialDesc>,
    /// Bump or normal map of material i, at index i; shorter than `materials` when the
    /// last ones have none (read it with [`SceneDesc::shading_normal`]).
    pub shading_normals: Vec<Option<ShadingNormalDesc>>,
    /// Named textures, referred to by index from textured materials and other textures.
    pub textures: Vec<TextureDesc>,
    pub shapes: Vec<ShapeDesc>,
    /// Object prototypes (`ObjectBegin`); their shapes are in instance space.
    pub objects: Vec<ObjectDesc>,
    pub instances: Vec<InstanceDesc>,
    pub lights: Vec<LightDesc>,
    /// Everything read but not supported, and parameters never used.
    pub warnings: Vec<Warning>,
    /// The scene file, when the scene came from one (relative paths resolve from its folder).
    pub source: Option<PathBuf>,
}

impl SceneDesc {
    /// The bump or normal map of material `id`, if it has one.
    pub fn shading_normal(&self, id: MaterialId) -> Option<&ShadingNormalDesc> {
        self.shading_normals.get(id as usize)?.as_ref()
    }
}

/// `Camera`: where it is and how it forms the image.
#[derive(Clone, Debug)]
pub struct CameraDesc {
    /// The current transform at the `Camera` directive.
    pub camera_from_world: Transform,
    pub kind: CameraKind,
    /// `shutterclose` − `shutteropen` (default 1 s): the exposure time of the sensor's
    /// imaging ratio, as in pbrt-v4.
    pub exposure_time: f32,
    pub loc: FileLoc,
}

#[derive(Clone, Debug, PartialEq)]
pub enum CameraKind {
    /// `"perspective"`: `fov` (degrees, spans the shorter image axis), thin-lens depth of
    /// field from `lensradius` and `focaldistance`; `screenwindow` overrides the window.
    Perspective {
        fov_deg: f32,
        lens_radius: f32,
        focal_distance: f32,
        screen_window: Option<[f32; 4]>,
    },
    /// `"orthographic"`: parallel projection through `screenwindow` (default [-1,1] on the
    /// shorter axis).
    Orthographic {
        lens_radius: f32,
        focal_distance: f32,
        screen_window: Option<[f32; 4]>,
    },
    /// `"realistic"`: rays through a lens prescription (Kolb, Mitchell & Hanrahan 1995).
    /// `lens_file` is already resolved against the scene file's folder.
    Realistic {
        lens_file: PathBuf,
        aperture_diameter_mm: f32,
        focus_distance: f32,
    },
}

/// `Film "rgb"`.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmDesc {
    pub xresolution: u32,
    pub yresolution: u32,
    /// Output name from the file; the CLI's `-o` overrides it.
    pub filename: Option<String>,
    /// Film diagonal in mm (used by the realistic camera); pbrt default 35.
    pub diagonal_mm: f32,
    /// Sensor sensitivity; pbrt-v4 scales the image by `iso / 100` for the realistic
    /// camera's physical exposure. Default 100.
    pub iso: f32,
    /// `Film "gbuffer"`: the image is written with its G-buffer channels.
    pub gbuffer: Option<GBufferSpace>,
    /// `maxcomponentvalue`: a sample whose largest CIE XYZ component (as the sensor
    /// records it) is above this is scaled down to it. Infinite by default.
    pub max_component_value: f32,
    /// `whitebalance`: the colour temperature (K) of the CIE daylight illuminant that
    /// is mapped to the output's white (D65); `None`: no white balance.
    pub white_balance: Option<f32>,
    pub loc: FileLoc,
}

/// The space of a G-buffer film's positions and normals (`"string coordinatesystem"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GBufferSpace {
    /// The camera's space (pbrt-v4's default).
    Camera,
    /// Render (world) space.
    World,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    /// Owen-scrambled Sobol (pbrt-v4's `sobol`, `paddedsobol`, `zsobol` and `pmj02bn`
    /// map here: each is a (0,2)-sequence in every dimension pair).
    Sobol,
    /// Independent uniform random numbers.
    Independent,
    /// Per-pixel Halton points: dimension pair k in the prime bases of the 2k-th and
    /// (2k+1)-th primes, each pixel's digits randomised independently.
    Halton { randomization: DigitRandomization },
    /// `x` × `y` jittered strata per pixel (pbrt-v4's `stratified`), each dimension's
    /// strata visited in a per-pixel random order.
    Stratified { x: u32, y: u32, jitter: bool },
}

/// How the digits of a radical inverse are randomised (pbrt-v4's `"randomization"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DigitRandomization {
    /// The plain radical inverse: every pixel sees the same points.
    None,
    /// One random permutation per digit position (Faure 1992; pbrt's `permutedigits`).
    PermuteDigits,
    /// Nested scrambling: each digit's permutation depends on the digits before it
    /// (Owen 1995, "Randomly permuted (t,m,s)-nets and (t,s)-sequences"); pbrt's
    /// `owen` and `fastowen`.
    Owen,
}

/// `Sampler`: kind, samples per pixel and seed.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplerDesc {
    pub kind: SamplerKind,
    pub pixel_samples: u32,
    pub seed: u64,
    pub loc: FileLoc,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterKind {
    Box,
    Triangle,
    /// pbrt-v4's truncated Gaussian with standard deviation `sigma` (pixels).
    Gaussian {
        sigma: f32,
    },
    /// Mitchell & Netravali's cubic with parameters `b` and `c` (pbrt-v4's `B`, `C`).
    Mitchell {
        b: f32,
        c: f32,
    },
    /// pbrt-v4's `"sinc"`: Lanczos' windowed sinc with window `tau`.
    LanczosSinc {
        tau: f32,
    },
}

/// `PixelFilter`: kind and radius in pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterDesc {
    pub kind: FilterKind,
    pub radius: Vec2,
    pub loc: FileLoc,
}

/// `Integrator`: the name and its parameters, which the chosen integrator reads (and
/// whose unused entries it reports) when the render is set up.
#[derive(Clone, Debug)]
pub struct IntegratorDesc {
    pub name: String,
    pub params: ParamSet,
    pub loc: FileLoc,
}

/// Index into `SceneDesc::materials`.
pub type MaterialId = u32;

#[derive(Clone, Debug, PartialEq)]
pub enum MaterialDesc {
    /// Lambertian reflector, `reflectance` in [0,1] per channel.
    Diffuse { reflectance: Rgb },
    /// Smooth dielectric interface with relative index `eta` (inside / outside).
    Dielectric { eta: f32 },
    /// Smooth conductor: a perfect mirror with the given reflectance, or Fresnel
    /// reflection from complex index `eta + i k` per channel.
    Conductor(ConductorDesc),
    /// Rough dielectric (Trowbridge–Reitz microfacets): relative index `eta` and the
    /// distribution's alpha along the surface's two tangent axes (already remapped
    /// from pbrt's `roughness` when `remaproughness` is true).
    RoughDielectric {
        eta: f32,
        alpha_u: f32,
        alpha_v: f32,
    },
    /// Rough conductor (Trowbridge–Reitz microfacets) with the Fresnel term of
    /// `conductor` and alphas as for [`MaterialDesc::RoughDielectric`].
    RoughConductor {
        conductor: ConductorDesc,
        alpha_u: f32,
        alpha_v: f32,
    },
    /// `"thindielectric"`: a sheet of index `eta` and negligible thickness.
    ThinDielectric { eta: f32 },
    /// `"diffusetransmission"`: Lambertian reflection and transmission, `scale`
    /// already applied.
    DiffuseTransmission {
        reflectance: Rgb,
        transmittance: Rgb,
    },
    /// `"mix"`: at each hit one of two materials, the second with probability `amount`
    /// (pbrt-v4's convention; a float texture is evaluated at the hit), chosen by a
    /// hash of the hit so that it is the same every time the same point is seen from
    /// the same direction.
    Mix {
        materials: [MaterialId; 2],
        amount: FloatParam,
    },
    /// pbrt-v4's `coateddiffuse`: a dielectric coat over a Lambertian base of
    /// `reflectance`.
    CoatedDiffuse { reflectance: Rgb, coat: CoatDesc },
    /// pbrt-v4's `coatedconductor`: a dielectric coat over a conductor whose index
    /// (`ConductorDesc::EtaK`, given relative to vacuum as pbrt reads it) or
    /// reflectance is as for [`MaterialDesc::Conductor`], with the conductor's own
    /// microfacet alphas (0: smooth).
    CoatedConductor {
        conductor: ConductorDesc,
        alpha_u: f32,
        alpha_v: f32,
        coat: CoatDesc,
    },
    /// `"interface"`: no surface at all (a boundary between media); rays pass through.
    Interface,
    /// A material with texture-valued parameters, made concrete at each hit.
    Textured(TexturedMaterialDesc),
}

/// The coat and the slab under it of a layered material (pbrt-v4's `coateddiffuse`
/// and `coatedconductor` parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoatDesc {
    /// Index of the coat relative to the outside.
    pub eta: f32,
    /// Microfacet alphas of the coat (already remapped; 0: smooth).
    pub alpha_u: f32,
    pub alpha_v: f32,
    /// Thickness of the medium between coat and base, in mean free paths.
    pub thickness: f32,
    /// Single-scattering albedo of that medium (0: absorbing only).
    pub albedo: Rgb,
    /// Henyey–Greenstein asymmetry of the medium, in (-1, 1).
    pub g: f32,
    /// Scattering events of the random walk through the layers.
    pub max_depth: u32,
    /// Walks averaged per evaluation.
    pub samples: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ConductorDesc {
    Reflectance(Rgb),
    EtaK { eta: Rgb, k: Rgb },
}

/// A diffuse area light attached to a shape (`AreaLightSource "diffuse"`).
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLightDesc {
    /// Emitted radiance, `scale` (and `power`) already applied; with `image`, the
    /// factor the image's radiance is multiplied by.
    pub l: Rgb,
    /// Emits on both sides; otherwise only on the side of the surface normal.
    pub two_sided: bool,
    /// `filename`: the radiance varies over the surface as this picture does.
    pub image: Option<AreaLightImage>,
}

/// The picture of an area light given by `filename` (pbrt-v4's `DiffuseAreaLight`):
/// the radiance at a surface point is the image bilinearly interpolated at the
/// point's (u, 1 − v), clamped at the borders, times [`AreaLightDesc::l`].
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLightImage {
    pub image: LightImage,
    /// `power` was given: `l` was computed for an image of mean luminance 1 and is
    /// divided by the image's mean luminance once the image is read.
    pub per_unit_mean: bool,
}

/// Shape geometry in object space.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// Triangles: three indices each into `positions`. Optional per-vertex shading
    /// normals and uvs (same length as `positions`).
    ///
    /// Which side faces out (pbrt-v4): without `normals`, the geometric normal is
    /// (p1 - p0) × (p2 - p0) in render space, flipped when `reverse_orientation` is set
    /// or when `render_from_object` swaps handedness (both: no flip). With `normals`,
    /// the shading normal (interpolated N, transformed as a normal, negated when
    /// `reverse_orientation` is set) is authoritative: the geometric normal is turned
    /// to its side. A one-sided area light emits on the side of the geometric normal.
    TriangleMesh {
        positions: Vec<Vec3>,
        indices: Vec<u32>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
    },
    /// Bilinear patches: four indices each, in pbrt's order (p00, p10, p01, p11).
    BilinearMesh {
        positions: Vec<Vec3>,
        indices: Vec<u32>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
    },
    /// Sphere about the object-space origin (pbrt: `radius`, `zmin`, `zmax`, `phimax` degrees).
    Sphere {
        radius: f32,
        z_min: f32,
        z_max: f32,
        phi_max_deg: f32,
    },
    /// Disk in the plane z = `height`, normal +z.
    Disk {
        height: f32,
        radius: f32,
        inner_radius: f32,
        phi_max_deg: f32,
    },
}

/// One `Shape` with the graphics state that applied to it.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    pub geometry: Geometry,
    pub render_from_object: Transform,
    /// `ReverseOrientation` was in effect (flips the normal, and so the emitting side;
    /// for meshes with shading normals it flips those, see [`Geometry::TriangleMesh`]).
    pub reverse_orientation: bool,
    pub material: MaterialId,
    pub area_light: Option<AreaLightDesc>,
    /// pbrt-v4's `alpha` cut-out: where it is 0 rays pass through the shape as if it
    /// were not there, where fractional they pass with probability 1 − alpha. `None`
    /// for an opaque shape (alpha 1).
    pub alpha: Option<FloatParam>,
    pub loc: FileLoc,
}

impl ShapeDesc {
    /// Planar quads `(v0, v1, v2, v3)` as one triangle mesh of the triangles
    /// `(v0, v1, v2)`, `(v0, v2, v3)` each, in render space, not emitting.
    pub fn quads(list: &[[Vec3; 4]], material: MaterialId, loc: FileLoc) -> ShapeDesc {
        let mut positions = Vec::with_capacity(4 * list.len());
        let mut indices = Vec::with_capacity(6 * list.len());
        for q in list {
            let base = positions.len() as u32;
            positions.extend_from_slice(q);
            indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
        }
        ShapeDesc {
            geometry: Geometry::TriangleMesh {
                positions,
                indices,
                normals: None,
                uvs: None,
            },
            render_from_object: Transform::IDENTITY,
            reverse_orientation: false,
            material,
            area_light: None,
            alpha: None,
            loc,
        }
    }
}

/// `ObjectBegin "name"` … `ObjectEnd`.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectDesc {
    pub name: String,
    pub shapes: Vec<ShapeDesc>,
    pub loc: FileLoc,
}

/// `ObjectInstance "name"` with the transform in effect.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceDesc {
    /// Index into `SceneDesc::objects`.
    pub object: usize,
    pub render_from_instance: Transform,
    pub loc: FileLoc,
}

/// `LightSource`. Positions and directions are in render space; `scale` and `power`
/// are already applied.
#[derive(Clone, Debug, PartialEq)]
pub enum LightDesc {
    /// Isotropic point light with radiant intensity `intensity` (W/sr per channel).
    Point {
        position: Vec3,
        intensity: Rgb,
        loc: FileLoc,
    },
    /// Spot light at `position` aimed along unit `direction`; full intensity inside
    /// `cos_falloff_start`, smoothly falling to zero at `cos_total_width` (pbrt-v4).
    Spot {
        position: Vec3,
        direction: Vec3,
        intensity: Rgb,
        cos_falloff_start: f32,
        cos_total_width: f32,
        loc: FileLoc,
    },
    /// Directional light: radiance arrives travelling along unit `direction`
    /// (from `from` towards `to`), irradiance `radiance` on a perpendicular surface.
    Distant {
        direction: Vec3,
        radiance: Rgb,
        loc: FileLoc,
    },
    /// Light from every direction: constant `radiance`, or with `image` the image's
    /// radiance times `radiance` (the `scale`).
    Infinite {
        radiance: Rgb,
        image: Option<EnvironmentImage>,
        loc: FileLoc,
    },
    /// Point light at the origin of `render_from_light` whose intensity per direction
    /// is `intensity` (`I` × `scale`) times the average of the RGB channels of `image`,
    /// a square equal-area octahedral image over the light's frame with its y and z
    /// axes exchanged (pbrt-v4). Without an image, isotropic. With `power`, the
    /// intensity is rescaled when the world is built (the power depends on the image).
    Goniometric {
        render_from_light: Transform,
        intensity: Rgb,
        power: Option<f32>,
        image: Option<LightImage>,
        loc: FileLoc,
    },
    /// Point light at the origin of `render_from_light` projecting `image` (times
    /// `scale`) along its +z through a pinhole; `fov` (degrees) spans the image's
    /// narrower side. `power` is applied when the world is built.
    Projection {
        render_from_light: Transform,
        scale: Rgb,
        fov: f32,
        power: Option<f32>,
        image: LightImage,
        loc: FileLoc,
    },
}

/// An image file a light names (`filename`), read when the world is built.
#[derive(Clone, Debug, PartialEq)]
pub struct LightImage {
    /// The file, resolved against the scene's folder.
    pub path: PathBuf,
    /// Where the scene names the file (for errors about it).
    pub at: FileLoc,
}

/// The picture of an image-based infinite light, as the scene names it: a square image
/// in pbrt-v4's equal-area octahedral layout, in the light's frame (+z up), with the
/// transform to render space (the CTM at `LightSource`). The image is read when the
/// world is built, not by the parser.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentImage {
    /// The file, resolved against the scene's folder.
    pub path: PathBuf,
    /// Where the scene names the file (for errors about it).
    pub at: FileLoc,
    /// `illuminance`: the scale is adjusted so that a surface facing the light's +z
    /// receives this illuminance from the image.
    pub illuminance: Option<f32>,
    pub render_from_light: Transform,
}

/// The z range `(low, high)` of a sphere of `radius` cut at `z_min` and `z_max`, as
/// pbrt-v4 reads them: clamped to the sphere, either order.
pub fn sphere_z_range(radius: f32, z_min: f32, z_max: f32) -> (f32, f32) {
    let r = radius.abs();
    let (a, b) = (z_min.clamp(-r, r), z_max.clamp(-r, r));
    (a.min(b), a.max(b))
}

impl Geometry {
    /// Primitives the geometry becomes: triangles, bilinear patches, or one quadric.
    pub fn primitive_count(&self) -> u64 {
        match self {
            Geometry::TriangleMesh { indices, .. } => indices.len() as u64 / 3,
            Geometry::BilinearMesh { indices, .. } => indices.len() as u64 / 4,
            Geometry::Sphere { .. } | Geometry::Disk { .. } => 1,
        }
    }

    /// Surface area in render space. Meshes are measured after the transform; spheres
    /// and disks by their object-space formula times the transform's mean area scale
    /// |det|^(2/3) (exact for uniform scales). Used for light `power` and default patch sizes.
    pub fn surface_area(&self, render_from_object: &glam::Mat4) -> f32 {
        let area_scale = glam::Mat3::from_mat4(*render_from_object)
            .determinant()
            .abs()
            .powf(2.0 / 3.0);
        let point = |p: Vec3| render_from_object.transform_point3(p);
        let phi = |deg: f32| deg.to_radians().clamp(0.0, std::f32::consts::TAU);
        match self {
            Geometry::TriangleMesh {
                positions, indices, ..
            } => indices
                .chunks_exact(3)
                .map(|tri| {
                    let [a, b, c] = [0, 1, 2].map(|k| point(positions[tri[k] as usize]));
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum(),
            Geometry::BilinearMesh {
                positions, indices, ..
            } => indices
                .chunks_exact(4)
                .map(|q| {
                    super::mesh::bilinear_patch_area(
                        [0, 1, 2, 3].map(|k| point(positions[q[k] as usize])),
                    )
                })
                .sum(),
            Geometry::Sphere {
                radius,
                z_min,
                z_max,
                phi_max_deg,
            } => {
                let (low, high) = sphere_z_range(*radius, *z_min, *z_max);
                phi(*phi_max_deg) * radius.abs() * (high - low) * area_scale
            }
            Geometry::Disk {
                radius,
                inner_radius,
                phi_max_deg,
                ..
            } => {
                0.5 * phi(*phi_max_deg)
                    * (radius * radius - inner_radius * inner_radius).max(0.0)
                    * area_scale
            }
        }
    }
}

impl SceneDesc {
    /// The file name to write: the film's, or a default.
    pub fn output_name(&self) -> &str {
        self.film.filename.as_deref().unwrap_or("radiant.exr")
    }
}
