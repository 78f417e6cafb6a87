//! `Shape` directives.
//!
//! - `"trianglemesh"`: `point3 P`, `integer indices` (may be omitted for exactly three
//!   vertices), `normal N`, `point2 uv`; `vector3 S` and `integer faceIndices` are read
//!   and ignored with a warning.
//! - `"bilinearmesh"`: `P`, `indices` (four per patch: p00 p10 p01 p11; may be omitted
//!   for exactly four vertices), `N`, `uv`.
//! - `"plymesh"`, `"objmesh"`: `string filename`, relative to the scene file (PLY may be
//!   gzip-compressed).
//! - `"loopsubdiv"`: `P`, `indices`, `integer levels` (default 3): subdivided at load
//!   time into a triangle mesh on the limit surface (see [`crate::subdiv`]).
//! - `"sphere"`: `radius` 1, `zmin` -radius, `zmax` radius, `phimax` 360.
//! - `"disk"`: `height` 0, `radius` 1, `innerradius` 0, `phimax` 360.
//!
//! Each shape takes the CTM as its render-from-object transform, the current material,
//! `ReverseOrientation` and the current area light; `alpha` (float or float texture,
//! default 1) makes it a cut-out.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::Parser;
use super::state::with_defaults;
use crate::desc::{AreaLightDesc, AreaLightImage, Geometry, ShapeDesc};
use crate::error::{FileLoc, SceneError};
use crate::mesh::{
    MeshData, first_non_finite2, first_non_finite3, first_out_of_range, repair_normals,
};
use crate::params::{ParamSet, ParamValue};
use crate::texture::{FloatParam, TexturedParam};
use crate::{obj, ply, subdiv};

/// pbrt-v4 shapes radiant does not render.
const SKIPPED_SHAPES: [&str; 6] = [
    "curve",
    "cylinder",
    "cone",
    "paraboloid",
    "hyperboloid",
    "nurbs",
];

impl Parser {
    pub(super) fn shape(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("Shape")?;
        let ps = with_defaults(self.param_list()?, &self.gs.defaults.shape);
        self.require_world("Shape", loc)?;
        let owner = format!("Shape \"{name}\"");
        let alpha = match self.float_texture_param(&ps, "alpha", 1.0)? {
            TexturedParam::Constant(a) if a >= 1.0 => None,
            a => Some(a),
        };
        ps.lookup("emissionfilename");
        let geometries = match name.as_str() {
            "trianglemesh" => vec![self.triangle_mesh(&ps, loc, &owner)?],
            "bilinearmesh" => vec![self.bilinear_mesh(&ps, loc, &owner)?],
            "plymesh" | "objmesh" => self.mesh_file(&name, &ps, loc, &owner)?,
            "loopsubdiv" => vec![loop_subdivision(&ps, loc)?],
            "sphere" => vec![sphere(&ps, loc)?],
            "disk" => vec![disk(&ps, loc)?],
            _ if SKIPPED_SHAPES.contains(&name.as_str()) => {
                ps.mark_all_used();
                self.warn(loc, format!("{owner} is not supported; shape skipped"));
                return Ok(());
            }
            _ => return Err(SceneError::at(loc, format!("unknown shape \"{name}\""))),
        };
        self.report_unused(&ps, &owner);
        self.add_shapes(geometries, alpha, loc);
        Ok(())
    }

    fn add_shapes(&mut self, geometries: Vec<Geometry>, alpha: Option<FloatParam>, loc: &FileLoc) {
        let render_from_object = self.gs.ctm;
        let material = self.current_material();
        let area_light = match (self.gs.area_light.clone(), self.object.is_some()) {
            (None, _) => None,
            (Some(_), true) => {
                if !self.object_area_light_warned {
                    self.object_area_light_warned = true;
                    self.warn(
                        loc,
                        "area lights inside object definitions lose their emission (as in pbrt-v4)",
                    );
                }
                None
            }
            (Some(al), false) => {
                let mut l = al.l * al.scale;
                let mut per_unit_mean = false;
                if let Some(power) = al.power {
                    // Φ = π A L per emitting side for a Lambertian emitter; an image
                    // counts by its mean luminance, divided out when it is read.
                    let area: f32 = geometries
                        .iter()
                        .map(|g| g.surface_area(&render_from_object.m))
                        .sum();
                    let sides = if al.two_sided { 2.0 } else { 1.0 };
                    let y = al.l.luminance();
                    if area > 0.0 && y > 0.0 {
                        l *= power / (radiant_math::PI * area * sides * y);
                        per_unit_mean = al.image.is_some();
                    } else {
                        self.warn(
                            loc,
                            "area light \"power\" ignored: the shape has no area or L is black",
                        );
                    }
                }
                Some(AreaLightDesc {
                    l,
                    two_sided: al.two_sided,
                    image: al.image.map(|image| AreaLightImage {
                        image,
                        per_unit_mean,
                    }),
                })
            }
        };
        let shapes = geometries.into_iter().map(|geometry| ShapeDesc {
            geometry,
            render_from_object,
            reverse_orientation: self.gs.reverse_orientation,
            material,
            area_light: area_light.clone(),
            alpha,
            loc: loc.clone(),
        });
        match &mut self.object {
            Some(object) => object.shapes.extend(shapes),
            None => self.shapes.extend(shapes),
        }
    }

    fn triangle_mesh(
        &mut self,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<Geometry, SceneError> {
        let (positions, indices, normals, uvs) = mesh_params(ps, loc, 3)?;
        let normals = self.mend_normals(owner, &positions, &indices, &[], normals);
        for extra in ["S", "faceIndices"] {
            if let Some(p) = ps.lookup(extra) {
                let at = p.loc.clone();
                self.warn(&at, format!("{owner}: \"{extra}\" is read but not used"));
            }
        }
        Ok(Geometry::TriangleMesh {
            positions,
            indices,
            normals,
            uvs,
        })
    }

    fn bilinear_mesh(
        &mut self,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<Geometry, SceneError> {
        let (positions, indices, normals, uvs) = mesh_params(ps, loc, 4)?;
        let normals = self.mend_normals(owner, &positions, &[], &indices, normals);
        Ok(Geometry::BilinearMesh {
            positions,
            indices,
            normals,
            uvs,
        })
    }

    /// Non-finite or zero normals become the faces' geometric normal at their vertex,
    /// with one warning for the mesh.
    fn mend_normals(
        &mut self,
        owner: &str,
        positions: &[Vec3],
        triangles: &[u32],
        quads: &[u32],
        normals: NormalsAt,
    ) -> Option<Vec<Vec3>> {
        let (mut normals, at) = normals?;
        let mended = repair_normals(positions, triangles, quads, &mut normals);
        if mended > 0 {
            self.warn(
                &at,
                format!(
                    "{owner}: {mended} of {} normals are not finite or zero; the faces' geometric normal is used there",
                    normals.len()
                ),
            );
        }
        Some(normals)
    }

    fn mesh_file(
        &mut self,
        kind: &str,
        ps: &ParamSet,
        loc: &FileLoc,
        owner: &str,
    ) -> Result<Vec<Geometry>, SceneError> {
        let Some((names, at)) = ps.strings("filename")? else {
            return Err(SceneError::at(
                loc,
                format!("{owner} needs \"string filename\""),
            ));
        };
        let [written] = names else {
            return Err(SceneError::at(at, "\"filename\" needs one value"));
        };
        let at = at.clone();
        let path = self.resolve_path(written);
        for unsupported in ["displacement", "edgelength"] {
            if let Some(p) = ps.lookup(unsupported) {
                let ploc = p.loc.clone();
                self.warn(
                    &ploc,
                    format!("{owner}: \"{unsupported}\" is not supported; ignored"),
                );
            }
        }
        let read = if kind == "plymesh" {
            ply::read_ply(&path)
        } else {
            obj::read_obj(&path)
        };
        let mut mesh = read.map_err(|e| at_param(e, &at, &path))?;
        mesh.normals = self.mend_normals(
            owner,
            &mesh.positions,
            &mesh.triangles,
            &mesh.quads,
            mesh.normals.take().map(|n| (n, at.clone())),
        );
        if mesh.polygons_split > 0 {
            self.warn(
                &at,
                format!(
                    "{owner}: {} polygons with more than 4 vertices split into triangle fans",
                    mesh.polygons_split
                ),
            );
        }
        for note in std::mem::take(&mut mesh.notes) {
            self.warn(&at, format!("{owner}: {}: {note}", path.display()));
        }
        if mesh.faces_skipped > 0 {
            self.warn(
                &at,
                format!(
                    "{owner}: {} faces with fewer than 3 vertices skipped",
                    mesh.faces_skipped
                ),
            );
        }
        Ok(mesh_geometries(mesh))
    }
}

/// A mesh file's error, moved to the parameter that named the file.
fn at_param(e: SceneError, at: &FileLoc, path: &Path) -> SceneError {
    match e {
        SceneError::File { message, .. } => {
            SceneError::at(at, format!("{}: {message}", path.display()))
        }
        other => other,
    }
}

fn mesh_geometries(mesh: MeshData) -> Vec<Geometry> {
    let mut out = Vec::new();
    if !mesh.triangles.is_empty() {
        out.push(Geometry::TriangleMesh {
            positions: mesh.positions.clone(),
            indices: mesh.triangles,
            normals: mesh.normals.clone(),
            uvs: mesh.uvs.clone(),
        });
    }
    if !mesh.quads.is_empty() {
        out.push(Geometry::BilinearMesh {
            positions: mesh.positions,
            indices: mesh.quads,
            normals: mesh.normals,
            uvs: mesh.uvs,
        });
    }
    out
}

/// Normals as read, with the location of their parameter (for the repair warning).
type NormalsAt = Option<(Vec<Vec3>, FileLoc)>;
type MeshParams = (Vec<Vec3>, Vec<u32>, NormalsAt, Option<Vec<Vec2>>);

/// `P`, `indices` (`per` per primitive), `N`, `uv`, validated.
fn mesh_params(ps: &ParamSet, loc: &FileLoc, per: usize) -> Result<MeshParams, SceneError> {
    let Some((positions, p_loc)) = ps.point3s("P")? else {
        return Err(SceneError::at(loc, "mesh needs \"point3 P\""));
    };
    let n = positions.len();
    if let Some((i, v)) = first_non_finite3(positions) {
        return Err(SceneError::at(
            p_loc,
            format!("\"P\": vertex {i} is not finite ({v})"),
        ));
    }
    let indices: Vec<u32> = match ps.ints("indices")? {
        Some((ix, i_loc)) => {
            if ix.len() % per != 0 || ix.is_empty() {
                return Err(SceneError::at(
                    i_loc,
                    format!(
                        "\"indices\": {} values is not a positive multiple of {per}",
                        ix.len()
                    ),
                ));
            }
            let ix: Vec<u32> = ix
                .iter()
                .map(|&i| u32::try_from(i).unwrap_or(u32::MAX))
                .collect();
            if let Some((k, i)) = first_out_of_range(&ix, n) {
                let shown = if i == u32::MAX {
                    "a negative index".to_string()
                } else {
                    format!("index {i}")
                };
                return Err(SceneError::at(
                    i_loc,
                    format!("\"indices\": entry {k} is {shown}, but there are {n} vertices"),
                ));
            }
            ix
        }
        None if n == per => (0..per as u32).collect(),
        None => {
            return Err(SceneError::at(
                loc,
                format!("mesh needs \"integer indices\" unless it has exactly {per} vertices"),
            ));
        }
    };
    let normals = match ps.normals("N")? {
        None => None,
        Some((normals, n_loc)) => {
            if normals.len() != n {
                return Err(SceneError::at(
                    n_loc,
                    format!("\"N\": {} normals for {n} vertices", normals.len()),
                ));
            }
            Some((normals.to_vec(), n_loc.clone()))
        }
    };
    let uvs = uv_param(ps, n)?;
    Ok((positions.to_vec(), indices, normals, uvs))
}

/// `point2 uv`, or pbrt-v3's `float uv` / `float st` as flat pairs.
fn uv_param(ps: &ParamSet, n: usize) -> Result<Option<Vec<Vec2>>, SceneError> {
    let Some(p) = ps.lookup("uv").or_else(|| ps.lookup("st")) else {
        return Ok(None);
    };
    let uvs: Vec<Vec2> = match &p.value {
        ParamValue::Point2(v) | ParamValue::Vector2(v) => v.clone(),
        ParamValue::Float(v) if v.len() % 2 == 0 => {
            v.chunks_exact(2).map(Vec2::from_slice).collect()
        }
        other => {
            return Err(SceneError::at(
                &p.loc,
                format!(
                    "\"{}\" has type \"{}\", expected \"point2\"",
                    p.name,
                    other.type_name()
                ),
            ));
        }
    };
    if uvs.len() != n {
        return Err(SceneError::at(
            &p.loc,
            format!("\"{}\": {} uvs for {n} vertices", p.name, uvs.len()),
        ));
    }
    if let Some((i, v)) = first_non_finite2(&uvs) {
        return Err(SceneError::at(
            &p.loc,
            format!("\"{}\": uv {i} is not finite ({v})", p.name),
        ));
    }
    Ok(Some(uvs))
}

/// More triangles than this from one `loopsubdiv` is surely a wrong `levels` (it would
/// take tens of gigabytes).
const MAX_SUBDIVIDED_TRIANGLES: u128 = 1 << 27;

/// Peak memory of `loopsubdiv` per triangle it makes: one triangle subdivided 10 and
/// 11 times peaks near 270 bytes per triangle for a whole render, of which about 100
/// are the renderer's BVH.
const SUBDIVISION_BYTES_PER_TRIANGLE: f64 = 180.0;

fn loop_subdivision(ps: &ParamSet, loc: &FileLoc) -> Result<Geometry, SceneError> {
    let levels = match ps.ints("levels")? {
        None => 3,
        Some(([l], at)) => u32::try_from(*l)
            .map_err(|_| SceneError::at(at, format!("\"levels\" must be at least 0, not {l}")))?,
        Some((_, at)) => return Err(SceneError::at(at, "\"levels\" needs one value")),
    };
    let (positions, indices, normals, uvs) = mesh_params(ps, loc, 3)?;
    if let Some((_, at)) = normals {
        return Err(SceneError::at(
            &at,
            "\"N\" is not a parameter of \"loopsubdiv\" (normals come from the limit surface)",
        ));
    }
    if uvs.is_some() {
        let at = ps
            .lookup("uv")
            .or_else(|| ps.lookup("st"))
            .map(|p| p.loc.clone());
        return Err(SceneError::at(
            at.as_ref().unwrap_or(loc),
            "\"uv\" is not a parameter of \"loopsubdiv\"",
        ));
    }
    let count = subdiv::triangle_count(indices.len() / 3, levels);
    if count > MAX_SUBDIVIDED_TRIANGLES {
        let at = ps.lookup("levels").map_or(loc, |p| &p.loc).clone();
        return Err(SceneError::at(
            &at,
            format!(
                "\"levels\" {levels} would make {count} triangles (at most {MAX_SUBDIVIDED_TRIANGLES})"
            ),
        ));
    }
    // The subdivision's working set (edge maps and vertex rings of the last level) is
    // far larger than its result, so it is checked against the memory budget before
    // any of it is made.
    let bytes = count as f64 * SUBDIVISION_BYTES_PER_TRIANGLE;
    if let Err(over) = crate::budget::check(bytes) {
        let at = ps.lookup("levels").map_or(loc, |p| &p.loc).clone();
        return Err(SceneError::at(
            &at,
            format!("\"levels\" {levels} would make {count} triangles, which need {over}"),
        ));
    }
    let s = subdiv::loop_subdivide(&positions, &indices, levels);
    Ok(Geometry::TriangleMesh {
        positions: s.positions,
        indices: s.indices,
        normals: Some(s.normals),
        uvs: None,
    })
}

fn positive(
    ps: &ParamSet,
    name: &str,
    default: f32,
    allow_zero: bool,
    loc: &FileLoc,
) -> Result<f32, SceneError> {
    let v = ps.finite_float(name, default)?;
    if v < 0.0 || (v == 0.0 && !allow_zero) {
        let at = ps.lookup(name).map_or(loc, |p| &p.loc);
        return Err(SceneError::at(
            at,
            format!("\"{name}\" must be positive, got {v}"),
        ));
    }
    Ok(v)
}

fn sphere(ps: &ParamSet, loc: &FileLoc) -> Result<Geometry, SceneError> {
    let radius = positive(ps, "radius", 1.0, false, loc)?;
    let z_min = ps.finite_float("zmin", -radius)?.clamp(-radius, radius);
    let z_max = ps.finite_float("zmax", radius)?.clamp(-radius, radius);
    Ok(Geometry::Sphere {
        radius,
        z_min: z_min.min(z_max),
        z_max: z_min.max(z_max),
        phi_max_deg: phi_max(ps)?,
    })
}

/// `phimax` in degrees: it must be positive; above 360 it is a full turn (pbrt-v4
/// clamps it to [0, 360], but a turn of 0 degrees or less has no surface at all).
fn phi_max(ps: &ParamSet) -> Result<f32, SceneError> {
    let v = ps.finite_float("phimax", 360.0)?;
    if v <= 0.0 {
        let at = &ps.lookup("phimax").expect("present").loc;
        return Err(SceneError::at(
            at,
            format!("\"phimax\" must lie in (0, 360] degrees, got {v}"),
        ));
    }
    Ok(v.min(360.0))
}

fn disk(ps: &ParamSet, loc: &FileLoc) -> Result<Geometry, SceneError> {
    Ok(Geometry::Disk {
        height: ps.finite_float("height", 0.0)?,
        radius: positive(ps, "radius", 1.0, false, loc)?,
        inner_radius: positive(ps, "innerradius", 0.0, true, loc)?,
        phi_max_deg: phi_max(ps)?,
    })
}
