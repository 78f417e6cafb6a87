//! Building the world from a scene description: geometry to render space in flat
//! arrays, one light per emitting primitive, the BVH over everything.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};

use super::shapes::{
    BilinearPrim, Instance, MeshAttrs, Placed, PrimRef, ShapeSet, TriangleAttr, triangle_uvs,
};
use super::{MAX_MIX_DEPTH, MaterialEntry, NO_LIGHT, World};
use crate::camera::RaySpread;
use crate::geometry::bilinear::BilinearPatch;
use crate::geometry::disk::Disk;
use crate::geometry::sphere::Sphere;
use crate::light::{
    AreaLight, EmissionImage, EmittingMesh, EnvironmentMap, EnvironmentPicture, GoniometricLight,
    LIGHT_SAMPLER_NAMES, LIGHT_SAMPLER_PARAM, Light, LightSampler, LightShape, ProjectionLight,
    SceneSphere, parallelogram_of, rotation_of,
};
use crate::material::{Material, spectrally_matched};
use crate::texture::{TextureSet, concrete_material};
use radiant_math::Transform;
use radiant_math::color::Rgb;
use radiant_scene::{
    AreaLightDesc, EnvironmentImage, FileLoc, Geometry, LightDesc, LightImage, MaterialDesc,
    SceneDesc, SceneError, ShapeDesc, TexturedMaterialDesc, TexturedParam, Warning,
};

/// Point lookups per axis over the (u, v) square for a textured material's mean.
const AVERAGE_GRID: u32 = 8;

/// A textured material with each texture replaced by its mean over (u, v).
fn representative(desc: &TexturedMaterialDesc, textures: &TextureSet) -> Material {
    concrete_material(
        desc,
        |p| textures.uv_average_float(p, AVERAGE_GRID),
        |p| textures.uv_average(p, AVERAGE_GRID),
    )
}

/// Errors building the world are scene errors: they name the shape's location.
pub type BuildError = SceneError;

impl World {
    /// Builds the render-ready world. Returns warnings for things that work only
    /// approximately (they are never silent).
    pub fn build(desc: &SceneDesc) -> Result<(World, Vec<Warning>), BuildError> {
        check_capacity(desc)?;
        let mut warnings = Vec::new();
        let textures = TextureSet::build(desc)?;
        let textured: Vec<Option<TexturedMaterialDesc>> = desc
            .materials
            .iter()
            .map(|m| match m {
                MaterialDesc::Textured(t) => Some(t.clone()),
                _ => None,
            })
            .collect();
        let materials = material_table(&desc.materials, &textures)?;
        let shading_normals = super::normals::build_shading_normals(desc)?;
        let mut lights = Vec::new();

        let mut prototypes = Vec::with_capacity(desc.objects.len());
        for object in &desc.objects {
            let mut set = ShapeSet::default();
            for shape in &object.shapes {
                // pbrt does not support area lights in instances either; the parser warned.
                add_shape(&mut set, shape, &materials, None, &mut warnings)?;
            }
            set.finish(&[]);
            prototypes.push(set);
        }

        let mut top = ShapeSet::default();
        let mut emission_images = HashMap::new();
        for shape in &desc.shapes {
            let emitter = match (&shape.area_light, shape.alpha) {
                (None, _) => None,
                // Cut out everywhere: no surface, so no emission (pbrt-v4 masks it).
                (Some(_), Some(TexturedParam::Constant(a))) if a <= 0.0 => None,
                (Some(a), alpha) => {
                    if alpha.is_some() {
                        warnings.push(Warning {
                            loc: shape.loc.clone(),
                            message: "area light on a shape with an alpha cut-out: rays pass the cut-out parts, but light samples and photons still leave them".into(),
                        });
                    }
                    Some(emitter_of(
                        a,
                        &mut emission_images,
                        &shape.loc,
                        &mut warnings,
                    )?)
                }
            };
            add_shape(
                &mut top,
                shape,
                &materials,
                emitter.map(|e| (e, &mut lights)),
                &mut warnings,
            )?;
        }
        for inst in &desc.instances {
            // A singular instance transform has collapsed the object.
            if prototypes[inst.object].is_empty() || !inst.render_from_instance.is_invertible() {
                continue;
            }
            let i = top.instances.len() as u32;
            top.instances.push(Instance {
                prototype: inst.object as u32,
                render_from_instance: inst.render_from_instance,
            });
            top.prims.push(PrimRef::Instance(i));
        }
        top.finish(&prototypes);
        let bounds = top.bounds();

        for l in &desc.lights {
            lights.push(light_from_desc(l, &mut warnings)?);
        }
        let light_sampler =
            light_sampler_from_desc(desc, &lights, SceneSphere::around(&bounds), &mut warnings)?;
        let footprints_used = textured.iter().any(Option::is_some) || !shading_normals.is_empty();
        let world = World {
            geometry: top,
            prototypes,
            materials,
            textured,
            textures,
            shading_normals,
            footprints_used,
            cut_outs: desc
                .shapes
                .iter()
                .chain(desc.objects.iter().flat_map(|o| o.shapes.iter()))
                .any(|s| s.alpha.is_some()),
            ray_spread: RaySpread::NONE,
            lights,
            light_sampler,
            bounds,
        };
        Ok((world, warnings))
    }

    /// The scene's bounding sphere, for lights at infinity.
    pub fn scene_sphere(&self) -> SceneSphere {
        SceneSphere::around(&self.bounds)
    }
}

/// The light sampler the integrator's `"string lightsampler"` names (default
/// `"power"`); pbrt-v4's names that radiant lacks get the default, with a warning.
fn light_sampler_from_desc(
    desc: &SceneDesc,
    lights: &[Light],
    scene: SceneSphere,
    warnings: &mut Vec<Warning>,
) -> Result<LightSampler, BuildError> {
    let params = &desc.integrator.params;
    let name = params.string(LIGHT_SAMPLER_PARAM, LIGHT_SAMPLER_NAMES[0].into())?;
    let loc = params
        .lookup(LIGHT_SAMPLER_PARAM)
        .map_or(&desc.integrator.loc, |p| &p.loc);
    let (sampler, stand_in) = LightSampler::by_name(&name, lights, scene)
        .map_err(|e| SceneError::at(loc, e.to_string()))?;
    if stand_in {
        warnings.push(Warning {
            loc: loc.clone(),
            message: format!(
                "light sampler \"{name}\" is not supported; using \"{}\"",
                sampler.name()
            ),
        });
    }
    Ok(sampler)
}

fn light_from_desc(l: &LightDesc, warnings: &mut Vec<Warning>) -> Result<Light, BuildError> {
    Ok(match l {
        LightDesc::Point {
            position,
            intensity,
            ..
        } => Light::Point {
            position: *position,
            intensity: *intensity,
        },
        LightDesc::Spot {
            position,
            direction,
            intensity,
            cos_falloff_start,
            cos_total_width,
            ..
        } => Light::Spot {
            position: *position,
            direction: direction.normalize(),
            intensity: *intensity,
            cos_falloff_start: *cos_falloff_start,
            cos_total_width: *cos_total_width,
        },
        LightDesc::Distant {
            direction,
            radiance,
            ..
        } => Light::Distant {
            direction: direction.normalize(),
            radiance: *radiance,
        },
        LightDesc::Infinite {
            radiance,
            image: None,
            ..
        } => Light::Infinite {
            radiance: *radiance,
            map: None,
        },
        LightDesc::Infinite {
            radiance,
            image: Some(image),
            loc,
        } => {
            let (rotation, similar) = rotation_of(&image.render_from_light);
            if !similar {
                warnings.push(Warning {
                    loc: loc.clone(),
                    message: "LightSource \"infinite\": the transform is not a rotation and uniform scale; only its rotation orients the image".into(),
                });
            }
            let picture = read_environment_image(image)?;
            let scale = match image.illuminance {
                None => *radiance,
                Some(target) => match picture.upper_illuminance() {
                    e if e > 0.0 => *radiance * (target as f64 / e) as f32,
                    _ => {
                        warnings.push(Warning {
                            loc: image.at.clone(),
                            message: "LightSource \"infinite\": the image is black above the horizon; \"illuminance\" ignored".into(),
                        });
                        *radiance
                    }
                },
            };
            Light::Infinite {
                radiance: scale,
                map: Some(Arc::new(EnvironmentMap::new(
                    picture.size,
                    &picture.pixels,
                    scale,
                    rotation,
                ))),
            }
        }
        LightDesc::Goniometric {
            render_from_light,
            intensity,
            power,
            image,
            loc,
        } => goniometric_light(
            render_from_light,
            *intensity,
            *power,
            image.as_ref(),
            loc,
            warnings,
        )?,
        LightDesc::Projection {
            render_from_light,
            scale,
            fov,
            power,
            image,
            loc,
        } => projection_light(
            render_from_light,
            *scale,
            *fov,
            *power,
            image,
            loc,
            warnings,
        )?,
    })
}

/// A light image as read, each pixel finite and at least 0; errors located at the
/// `filename` parameter and naming `what`.
fn read_light_image(
    image: &LightImage,
    what: &str,
) -> Result<(usize, usize, Vec<Rgb>), BuildError> {
    let read = read_located(&image.path, &image.at, what)?;
    let pixels = finite_pixels(&read, &image.path, &image.at)?;
    Ok((read.width, read.height, pixels))
}

/// The image at `path`, a read error located at `at` and naming `what`.
fn read_located(
    path: &std::path::Path,
    at: &FileLoc,
    what: &str,
) -> Result<radiant_image::Image, BuildError> {
    radiant_image::read_image(path)
        .map_err(|err| SceneError::at(at, format!("cannot read {what} image: {err}")))
}

/// The image's pixels with negative values clamped to 0; a non-finite pixel is an
/// error located at `at`.
fn finite_pixels(
    read: &radiant_image::Image,
    path: &std::path::Path,
    at: &FileLoc,
) -> Result<Vec<Rgb>, BuildError> {
    if let Some(k) = read.pixels.iter().position(|p| !p.is_finite()) {
        return Err(SceneError::at(
            at,
            format!(
                "{}: pixel ({}, {}) is not finite",
                path.display(),
                k % read.width,
                k / read.width
            ),
        ));
    }
    Ok(read.pixels.iter().map(|p| p.clamp_min(0.0)).collect())
}

/// Factor that makes luminance power `have` equal to `target` (1 with a warning when
/// the light emits nothing).
fn power_factor(target: Option<f32>, have: f32, loc: &FileLoc, warnings: &mut Vec<Warning>) -> f32 {
    match target {
        Some(phi) if have > 0.0 => phi / have,
        Some(_) => {
            warnings.push(Warning {
                loc: loc.clone(),
                message: "light \"power\" ignored: the light emits nothing".into(),
            });
            1.0
        }
        None => 1.0,
    }
}

fn goniometric_light(
    render_from_light: &Transform,
    intensity: Rgb,
    power: Option<f32>,
    image: Option<&LightImage>,
    loc: &FileLoc,
    warnings: &mut Vec<Warning>,
) -> Result<Light, BuildError> {
    let position = render_from_light.point(Vec3::ZERO);
    let Some(image) = image else {
        let k = power_factor(
            power,
            intensity.luminance() * 4.0 * radiant_math::PI,
            loc,
            warnings,
        );
        return Ok(Light::Point {
            position,
            intensity: intensity * k,
        });
    };
    let (width, height, pixels) = read_light_image(image, "goniometric light")?;
    if width != height {
        return Err(SceneError::at(
            &image.at,
            format!(
                "{}: goniometric image is {width}x{height}; it must be square, in the \
                 equal-area octahedral layout",
                image.path.display()
            ),
        ));
    }
    let (rotation, similar) = rotation_of(render_from_light);
    if !similar {
        warnings.push(Warning {
            loc: loc.clone(),
            message: "LightSource \"goniometric\": the transform is not a rotation and uniform scale; only its rotation orients the image".into(),
        });
    }
    // The image's polar axis is the light's +y: exchange y and z.
    let swap_yz = Mat3::from_cols(Vec3::X, Vec3::Z, Vec3::Y);
    let grey: Vec<Rgb> = pixels
        .iter()
        .map(|p| Rgb::splat((p.r + p.g + p.b) / 3.0))
        .collect();
    let mean = grey.iter().map(|p| p.r as f64).sum::<f64>() / grey.len() as f64;
    let k = power_factor(
        power,
        (4.0 * std::f64::consts::PI * mean) as f32 * intensity.luminance(),
        loc,
        warnings,
    );
    let map = EnvironmentMap::new(width, &grey, intensity * k, rotation * swap_yz);
    Ok(Light::Goniometric(Arc::new(GoniometricLight::new(
        position,
        Arc::new(map),
    ))))
}

fn projection_light(
    render_from_light: &Transform,
    scale: Rgb,
    fov: f32,
    power: Option<f32>,
    image: &LightImage,
    loc: &FileLoc,
    warnings: &mut Vec<Warning>,
) -> Result<Light, BuildError> {
    let (width, height, pixels) = read_light_image(image, "projection light")?;
    let (rotation, similar) = rotation_of(render_from_light);
    if !similar {
        warnings.push(Warning {
            loc: loc.clone(),
            message: "LightSource \"projection\": the transform is not a rotation and uniform scale; only its rotation orients the image".into(),
        });
    }
    let position = render_from_light.point(Vec3::ZERO);
    let pixels = Arc::new(pixels);
    let light = ProjectionLight::new(
        position,
        rotation,
        fov,
        width,
        height,
        pixels.clone(),
        scale,
    );
    let k = power_factor(power, light.power().luminance(), loc, warnings);
    Ok(Light::Projection(Arc::new(if k == 1.0 {
        light
    } else {
        ProjectionLight::new(position, rotation, fov, width, height, pixels, scale * k)
    })))
}

/// Reads the image of an infinite light: square (pbrt-v4's equal-area octahedral
/// layout), finite; negative values are clamped to 0. Errors are located at the
/// `filename` parameter.
fn read_environment_image(image: &EnvironmentImage) -> Result<EnvironmentPicture, BuildError> {
    let at = &image.at;
    let path = &image.path;
    let read = read_located(path, at, "environment")?;
    if read.width != read.height {
        return Err(SceneError::at(
            at,
            format!(
                "{}: environment image is {}x{}; an infinite light needs a square image in \
                 the equal-area octahedral layout (convert a latitude-longitude map with \
                 pbrt-v4's `imgtool makeequiarea`)",
                path.display(),
                read.width,
                read.height
            ),
        ));
    }
    Ok(EnvironmentPicture {
        size: read.width,
        pixels: finite_pixels(&read, path, at)?,
    })
}

fn is_similarity(xf: &Transform) -> bool {
    let m = Mat3::from_mat4(xf.m);
    let (a, b, c) = (m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
    let tol = 1e-4 * a.max(b).max(c);
    (a - b).abs() < tol
        && (a - c).abs() < tol
        && m.x_axis.dot(m.y_axis).abs() < tol * a
        && m.x_axis.dot(m.z_axis).abs() < tol * a
        && m.y_axis.dot(m.z_axis).abs() < tol * a
}

/// The world's material table, entry for entry the description's: BSDFs, and mixes
/// that refer to other entries (checked to be in range and free of cycles); a textured
/// material at its textures' means (its textures are evaluated per hit).
fn material_table(
    descs: &[MaterialDesc],
    textures: &TextureSet,
) -> Result<Vec<MaterialEntry>, BuildError> {
    let table: Vec<MaterialEntry> = descs
        .iter()
        .map(|d| match d {
            MaterialDesc::Mix { materials, amount } => MaterialEntry::Mix {
                materials: *materials,
                amount: match amount {
                    TexturedParam::Constant(a) => *a,
                    TexturedParam::Texture(_) => textures.uv_average_float(*amount, AVERAGE_GRID),
                },
                amount_texture: match amount {
                    TexturedParam::Constant(_) => None,
                    TexturedParam::Texture(id) => Some(*id),
                },
            },
            MaterialDesc::Textured(t) => MaterialEntry::Bsdf(representative(t, textures)),
            d => MaterialEntry::Bsdf(Material::from_desc(&spectrally_matched(d))),
        })
        .collect();
    let refuse = |msg: String| SceneError::at(&FileLoc::builtin("materials"), msg);
    // Nesting depth of each entry, memoised; past the bound means a cycle (or nesting
    // far beyond any real scene), and the recursion never goes deeper than the bound.
    fn depth(table: &[MaterialEntry], memo: &mut [Option<usize>], i: u32, level: usize) -> usize {
        if level > MAX_MIX_DEPTH {
            return level;
        }
        if let Some(d) = memo[i as usize] {
            return d;
        }
        let d = match table[i as usize] {
            MaterialEntry::Bsdf(_) => 0,
            MaterialEntry::Mix { materials, .. } => {
                1 + materials
                    .iter()
                    .map(|&m| depth(table, memo, m, level + 1))
                    .max()
                    .unwrap_or(0)
            }
        };
        if d <= MAX_MIX_DEPTH {
            memo[i as usize] = Some(d);
        }
        d
    }
    for (i, entry) in table.iter().enumerate() {
        let MaterialEntry::Mix { materials, .. } = entry else {
            continue;
        };
        if let Some(&bad) = materials.iter().find(|&&m| m as usize >= table.len()) {
            return Err(refuse(format!(
                "mix material {i} refers to material {bad}, out of range"
            )));
        }
    }
    let mut memo = vec![None; table.len()];
    for i in 0..table.len() {
        if depth(&table, &mut memo, i as u32, 0) > MAX_MIX_DEPTH {
            return Err(refuse(format!(
                "mix material {i}: mixes nest more than {MAX_MIX_DEPTH} deep or form a cycle"
            )));
        }
    }
    Ok(table)
}

/// Primitive ids are u32 (BVH leaves, hit records); one id stays free as a marker.
const MAX_PRIMITIVES: u64 = u32::MAX as u64 - 1;
/// A lower estimate of the memory one primitive takes once built: its vertices and
/// per-primitive record, its reference and share of BVH nodes (measured at about 150
/// bytes per triangle of a 2-million-triangle mesh, scene description excluded).
const BYTES_PER_PRIMITIVE: f64 = 96.0;

/// Before anything is built: the primitives of all shapes must fit the BVH's ids and
/// the memory budget; otherwise a located error at the shape where the count goes over.
fn check_capacity(desc: &SceneDesc) -> Result<(), BuildError> {
    let mut primitives = 0u64;
    let shapes = desc
        .objects
        .iter()
        .flat_map(|o| o.shapes.iter())
        .chain(&desc.shapes);
    for shape in shapes {
        primitives += shape.geometry.primitive_count();
        if primitives > MAX_PRIMITIVES {
            return Err(SceneError::at(
                &shape.loc,
                format!(
                    "the scene reaches {primitives} primitives here, more than the BVH's capacity of {MAX_PRIMITIVES}"
                ),
            ));
        }
        if let Err(over) = crate::budget::check(primitives as f64 * BYTES_PER_PRIMITIVE) {
            return Err(SceneError::at(
                &shape.loc,
                format!("{primitives} primitives up to this shape would need {over}"),
            ));
        }
    }
    Ok(())
}

/// What an emitting shape's lights are made of: its area light with the image read.
#[derive(Clone, Debug)]
struct Emitter {
    l: Rgb,
    two_sided: bool,
    image: Option<Arc<EmissionImage>>,
}

/// The emitter of an area light, its image read once per file (shapes under one
/// `AreaLightSource` share it); with `power`, `l` divided by the image's mean
/// luminance, as pbrt-v4 normalises an image light's power.
fn emitter_of(
    a: &AreaLightDesc,
    images: &mut HashMap<std::path::PathBuf, Arc<EmissionImage>>,
    loc: &FileLoc,
    warnings: &mut Vec<Warning>,
) -> Result<Emitter, BuildError> {
    let Some(picture) = &a.image else {
        return Ok(Emitter {
            l: a.l,
            two_sided: a.two_sided,
            image: None,
        });
    };
    let image = match images.get(&picture.image.path) {
        Some(img) => img.clone(),
        None => {
            let img = Arc::new(read_emission_image(&picture.image)?);
            images.insert(picture.image.path.clone(), img.clone());
            img
        }
    };
    let l = image_emission_factor(a, &image).unwrap_or_else(|| {
        warnings.push(Warning {
            loc: loc.clone(),
            message: "area light \"power\" ignored: the image is black".into(),
        });
        a.l
    });
    Ok(Emitter {
        l,
        two_sided: a.two_sided,
        image: Some(image),
    })
}

/// The factor an area light's `image` is multiplied by: `l`, divided by the image's
/// mean luminance when `power` was given; `None` when that mean is 0.
pub fn image_emission_factor(a: &AreaLightDesc, image: &EmissionImage) -> Option<Rgb> {
    match &a.image {
        Some(picture) if picture.per_unit_mean => {
            let y = image.mean().luminance();
            (y > 0.0).then(|| a.l / y)
        }
        _ => Some(a.l),
    }
}

/// The picture of an area light with `filename`, read and checked (finite; negative
/// values clamped to 0); errors located at the parameter.
pub fn read_emission_image(image: &LightImage) -> Result<EmissionImage, BuildError> {
    let (width, height, pixels) = read_light_image(image, "area light")?;
    Ok(EmissionImage::new(width, height, pixels))
}

/// Adds one shape's primitives; with `emission` (never inside prototypes) its area
/// lights go to the list.
fn add_shape(
    set: &mut ShapeSet,
    shape: &ShapeDesc,
    materials: &[MaterialEntry],
    emission: Option<(Emitter, &mut Vec<Light>)>,
    warnings: &mut Vec<Warning>,
) -> Result<(), BuildError> {
    let material = shape.material;
    if materials.get(material as usize).is_none() {
        return Err(SceneError::at(
            &shape.loc,
            format!("material index {material} out of range"),
        ));
    }
    // An interface without emission is no surface at all.
    if materials[material as usize] == MaterialEntry::Bsdf(Material::Interface)
        && emission.is_none()
    {
        return Ok(());
    }
    let xf = shape.render_from_object;
    let ro = shape.reverse_orientation;
    match &shape.geometry {
        Geometry::TriangleMesh {
            positions,
            indices,
            normals,
            uvs,
        } => add_mesh(
            set,
            shape,
            positions,
            indices.clone(),
            normals,
            uvs,
            false,
            emission,
        ),
        Geometry::BilinearMesh {
            positions,
            indices,
            normals,
            uvs,
        } => {
            // Planar patches (p00, p10, p01, p11) become the triangles (p00,p10,p11),
            // (p00,p11,p01) — exactly what the patch intersector does for them — so they
            // share the triangle BVH; curved ones stay patches (Reshetov 2019).
            let orientation = if ro ^ xf.swaps_handedness() {
                -1.0
            } else {
                1.0
            };
            let mut tris = Vec::with_capacity(indices.len() / 4 * 6);
            let mut emission = emission;
            for q in indices.chunks_exact(4) {
                let [a, b, c, d] = [q[0], q[1], q[2], q[3]];
                let [p00, p10, p01, p11] = [a, b, c, d].map(|i| xf.point(positions[i as usize]));
                let patch = BilinearPatch::new(p00, p10, p01, p11);
                if patch.is_planar() {
                    tris.extend_from_slice(&[a, b, d, a, d, c]);
                    continue;
                }
                let light = match &mut emission {
                    Some((desc, lights)) => {
                        push_light(lights, desc, LightShape::Bilinear { patch, orientation })
                    }
                    None => NO_LIGHT,
                };
                let i = set.bilinears.len() as u32;
                set.bilinears.push(BilinearPrim {
                    patch,
                    material,
                    light,
                    orientation,
                    alpha: shape.alpha,
                });
                set.prims.push(PrimRef::Bilinear(i));
            }
            if normals.is_some() && !set.bilinears.is_empty() {
                warnings.push(Warning {
                    loc: shape.loc.clone(),
                    message: "shading normals on curved bilinear patches are not interpolated; geometric normals are used"
                        .into(),
                });
            }
            add_mesh(set, shape, positions, tris, normals, uvs, true, emission);
        }
        // Quadrics are intersected in object space: under a singular transform (which
        // the parser accepted with a warning) they have collapsed and are left out.
        Geometry::Sphere { .. } | Geometry::Disk { .. } if !xf.is_invertible() => {}
        Geometry::Sphere {
            radius,
            z_min,
            z_max,
            phi_max_deg,
        } => {
            let sphere = Sphere::partial(*radius, *z_min, *z_max, *phi_max_deg)
                .map_err(|e| SceneError::at(&shape.loc, format!("sphere: {e}")))?;
            let light = emission.map_or(NO_LIGHT, |(a, lights)| {
                if !is_similarity(&xf) {
                    warnings.push(non_similar_warning(shape));
                }
                push_light(
                    lights,
                    &a,
                    LightShape::Sphere {
                        sphere,
                        render_from_object: xf,
                        reverse: ro,
                    },
                )
            });
            let i = set.spheres.len() as u32;
            set.spheres.push(Placed {
                shape: sphere,
                render_from_object: xf,
                material,
                light,
                reverse: ro,
                alpha: shape.alpha,
            });
            set.prims.push(PrimRef::Sphere(i));
        }
        Geometry::Disk {
            height,
            radius,
            inner_radius,
            phi_max_deg,
        } => {
            let disk = Disk::new(*height, *radius, *inner_radius, *phi_max_deg)
                .map_err(|e| SceneError::at(&shape.loc, format!("disk: {e}")))?;
            let light = emission.map_or(NO_LIGHT, |(a, lights)| {
                if !is_similarity(&xf) {
                    warnings.push(non_similar_warning(shape));
                }
                push_light(lights, &a, LightShape::disk(disk, xf, ro))
            });
            let i = set.disks.len() as u32;
            set.disks.push(Placed {
                shape: disk,
                render_from_object: xf,
                material,
                light,
                reverse: ro,
                alpha: shape.alpha,
            });
            set.prims.push(PrimRef::Disk(i));
        }
    }
    Ok(())
}

fn non_similar_warning(shape: &ShapeDesc) -> Warning {
    Warning {
        loc: shape.loc.clone(),
        message: "area light on a non-uniformly scaled quadric: light sampling assumes a uniform scale and will be biased"
            .into(),
    }
}

fn push_light(lights: &mut Vec<Light>, a: &Emitter, shape: LightShape) -> u32 {
    lights.push(Light::Area(AreaLight {
        shape,
        l: a.l,
        two_sided: a.two_sided,
        image: a.image.clone(),
    }));
    (lights.len() - 1) as u32
}

/// The light of an emitting triangle mesh (render-space vertices `p`): one triangle, a
/// parallelogram for two that form one, else the whole mesh; `None` when no triangle
/// has an area. With shading normals a triangle's front follows them (pbrt-v4), else
/// the winding times `orientation`. With `uvs` (a light with an image: each
/// triangle's vertex (u, v), by its index in the mesh) it is always a mesh carrying
/// them.
fn emitting_mesh(
    p: &[Vec3],
    indices: &[u32],
    normals: Option<&[Vec3]>,
    orientation: f32,
    uvs: Option<&dyn Fn(usize) -> [Vec2; 3]>,
) -> Option<LightShape> {
    let mut triangles = Vec::new();
    let mut fronts = Vec::new();
    let mut tuvs = Vec::new();
    for (k, tri) in indices.chunks_exact(3).enumerate() {
        let v = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let pts = v.map(|i| p[i]);
        let cross = (pts[1] - pts[0]).cross(pts[2] - pts[0]);
        if cross.length() == 0.0 {
            continue;
        }
        let mut front = cross.normalize();
        match normals {
            Some(ns) if (ns[v[0]] + ns[v[1]] + ns[v[2]]).dot(front) < 0.0 => front = -front,
            Some(_) => {}
            None => front *= orientation,
        }
        triangles.push(pts);
        fronts.push(front);
        if let Some(uv_of) = uvs {
            tuvs.push(uv_of(k));
        }
    }
    if uvs.is_some() {
        return (!triangles.is_empty())
            .then(|| LightShape::Mesh(Box::new(EmittingMesh::new(triangles, fronts, tuvs))));
    }
    match (&triangles[..], &fronts[..]) {
        ([], _) => None,
        ([t], [n]) => Some(LightShape::Triangle {
            p: *t,
            n: *n,
            area: 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length(),
        }),
        ([a, b], [na, nb]) if na.dot(*nb) > 1.0 - 1e-6 => match parallelogram_of(*a, *b) {
            Some((corner, e1, e2)) => Some(LightShape::Parallelogram {
                p: corner,
                e1,
                e2,
                n: *na,
                area: e1.cross(e2).length(),
            }),
            None => Some(LightShape::Mesh(Box::new(EmittingMesh::new(
                triangles,
                fronts,
                Vec::new(),
            )))),
        },
        _ => Some(LightShape::Mesh(Box::new(EmittingMesh::new(
            triangles,
            fronts,
            Vec::new(),
        )))),
    }
}

/// Adds a triangle mesh; `bilinear_halves` when its triangles are the halves of
/// planar bilinear patches, in pairs (their default (u, v) is the patch's).
#[allow(clippy::too_many_arguments)]
fn add_mesh(
    set: &mut ShapeSet,
    shape: &ShapeDesc,
    positions: &[Vec3],
    indices: Vec<u32>,
    normals: &Option<Vec<Vec3>>,
    uvs: &Option<Vec<Vec2>>,
    bilinear_halves: bool,
    mut emission: Option<(Emitter, &mut Vec<Light>)>,
) {
    let xf = shape.render_from_object;
    let ro = shape.reverse_orientation;
    let orientation = if ro ^ xf.swaps_handedness() {
        -1.0
    } else {
        1.0
    };
    let p: Vec<Vec3> = positions.iter().map(|&v| xf.point(v)).collect();
    // pbrt-v4 flips per-vertex normals under ReverseOrientation.
    let n: Option<Vec<Vec3>> = normals.as_ref().map(|ns| {
        ns.iter()
            .map(|&v| {
                let w = xf.normal(v).normalize_or_zero();
                if ro { -w } else { w }
            })
            .collect()
    });
    let mesh = set.meshes.len() as u32;
    let light = match &mut emission {
        None => NO_LIGHT,
        Some((a, lights)) => {
            let uv_of = |k: usize| {
                let tri = &indices[3 * k..3 * k + 3];
                let vi = [tri[0], tri[1], tri[2]].map(|v| v as usize);
                triangle_uvs(uvs.as_deref(), vi, k, bilinear_halves)
            };
            let with_uvs: Option<&dyn Fn(usize) -> [Vec2; 3]> = a.image.is_some().then_some(&uv_of);
            emitting_mesh(&p, &indices, n.as_deref(), orientation, with_uvs)
                .map_or(NO_LIGHT, |shape| push_light(lights, a, shape))
        }
    };
    for (k, tri) in indices.chunks_exact(3).enumerate() {
        let pts = [tri[0], tri[1], tri[2]].map(|i| p[i as usize]);
        // Degenerate triangles carry no light (no area to sample), as the mesh light
        // leaves them out.
        let degenerate = (pts[1] - pts[0]).cross(pts[2] - pts[0]).length() == 0.0;
        let light = if degenerate { NO_LIGHT } else { light };
        set.triangles.push(pts);
        set.triangle_attrs.push(TriangleAttr {
            mesh,
            index: k as u32,
            material: shape.material,
            light,
            orientation,
        });
    }
    set.meshes.push(MeshAttrs {
        indices,
        normals: n,
        uvs: uvs.clone(),
        bilinear_halves,
        alpha: shape.alpha,
    });
}
