//! From a scene description to patches: every diffuse surface (triangle meshes,
//! bilinear patches, tessellated spheres and disks, instances flattened) as planar faces
//! in render space, then split by [`super::face_mesh`] into one shared-vertex patch mesh.
//!
//! Per band: exitance `E = pi L` on the emitting side of area lights (Lambertian
//! emitters), reflectance = the diffuse albedo. Other materials are approximated by
//! their diffuse albedo alone (documented approximation, one warning per material):
//! `diffusetransmission` by its reflectance (the transmitted part is lost), a `mix` by
//! the amount-weighted albedo of its two materials, and glass and metals by zero (their
//! patches absorb; the display follows camera rays through them by their BSDF). A
//! textured material (or mix amount) and an area light's image give each patch its own
//! mean, over its centroid and the midpoints towards its corners, read on the shape's
//! true surface through the render world (an image light is reported once); the
//! shape's mean over the (u, v) square (a 16 × 16 grid of point lookups) stands where
//! no point is found. A shape with a constant alpha of 0 is left out;
//! other alpha cut-outs are solved as opaque (with a warning). Patches are one-sided:
//! the front is the side the shape's
//! normal points to (pbrt's rules: winding, `ReverseOrientation`, handedness of the
//! transform, shading normals), which is also the side a one-sided light emits on.

use std::collections::HashMap;
use std::path::PathBuf;

use glam::{DMat4, DVec3, Vec3};

use super::face_mesh::{FaceMesh, Subdivision};
use super::patch::PatchSet;
use crate::settings::{DEFAULT_PATCH_COUNT, RadiositySettings, SolverKind};
use radiant_math::color::Rgb;
use radiant_render::geometry::Ray;
use radiant_render::integrator::direct::surface_emission;
use radiant_render::light::EmissionImage;
use radiant_render::texture::{TextureSet, concrete_material};
use radiant_render::world::{World, image_emission_factor, read_emission_image};
use radiant_scene::{
    AreaLightDesc, FileLoc, Geometry, MaterialDesc, SceneDesc, SceneError, ShapeDesc,
    TexturedMaterialDesc, TexturedParam, Warning, sphere_z_range,
};

/// What every patch of one input face carries.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceTag {
    /// Index into `SceneDesc::materials`.
    pub material: u32,
    /// Exitance `pi L` per band (zero for non-emitters).
    pub emission: [f64; 3],
    pub reflectance: [f64; 3],
    /// Index of the shape among the scene's shapes then the instanced shapes, in order.
    pub shape: u32,
}

/// Point lookups per axis over the (u, v) square for a textured reflectance's mean.
const TEXTURE_AVERAGE_GRID: u32 = 16;

/// Whether a material's diffuse albedo varies over the surface: a texture in it, or in
/// a mix's amount or materials.
fn varies_over_surface(materials: &[MaterialDesc], id: u32, depth: u32) -> bool {
    match materials.get(id as usize) {
        Some(MaterialDesc::Textured(_)) => true,
        Some(MaterialDesc::Mix {
            materials: m,
            amount,
        }) if depth < 64 => {
            amount.constant().is_none()
                || m.iter()
                    .any(|&k| varies_over_surface(materials, k, depth + 1))
        }
        _ => false,
    }
}

/// Gives patch `i` of a textured surface (or of a light with an image) the mean of its
/// surface over points spread across it: the centroid and the midpoints towards each
/// corner, each found by a ray along the patch normal to the shape's true surface
/// (tessellated spheres and disks lie off it by their sag). Points where the ray meets
/// another material (or nothing) are left out; without any, the patch keeps the
/// shape's mean.
fn patch_means(world: &World, set: &mut PatchSet, i: usize, material: u32) {
    let polygon = set.polygon(i);
    let patch = &set.patches[i];
    let (n, c) = (patch.normal, patch.centroid);
    let reach = patch.area.sqrt().max(1e-12);
    let mut points = vec![c];
    points.extend(polygon.as_slice().iter().map(|&q| 0.5 * (c + q)));
    let (mut albedo, mut radiance, mut found) = (Rgb::BLACK, Rgb::BLACK, 0u32);
    for q in points {
        // From above the patch down its normal, then from below up it.
        let hit = [1.0, -1.0].iter().find_map(|&side| {
            let o = (q + side * reach * n).as_vec3();
            let d = (-side * n).as_vec3();
            world
                .intersect(&Ray::new(o, d), 2.0 * reach as f32)
                .filter(|h| h.material == material)
        });
        let Some(hit) = hit else { continue };
        albedo += world.diffuse_albedo_at(&hit);
        radiance += surface_emission(world, &hit, n.as_vec3());
        found += 1;
    }
    if found == 0 {
        return;
    }
    let k = 1.0 / found as f32;
    let p = &mut set.patches[i];
    p.reflectance = (albedo * k).to_array().map(|r| (r as f64).clamp(0.0, 1.0));
    if p.emission != [0.0; 3] {
        p.emission = (radiance * k)
            .to_array()
            .map(|l| std::f64::consts::PI * l.max(0.0) as f64);
    }
}

/// The radiance an area light's patches emit: `l`, or for a light with an image its
/// mean over the image (one value per shape, as for textured reflectances; reported
/// once per image). Images are read once per file.
fn area_light_mean(
    a: &AreaLightDesc,
    loc: &FileLoc,
    images: &mut HashMap<PathBuf, EmissionImage>,
    warnings: &mut Vec<Warning>,
) -> Result<Rgb, SceneError> {
    let Some(picture) = &a.image else {
        return Ok(a.l);
    };
    let path = &picture.image.path;
    if !images.contains_key(path) {
        images.insert(path.clone(), read_emission_image(&picture.image)?);
        warnings.push(Warning {
            loc: loc.clone(),
            message: format!(
                "radiosity: the area light's image '{}' is emitted as its mean radiance over each patch",
                path.display()
            ),
        });
    }
    let image = &images[path];
    Ok(image_emission_factor(a, image).unwrap_or(a.l) * image.mean())
}

/// The diffuse albedo radiosity gives each material, per band in [0, 1]: a mix's is
/// the amount-weighted mean of its two materials' (memoised, so shared sub-mixes cost
/// once; nesting bounded, so a cyclic description cannot recurse forever).
fn diffuse_albedos(materials: &[MaterialDesc], textures: &TextureSet) -> Vec<[f64; 3]> {
    fn albedo(
        materials: &[MaterialDesc],
        textures: &TextureSet,
        memo: &mut [Option<[f64; 3]>],
        id: u32,
        depth: u32,
    ) -> [f64; 3] {
        if let Some(a) = memo.get(id as usize).copied().flatten() {
            return a;
        }
        let clamp = |c: radiant_math::color::Rgb| c.to_array().map(|c| (c as f64).clamp(0.0, 1.0));
        let a = match materials.get(id as usize) {
            Some(MaterialDesc::Diffuse { reflectance })
            | Some(MaterialDesc::DiffuseTransmission { reflectance, .. }) => clamp(*reflectance),
            // The coat's transmittance and inner reflection in closed form (see
            // `Material::diffuse_albedo`); its gloss is left out.
            Some(d @ MaterialDesc::CoatedDiffuse { .. }) => clamp(
                radiant_render::material::Material::from_desc(
                    &radiant_render::material::spectrally_matched(d),
                )
                .diffuse_albedo(),
            ),
            // One reflectance per shape: the material with each texture at its mean
            // over (u, v).
            Some(MaterialDesc::Textured(t)) => clamp(
                concrete_material(
                    t,
                    |p| textures.uv_average_float(p, TEXTURE_AVERAGE_GRID),
                    |p| textures.uv_average(p, TEXTURE_AVERAGE_GRID),
                )
                .diffuse_albedo(),
            ),
            Some(MaterialDesc::Mix {
                materials: m,
                amount,
            }) if depth < 64 => {
                // A textured amount by its mean over (u, v), as textured reflectances.
                let t = (textures.uv_average_float(*amount, TEXTURE_AVERAGE_GRID) as f64)
                    .clamp(0.0, 1.0);
                let x = albedo(materials, textures, memo, m[0], depth + 1);
                let y = albedo(materials, textures, memo, m[1], depth + 1);
                [0, 1, 2].map(|k| (1.0 - t) * x[k] + t * y[k])
            }
            _ => [0.0; 3],
        };
        if let Some(slot) = memo.get_mut(id as usize) {
            *slot = Some(a);
        }
        a
    }
    let mut memo = vec![None; materials.len()];
    (0..materials.len() as u32)
        .map(|id| albedo(materials, textures, &mut memo, id, 0))
        .collect()
}

/// pbrt's name of a material's type, for messages.
fn material_type(m: &MaterialDesc) -> &'static str {
    match m {
        MaterialDesc::Diffuse { .. } => "diffuse",
        MaterialDesc::Dielectric { .. } | MaterialDesc::RoughDielectric { .. } => "dielectric",
        MaterialDesc::Conductor(_) | MaterialDesc::RoughConductor { .. } => "conductor",
        MaterialDesc::ThinDielectric { .. } => "thindielectric",
        MaterialDesc::DiffuseTransmission { .. } => "diffusetransmission",
        MaterialDesc::Mix { .. } => "mix",
        MaterialDesc::CoatedDiffuse { .. } => "coateddiffuse",
        MaterialDesc::CoatedConductor { .. } => "coatedconductor",
        MaterialDesc::Textured(TexturedMaterialDesc::Diffuse { .. }) => "diffuse",
        MaterialDesc::Textured(TexturedMaterialDesc::RoughDielectric { .. }) => "dielectric",
        MaterialDesc::Textured(TexturedMaterialDesc::RoughConductor { .. }) => "conductor",
        MaterialDesc::Textured(TexturedMaterialDesc::CoatedDiffuse { .. }) => "coateddiffuse",
        MaterialDesc::Textured(TexturedMaterialDesc::CoatedConductor { .. }) => "coatedconductor",
        MaterialDesc::Textured(TexturedMaterialDesc::DiffuseTransmission { .. }) => {
            "diffusetransmission"
        }
        MaterialDesc::Interface => "interface",
    }
}

/// No back-side patch.
pub const NO_TWIN: u32 = u32::MAX;

/// The meshed scene the radiosity solver works on.
#[derive(Clone, Debug)]
pub struct RadiosityScene {
    /// Patches with their true emission `pi L`.
    pub patches: PatchSet,
    /// The input face of every patch.
    pub patch_face: Vec<u32>,
    /// The patch on the other side of the same surface (two-sided lights, `twosided`),
    /// or [`NO_TWIN`]. Back patches come after all front patches.
    pub twin: Vec<u32>,
    /// Number of front patches (the rest are back sides).
    pub front_count: usize,
    /// The unsubdivided faces (the occluders for shadow rays).
    pub faces: FaceMesh,
    pub tags: Vec<SurfaceTag>,
    /// Longest patch edge the meshing aimed at (scene units).
    pub max_edge: f64,
    /// Things approximated or left out, each once.
    pub warnings: Vec<Warning>,
}

impl RadiosityScene {
    /// The tag of patch `i`.
    pub fn tag(&self, i: usize) -> &SurfaceTag {
        &self.tags[self.faces.faces[self.patch_face[i] as usize].tag as usize]
    }

    /// Meshes the diffuse surfaces of `desc` with the patch size of `settings`.
    pub fn from_desc(
        desc: &SceneDesc,
        settings: &RadiositySettings,
    ) -> Result<RadiosityScene, SceneError> {
        let mut warnings = Vec::new();
        let textures = TextureSet::build(desc)?;
        let shapes = flatten(desc);
        // One warning per non-diffuse material, at the first shape that uses it.
        let mut approximated = vec![false; desc.materials.len()];
        let albedos = diffuse_albedos(&desc.materials, &textures);
        let mut tags = Vec::new();
        let mut image_means = HashMap::new();
        let mut shape_tags = Vec::with_capacity(shapes.len());
        for (k, (shape, _)) in shapes.iter().enumerate() {
            let Some(material) = desc.materials.get(shape.material as usize) else {
                return Err(SceneError::at(
                    &shape.loc,
                    format!("material index {} out of range", shape.material),
                ));
            };
            let reflectance = albedos[shape.material as usize];
            let exact = matches!(
                material,
                MaterialDesc::Diffuse { .. }
                    | MaterialDesc::Interface
                    | MaterialDesc::Textured(TexturedMaterialDesc::Diffuse { .. })
            );
            if !exact && !approximated[shape.material as usize] {
                approximated[shape.material as usize] = true;
                let [r, g, b] = reflectance;
                warnings.push(Warning {
                    loc: shape.loc.clone(),
                    message: format!(
                        "radiosity: material {} (\"{}\") is not diffuse; its patches use its diffuse albedo ({r:.3}, {g:.3}, {b:.3}) and its specular, glossy and transmitted light is left out",
                        shape.material,
                        material_type(material)
                    ),
                });
            }
            let emission = match &shape.area_light {
                None => [0.0; 3],
                Some(a) => area_light_mean(a, &shape.loc, &mut image_means, &mut warnings)?
                    .to_array()
                    .map(|l| std::f64::consts::PI * l.max(0.0) as f64),
            };
            let is_interface = matches!(material, MaterialDesc::Interface);
            // A shape cut out everywhere is not there at all (pbrt-v4 masks its
            // emission too); partial cut-outs are solved as opaque patches.
            let invisible = matches!(shape.alpha, Some(TexturedParam::Constant(a)) if a <= 0.0);
            if invisible || (is_interface && emission == [0.0; 3]) {
                shape_tags.push(None);
                continue;
            }
            if shape.alpha.is_some() {
                warnings.push(Warning {
                    loc: shape.loc.clone(),
                    message: "radiosity: the shape's alpha cut-out is not honoured by the solve; its patches are opaque".into(),
                });
            }
            tags.push(SurfaceTag {
                material: shape.material,
                emission,
                reflectance,
                shape: k as u32,
            });
            shape_tags.push(Some(tags.len() as u32 - 1));
        }

        let total_area: f64 = shapes
            .iter()
            .zip(&shape_tags)
            .filter(|(_, t)| t.is_some())
            .map(|((s, xf), _)| s.geometry.surface_area(&xf.as_mat4()) as f64)
            .sum();
        let max_area = settings
            .max_patch_area
            .unwrap_or(total_area / DEFAULT_PATCH_COUNT)
            .max(1e-30);
        let max_edge = max_area.sqrt();
        // Before meshing: the patch count the area asks for. The shapes' own
        // tessellation and the subdivision follow this edge length, so a request beyond
        // the budget is refused here, before either allocates.
        let param_loc = |name: &str| {
            desc.integrator
                .params
                .lookup(name)
                .map_or(&desc.integrator.loc, |p| &p.loc)
                .clone()
        };
        let patches_by_area = total_area / max_area;
        check_patch_budget(
            patches_by_area,
            settings,
            &param_loc("maxpatcharea"),
            &format!("maxpatcharea {max_area:.2e}"),
        )?;

        let mut faces = FaceMesh::new();
        for ((shape, xf), tag) in shapes.iter().zip(&shape_tags) {
            let Some(tag) = *tag else { continue };
            add_shape(&mut faces, shape, xf, tag, max_edge, &mut warnings)?;
        }
        // Every input face is split into at least subdivision^2 patches.
        let sub = settings.subdivision.max(1) as f64;
        check_patch_budget(
            patches_by_area + faces.faces.len() as f64 * sub * sub,
            settings,
            &param_loc("subdivision"),
            &format!(
                "subdivision {} on {} faces",
                settings.subdivision,
                faces.faces.len()
            ),
        )?;
        let Subdivision {
            mut set,
            mut patch_face,
            dropped,
        } = faces.subdivide(max_edge, settings.subdivision, |tag| {
            let t = &tags[tag as usize];
            (t.emission, t.reflectance)
        });
        let varying: Vec<bool> = tags
            .iter()
            .map(|t| {
                varies_over_surface(&desc.materials, t.material, 0)
                    || shapes[t.shape as usize]
                        .0
                        .area_light
                        .as_ref()
                        .is_some_and(|a| a.image.is_some())
            })
            .collect();
        if varying.contains(&true) {
            let (world, _) = World::build(desc)?;
            for (i, &face) in patch_face.iter().enumerate() {
                let tag = faces.faces[face as usize].tag as usize;
                if varying[tag] {
                    patch_means(&world, &mut set, i, tags[tag].material);
                }
            }
        }
        // Back sides: the same points in reverse order, so both sides share vertices
        // and every back patch knows its front twin.
        let front_count = set.len();
        let mut twin = vec![NO_TWIN; front_count];
        for i in 0..front_count {
            let tag = faces.faces[patch_face[i] as usize].tag;
            let t = &tags[tag as usize];
            let two_sided_light = shapes[t.shape as usize]
                .0
                .area_light
                .as_ref()
                .is_some_and(|a| a.two_sided);
            if !(two_sided_light
                || settings.two_sided && t.emission == [0.0; 3] && t.reflectance != [0.0; 3])
            {
                continue;
            }
            let p = &set.patches[i];
            let mut corners: Vec<u32> = p.corners[..p.corner_count as usize].to_vec();
            corners.reverse();
            let (emission, reflectance) = (p.emission, p.reflectance);
            if set.add_patch(&corners, emission, reflectance).is_ok() {
                twin[i] = set.len() as u32 - 1;
                twin.push(i as u32);
                patch_face.push(patch_face[i]);
            }
        }
        if dropped > 0 {
            warnings.push(Warning {
                loc: desc.camera.loc.clone(),
                message: format!("radiosity: {dropped} degenerate patch(es) dropped while meshing"),
            });
        }
        Ok(RadiosityScene {
            patches: set,
            patch_face,
            twin,
            front_count,
            faces,
            tags,
            max_edge,
            warnings,
        })
    }
}

/// Memory per patch, all stages together: the patch and its points, the display mesh,
/// and the solver's radiosity, unshot and irradiance per band (a round upper figure).
const BYTES_PER_PATCH: f64 = 512.0;

/// Refuses `patches` (an estimate) when they, or the dense factor matrix the matrix
/// solvers would build for them, do not fit the memory budget.
fn check_patch_budget(
    patches: f64,
    settings: &RadiositySettings,
    loc: &radiant_scene::FileLoc,
    what: &str,
) -> Result<(), SceneError> {
    let mut bytes = patches * BYTES_PER_PATCH;
    let matrix = matches!(
        settings.solver,
        SolverKind::GaussSeidel | SolverKind::Jacobi
    );
    if matrix {
        bytes += patches * patches * std::mem::size_of::<f64>() as f64;
    }
    radiant_render::budget::check(bytes).map_err(|over| {
        let matrix_note = if matrix {
            " and their dense form-factor matrix"
        } else {
            ""
        };
        SceneError::at(
            loc,
            format!("{what} would make {patches:.2e} patches{matrix_note} ({over})"),
        )
    })
}

/// The scene's shapes with their render-from-object transforms (f64), instances
/// flattened (their shapes never emit: pbrt has no area lights in instances).
fn flatten(desc: &SceneDesc) -> Vec<(ShapeDesc, DMat4)> {
    let mut out: Vec<(ShapeDesc, DMat4)> = desc
        .shapes
        .iter()
        .map(|s| (s.clone(), s.render_from_object.m.as_dmat4()))
        .collect();
    for inst in &desc.instances {
        let Some(object) = desc.objects.get(inst.object) else {
            continue;
        };
        let to_render = inst.render_from_instance.m.as_dmat4();
        for s in &object.shapes {
            let mut s = s.clone();
            s.area_light = None;
            let xf = to_render * s.render_from_object.m.as_dmat4();
            out.push((s, xf));
        }
    }
    out
}

/// Uniform scale of an affine map (cube root of the determinant's magnitude).
fn scale_of(xf: &DMat4) -> f64 {
    xf.determinant().abs().cbrt()
}

/// Adds the faces of one shape, wound so that their normal is the shape's front.
fn add_shape(
    faces: &mut FaceMesh,
    shape: &ShapeDesc,
    xf: &DMat4,
    tag: u32,
    max_edge: f64,
    warnings: &mut Vec<Warning>,
) -> Result<(), SceneError> {
    // pbrt: ReverseOrientation xor a handedness-swapping transform flips the front.
    let flip = shape.reverse_orientation ^ (xf.determinant() < 0.0);
    let to_render = |p: Vec3| xf.transform_point3(p.as_dvec3());
    match &shape.geometry {
        Geometry::TriangleMesh {
            positions,
            indices,
            normals,
            ..
        } => {
            let p: Vec<DVec3> = positions.iter().map(|&v| to_render(v)).collect();
            let index: Vec<u32> = p.iter().map(|&v| faces.point(v)).collect();
            // With shading normals the front follows them (pbrt-v4, as the world does).
            let normal_matrix = xf.inverse().transpose();
            let mut triangles = Vec::with_capacity(indices.len() / 3);
            for t in indices.chunks_exact(3) {
                let v = [t[0], t[1], t[2]].map(|i| i as usize);
                if v.iter().any(|&i| i >= p.len()) {
                    return Err(SceneError::at(&shape.loc, "triangle index out of range"));
                }
                let winding = (p[v[1]] - p[v[0]]).cross(p[v[2]] - p[v[0]]);
                let reverse = match normals {
                    Some(ns) => {
                        let sum = v.iter().map(|&i| ns[i].as_dvec3()).sum::<DVec3>();
                        let mut shading = normal_matrix.transform_vector3(sum);
                        if shape.reverse_orientation {
                            shading = -shading;
                        }
                        shading.dot(winding) < 0.0
                    }
                    None => flip,
                };
                let tri = v.map(|i| index[i]);
                triangles.push(if reverse {
                    [tri[0], tri[2], tri[1]]
                } else {
                    tri
                });
            }
            faces.add_triangles_merging(&triangles, tag);
        }
        Geometry::BilinearMesh {
            positions, indices, ..
        } => {
            let index: Vec<u32> = positions
                .iter()
                .map(|&v| faces.point(to_render(v)))
                .collect();
            let mut curved = 0usize;
            for q in indices.chunks_exact(4) {
                if q.iter().any(|&i| i as usize >= index.len()) {
                    return Err(SceneError::at(
                        &shape.loc,
                        "bilinear patch index out of range",
                    ));
                }
                // (p00, p10, p01, p11) around the boundary: p00, p10, p11, p01.
                let mut c = [q[0], q[1], q[3], q[2]].map(|i| index[i as usize]);
                if flip {
                    c.reverse();
                }
                if !faces.is_planar_convex(&c) {
                    curved += 1;
                }
                faces.add_bilinear(c, tag);
            }
            if curved > 0 {
                warnings.push(Warning {
                    loc: shape.loc.clone(),
                    message: format!(
                        "radiosity: {curved} curved bilinear patch(es) meshed on their surface, in triangles"
                    ),
                });
            }
        }
        Geometry::Sphere {
            radius,
            z_min,
            z_max,
            phi_max_deg,
        } => {
            let r = radius.abs() as f64;
            let (zl, zh) = sphere_z_range(*radius, *z_min, *z_max);
            let (zl, zh) = (zl as f64, zh as f64);
            let (theta_top, theta_bottom) = (
                (zh / r).clamp(-1.0, 1.0).acos(),
                (zl / r).clamp(-1.0, 1.0).acos(),
            );
            let phi_max = (*phi_max_deg as f64)
                .to_radians()
                .clamp(1e-6, std::f64::consts::TAU);
            let local_edge = max_edge / scale_of(xf);
            let rings =
                ((r * (theta_bottom - theta_top) / local_edge).ceil() as usize).clamp(2, 4096);
            let segments = ((r * phi_max / local_edge).ceil() as usize).clamp(3, 8192);
            let point = |ring: usize, seg: usize| {
                let theta = theta_top + (theta_bottom - theta_top) * ring as f64 / rings as f64;
                let phi = phi_max * seg as f64 / segments as f64;
                let (s, c) = theta.sin_cos();
                let local = if ring == 0 && zh >= r || ring == rings && zl <= -r {
                    DVec3::new(0.0, 0.0, c * r)
                } else {
                    DVec3::new(r * s * phi.cos(), r * s * phi.sin(), r * c)
                };
                xf.transform_point3(local)
            };
            let full = phi_max >= std::f64::consts::TAU - 1e-9;
            add_grid(faces, rings, segments, full, flip, tag, point, true);
        }
        Geometry::Disk {
            height,
            radius,
            inner_radius,
            phi_max_deg,
        } => {
            let (ri, ro) = ((*inner_radius as f64).max(0.0), (*radius as f64).max(0.0));
            if ro <= ri {
                return Ok(());
            }
            let phi_max = (*phi_max_deg as f64)
                .to_radians()
                .clamp(1e-6, std::f64::consts::TAU);
            let local_edge = max_edge / scale_of(xf);
            let rings = (((ro - ri) / local_edge).ceil() as usize).clamp(1, 4096);
            let segments = ((ro * phi_max / local_edge).ceil() as usize).clamp(3, 8192);
            let point = |ring: usize, seg: usize| {
                let rho = ri + (ro - ri) * ring as f64 / rings as f64;
                let phi = phi_max * seg as f64 / segments as f64;
                xf.transform_point3(DVec3::new(rho * phi.cos(), rho * phi.sin(), *height as f64))
            };
            let full = phi_max >= std::f64::consts::TAU - 1e-9;
            add_grid(faces, rings, segments, full, flip, tag, point, false);
        }
    }
    Ok(())
}

/// Faces of a (ring, segment) parametric grid: `point(ring, seg)` for rings
/// `0..=rings` and segments `0..=segments` (the last equal to the first when `wrap`).
/// With `rings_run_down` (spheres: ring 0 at the top) the cell (ring+1, seg), (ring+1,
/// seg+1), (ring, seg+1), (ring, seg) faces outwards; otherwise (disks, ring 0 inside)
/// (ring, seg), (ring+1, seg), (ring+1, seg+1), (ring, seg+1) faces +z. Cells whose
/// corners collapse (poles, a disk's centre) become triangles.
#[allow(clippy::too_many_arguments)]
fn add_grid(
    faces: &mut FaceMesh,
    rings: usize,
    segments: usize,
    wrap: bool,
    flip: bool,
    tag: u32,
    point: impl Fn(usize, usize) -> DVec3,
    rings_run_down: bool,
) {
    let columns = if wrap { segments } else { segments + 1 };
    let mut index = Vec::with_capacity((rings + 1) * columns);
    for ring in 0..=rings {
        for seg in 0..columns {
            index.push(faces.point(point(ring, seg)));
        }
    }
    let at = |ring: usize, seg: usize| index[ring * columns + seg % columns];
    for ring in 0..rings {
        for seg in 0..segments {
            let mut c = if rings_run_down {
                [
                    at(ring + 1, seg),
                    at(ring + 1, seg + 1),
                    at(ring, seg + 1),
                    at(ring, seg),
                ]
            } else {
                [
                    at(ring, seg),
                    at(ring + 1, seg),
                    at(ring + 1, seg + 1),
                    at(ring, seg + 1),
                ]
            };
            if flip {
                c.reverse();
            }
            let mut unique: Vec<u32> = Vec::with_capacity(4);
            for k in 0..4 {
                if c[k] != c[(k + 1) % 4] {
                    unique.push(c[k]);
                }
            }
            faces.add_face(&unique, tag);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_scene::builtin::cornell_box;

    #[test]
    fn cornell_box_meshes_into_planar_patches_of_the_right_area() {
        let desc = cornell_box();
        let settings = RadiositySettings {
            max_patch_area: Some(2000.0),
            ..RadiositySettings::default()
        };
        let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
        // The measured room: 5 walls, the light, two blocks of 5 faces each. Areas
        // from the scene's quads (two triangles each): their sum, to rounding.
        let mut expected = 0.0;
        for s in &desc.shapes {
            if let Geometry::TriangleMesh {
                positions, indices, ..
            } = &s.geometry
            {
                for t in indices.chunks_exact(3) {
                    let p = [t[0], t[1], t[2]].map(|i| positions[i as usize].as_dvec3());
                    expected += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                }
            }
        }
        let area = scene.patches.total_area();
        assert!((area / expected - 1.0).abs() < 1e-9, "{area} vs {expected}");
        // Every planar quad of the scene merged back (the red wall is not planar).
        let triangles = scene.faces.faces.iter().filter(|f| f.count == 3).count();
        assert_eq!(triangles, 2);
        assert!(
            scene.patches.len() > 900 && scene.patches.len() < 1400,
            "{}",
            scene.patches.len()
        );
        // Light patches emit pi L on their front, which faces down.
        let light: Vec<usize> = (0..scene.patches.len())
            .filter(|&i| scene.patches.patches[i].emission[0] > 0.0)
            .collect();
        let light_area: f64 = light.iter().map(|&i| scene.patches.patches[i].area).sum();
        assert!((light_area - 13650.0).abs() < 1e-6);
        assert!(
            light
                .iter()
                .all(|&i| scene.patches.patches[i].normal.y < -0.999)
        );
    }
}
