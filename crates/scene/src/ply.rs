//! PLY meshes (`Shape "plymesh"`), ASCII and binary of either byte order, read with the
//! `ply-rs-bw` crate into plain structs.
//!
//! Vertex properties: `x y z`, optional `nx ny nz`, optional texture coordinates named
//! `u v`, `s t`, `texture_u texture_v` or `texture_s texture_t`. Faces: a list property
//! `vertex_indices` (or `vertex_index`). Triangles stay triangles, quads become bilinear
//! patches (as pbrt-v4 does), larger polygons are split into fans. Gzip-compressed
//! files (`.ply.gz`) are read as they are.

use std::io::{BufReader, Read};
use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Property, PropertyAccess, PropertyAccessResult, PropertyType,
};

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

/// The vertex properties of one attribute that are present, when some but not all of
/// them are (the attribute is then dropped, which deserves a note).
fn partial(def: &ElementDef, names: &[&str]) -> Option<String> {
    let present: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| def.properties.contains_key(*n))
        .collect();
    (!present.is_empty() && present.len() < names.len()).then(|| present.join(", "))
}

/// Notes on vertex properties present without their partners (`nx ny` without `nz`,
/// `u` without `v`): those are not read.
fn partial_vertex_notes(def: &ElementDef) -> Vec<String> {
    let mut notes = Vec::new();
    if let Some(found) = partial(def, &["nx", "ny", "nz"]) {
        notes.push(format!(
            "vertex normals need nx, ny and nz, but the file has only {found}; normals ignored"
        ));
    }
    if !has_uv(def) {
        for pair in [
            ["u", "v"],
            ["s", "t"],
            ["texture_u", "texture_v"],
            ["texture_s", "texture_t"],
        ] {
            if let Some(found) = partial(def, &pair) {
                notes.push(format!(
                    "texture coordinates need {} and {}, but the file has only {found}; texture coordinates ignored",
                    pair[0], pair[1]
                ));
            }
        }
    }
    notes
}

/// Reads an ASCII element list one line per element, as `ply-rs-bw` does, but refuses
/// a line with more values than the element's properties take (the library ignores
/// them, and they mean the header and the data disagree).
fn read_ascii<E: PropertyAccess, R: std::io::BufRead>(
    reader: &mut Reader<R>,
    def: &ElementDef,
) -> Result<Vec<E>, String> {
    let parser = Parser::<E>::new();
    let mut out = Vec::with_capacity(def.count.min(1 << 20));
    let mut line = String::new();
    for i in 0..def.count {
        line.clear();
        let read = reader
            .get_mut()
            .read_line(&mut line)
            .map_err(|e| e.to_string())?;
        if read == 0 {
            return Err(format!(
                "the file ends after {i} of its {} '{}' elements",
                def.count, def.name
            ));
        }
        let element = parser
            .read_ascii_element(&line, def)
            .map_err(|e| format!("'{}' {i}: {e}", def.name))?;
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if let Some(taken) = ascii_values_taken(&tokens, def)
            && tokens.len() > taken
        {
            return Err(format!(
                "'{}' {i} has {} values on its line, but its properties take {taken}",
                def.name,
                tokens.len()
            ));
        }
        out.push(element);
    }
    Ok(out)
}

/// How many values of an ASCII line an element's properties take (a list takes its
/// count and that many entries); `None` when a count cannot be read.
fn ascii_values_taken(tokens: &[&str], def: &ElementDef) -> Option<usize> {
    let mut at = 0;
    for p in def.properties.values() {
        at += match p.data_type {
            PropertyType::Scalar(_) => 1,
            PropertyType::List(..) => 1 + tokens.get(at)?.parse::<usize>().ok()?,
        };
    }
    Some(at)
}

/// Reads a PLY file. Errors are `SceneError::File` naming the file; NaN or infinite
/// vertex data, out-of-range indices, faces without a vertex index list and data the
/// header does not describe (extra values on an ASCII line, bytes after the last
/// element) are errors naming the element. What is read but dropped (a partial normal
/// or uv, a file without faces) is noted in [`MeshData::notes`].
pub fn read_ply(path: &Path) -> Result<MeshData, SceneError> {
    let fail = |message: String| SceneError::file(path, message);
    let file = crate::gz::open(path).map_err(|e| fail(format!("cannot open PLY file: {e}")))?;
    let mut reader = Reader::new(BufReader::new(file));
    let vertex_parser = Parser::<PlyVertex>::new();
    let header = vertex_parser
        .read_header(&mut reader)
        .map_err(|e| fail(format!("bad PLY header: {e}")))?;
    let ascii = header.encoding == Encoding::Ascii;

    let mut vertices = None;
    let mut faces = None;
    let (mut has_normals, mut has_uvs) = (false, false);
    let mut notes = Vec::new();
    for (name, def) in &header.elements {
        let bad = |e: String| fail(format!("bad PLY '{name}' data: {e}"));
        match name.as_str() {
            "vertex" => {
                if !has_all(def, &["x", "y", "z"]) {
                    return Err(fail("PLY vertices lack x, y or z".into()));
                }
                has_normals = has_all(def, &["nx", "ny", "nz"]);
                has_uvs = has_uv(def);
                notes.extend(partial_vertex_notes(def));
                vertices = Some(if ascii {
                    read_ascii::<PlyVertex, _>(&mut reader, def).map_err(bad)?
                } else {
                    vertex_parser
                        .read_payload_for_element(&mut reader, def, &header)
                        .map_err(|e| bad(e.to_string()))?
                });
            }
            "face" => {
                if !def.properties.contains_key("vertex_indices")
                    && !def.properties.contains_key("vertex_index")
                {
                    let seen: Vec<String> =
                        def.properties.keys().map(|k| format!("'{k}'")).collect();
                    return Err(fail(format!(
                        "the PLY 'face' element has no vertex index list (a list property named vertex_indices or vertex_index); its properties are {}",
                        if seen.is_empty() {
                            "none".to_string()
                        } else {
                            seen.join(", ")
                        }
                    )));
                }
                faces = Some(if ascii {
                    read_ascii::<PlyFace, _>(&mut reader, def).map_err(bad)?
                } else {
                    Parser::<PlyFace>::new()
                        .read_payload_for_element(&mut reader, def, &header)
                        .map_err(|e| bad(e.to_string()))?
                });
            }
            _ => {
                if ascii {
                    read_ascii::<PlySkip, _>(&mut reader, def).map_err(bad)?;
                } else {
                    Parser::<PlySkip>::new()
                        .read_payload_for_element(&mut reader, def, &header)
                        .map_err(|e| bad(e.to_string()))?;
                }
            }
        }
    }
    let vertices = vertices.ok_or_else(|| fail("PLY file has no vertex element".into()))?;
    trailing_data(reader.get_mut(), ascii).map_err(fail)?;

    let mut mesh = MeshData {
        positions: vertices.iter().map(|v| Vec3::from(v.p)).collect(),
        normals: has_normals.then(|| vertices.iter().map(|v| Vec3::from(v.n)).collect()),
        uvs: has_uvs.then(|| vertices.iter().map(|v| Vec2::from(v.uv)).collect()),
        ..Default::default()
    };
    let no_faces = faces.is_none();
    for (f, face) in faces.iter().flatten().enumerate() {
        let Some(ix) = &face.indices else {
            return Err(fail(format!(
                "face {f} has negative or non-integer vertex indices"
            )));
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
    if mesh.triangles.is_empty() && mesh.quads.is_empty() {
        notes.push(if no_faces {
            "the PLY file has no 'face' element (only points): the mesh has no triangles and renders nothing".to_string()
        } else {
            "the PLY file has no faces with 3 or more vertices: the mesh renders nothing".to_string()
        });
    }
    mesh.notes = notes;
    validate(&mesh).map_err(fail)?;
    Ok(mesh)
}

/// Refuses data after the last element: any byte in a binary file, anything but white
/// space in an ASCII one. Such data means the header's counts are wrong (or the file
/// was joined to another), so what was read is not what was meant.
fn trailing_data<R: std::io::BufRead>(rest: &mut R, ascii: bool) -> Result<(), String> {
    let mut extra = Vec::new();
    rest.take(1 << 16)
        .read_to_end(&mut extra)
        .map_err(|e| format!("cannot read PLY file: {e}"))?;
    let garbage = if ascii {
        extra.iter().any(|b| !b.is_ascii_whitespace())
    } else {
        !extra.is_empty()
    };
    if garbage {
        let size = if extra.len() == 1 << 16 {
            "at least 64 KiB".to_string()
        } else {
            format!("{} bytes", extra.len())
        };
        return Err(format!(
            "{size} of data after the last element the header declares (wrong element counts?)"
        ));
    }
    Ok(())
}
