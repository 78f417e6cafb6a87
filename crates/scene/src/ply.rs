//! PLY meshes (`Shape "plymesh"`), ASCII and binary of either byte order, read with the
//! `ply-rs-bw` crate into plain structs.
//!
//! Vertex properties: `x y z`, optional `nx ny nz`, optional texture coordinates named
//! `u v`, `s t`, `texture_u texture_v` or `texture_s texture_t`. Faces: a list property
//! `vertex_indices` (or `vertex_index`). Triangles stay triangles, quads become bilinear
//! patches (as pbrt-v4 does), larger polygons are split into fans. Gzip-compressed
//! files (`.ply.gz`) are read as they are.

use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Property, PropertyAccess, PropertyAccessResult};

use super::error::SceneError;
use super::mesh::{MeshData, quad_to_patch, validate};

#[derive(Default)]
struct PlyVertex {
    p: [f32; 3],
    n: [f32; 3],
    uv: [f32; 2],
}

fn vertex_slot(name: &str) -> Option<(usize, usize)> {
    Some(match name {
        "x" => (0, 0),
        "y" => (0, 1),
        "z" => (0, 2),
        "nx" => (1, 0),
        "ny" => (1, 1),
        "nz" => (1, 2),
        "u" | "s" | "texture_u" | "texture_s" => (2, 0),
        "v" | "t" | "texture_v" | "texture_t" => (2, 1),
        _ => return None,
    })
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let (Some((group, k)), Some(v)) = (vertex_slot(name), property.to_f32_lossy()) else {
            return PropertyAccessResult::Ignored;
        };
        match group {
            0 => self.p[k] = v,
            1 => self.n[k] = v,
            _ => self.uv[k] = v,
        }
        PropertyAccessResult::Set
    }
}

/// One face's vertex list; `None` when the list held negative or non-integer entries.
#[derive(Default)]
struct PlyFace {
    indices: Option<Vec<u32>>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if name == "vertex_indices" || name == "vertex_index" {
            self.indices = property.to_u32_list();
            return PropertyAccessResult::Set;
        }
        PropertyAccessResult::Ignored
    }
}

/// Elements radiant does not use (edges, materials…): read past and dropped.
struct PlySkip;

impl PropertyAccess for PlySkip {
    fn new() -> Self {
        PlySkip
    }
}

fn has_all(def: &ElementDef, names: &[&str]) -> bool {
    names.iter().all(|n| def.properties.contains_key(*n))
}

fn has_uv(def: &ElementDef) -> bool {
    [
        ["u", "v"],
        ["s", "t"],
        ["texture_u", "texture_v"],
        ["texture_s", "texture_t"],
    ]
    .iter()
    .any(|pair| has_all(def, pair))
}

/// Reads a PLY file. Errors are `SceneError::File` naming the file; NaN or infinite
/// vertex data and out-of-range indices are errors naming the element.
pub fn read_ply(path: &Path) -> Result<MeshData, SceneError> {
    let fail = |message: String| SceneError::file(path, message);
    let file = crate::gz::open(path).map_err(|e| fail(format!("cannot open PLY file: {e}")))?;
    let mut reader = Reader::new(BufReader::new(file));
    let vertex_parser = Parser::<PlyVertex>::new();
    let header = vertex_parser
        .read_header(&mut reader)
        .map_err(|e| fail(format!("bad PLY header: {e}")))?;

    let mut vertices = None;
    let mut faces = Vec::new();
    let (mut has_normals, mut has_uvs) = (false, false);
    for (name, def) in &header.elements {
        let bad = |e: ply_rs_bw::parser::ParseError| fail(format!("bad PLY '{name}' data: {e}"));
        match name.as_str() {
            "vertex" => {
                if !has_all(def, &["x", "y", "z"]) {
                    return Err(fail("PLY vertices lack x, y or z".into()));
                }
                has_normals = has_all(def, &["nx", "ny", "nz"]);
                has_uvs = has_uv(def);
                vertices = Some(
                    vertex_parser
                        .read_payload_for_element(&mut reader, def, &header)
                        .map_err(bad)?,
                );
            }
            "face" => {
                faces = Parser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(bad)?;
            }
            _ => {
                Parser::<PlySkip>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(bad)?;
            }
        }
    }
    let vertices = vertices.ok_or_else(|| fail("PLY file has no vertex element".into()))?;

    let mut mesh = MeshData {
        positions: vertices.iter().map(|v| Vec3::from(v.p)).collect(),
        normals: has_normals.then(|| vertices.iter().map(|v| Vec3::from(v.n)).collect()),
        uvs: has_uvs.then(|| vertices.iter().map(|v| Vec2::from(v.uv)).collect()),
        ..Default::default()
    };
    for (f, face) in faces.iter().enumerate() {
        let Some(ix) = &face.indices else {
            return Err(fail(format!("face {f} has negative vertex indices")));
        };
        match ix.len() {
            0..=2 => mesh.faces_skipped += 1,
            3 => mesh.triangles.extend_from_slice(ix),
            4 => mesh
                .quads
                .extend_from_slice(&quad_to_patch([ix[0], ix[1], ix[2], ix[3]])),
            _ => {
                mesh.polygons_split += 1;
                for k in 1..ix.len() - 1 {
                    mesh.triangles.extend_from_slice(&[ix[0], ix[k], ix[k + 1]]);
                }
            }
        }
    }
    validate(&mesh).map_err(fail)?;
    Ok(mesh)
}
