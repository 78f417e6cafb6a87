//! Wavefront OBJ meshes (`Shape "objmesh"`, a radiant extension), read with `tobj`:
//! polygons triangulated as fans, all groups merged into one mesh, one index per
//! vertex (positions duplicated where normals or uvs differ). Materials in the OBJ's
//! `.mtl` are ignored: the pbrt graphics state decides the material.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::error::SceneError;
use super::mesh::{MeshData, validate};

/// Reads an OBJ file. Normals and uvs are kept only when every group has them.
pub fn read_obj(path: &Path) -> Result<MeshData, SceneError> {
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj(path, &options).map_err(|e| {
        let message = match error_line(path, &options, &e) {
            Some((line, text)) => format!(
                "cannot read OBJ file: line {line}: {e} ('{}')",
                crate::token::excerpt(text.trim())
            ),
            None => format!("cannot read OBJ file: {e}"),
        };
        SceneError::file(path, message)
    })?;

    let all_have = |f: fn(&tobj::Mesh) -> bool| models.iter().all(|m| f(&m.mesh));
    let keep_normals = all_have(|m| m.normals.len() == m.positions.len());
    let keep_uvs = all_have(|m| m.texcoords.len() / 2 == m.positions.len() / 3);

    let mut mesh = MeshData {
        normals: keep_normals.then(Vec::new),
        uvs: keep_uvs.then(Vec::new),
        ..Default::default()
    };
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let triples =
            |v: &[f32]| -> Vec<Vec3> { v.chunks_exact(3).map(Vec3::from_slice).collect() };
        mesh.positions.extend(triples(&m.positions));
        if let Some(n) = &mut mesh.normals {
            n.extend(triples(&m.normals));
        }
        if let Some(uv) = &mut mesh.uvs {
            uv.extend(m.texcoords.chunks_exact(2).map(Vec2::from_slice));
        }
        mesh.triangles.extend(m.indices.iter().map(|i| base + i));
    }
    if mesh.triangles.is_empty() {
        return Err(SceneError::file(path, "OBJ file has no faces"));
    }
    validate(&mesh).map_err(|m| SceneError::file(path, m))?;
    Ok(mesh)
}

/// The line where `tobj` met `error`, and its text: `tobj` does not say, so the
/// shortest prefix of the file that fails the same way is found by bisection (only
/// on the error path; each try is one parse of a prefix).
fn error_line(
    path: &Path,
    options: &tobj::LoadOptions,
    error: &tobj::LoadError,
) -> Option<(usize, String)> {
    let text = crate::gz::open(path).ok().and_then(|mut f| {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut f, &mut s).ok()?;
        Some(s)
    })?;
    let ends: Vec<usize> = text
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .chain((!text.ends_with('\n')).then_some(text.len()))
        .collect();
    let fails = |lines: usize| {
        let mut prefix = &text.as_bytes()[..ends[lines - 1]];
        let no_materials = |_: &Path| Ok((Vec::new(), Default::default()));
        tobj::load_obj_buf(&mut prefix, options, no_materials)
            .err()
            .as_ref()
            == Some(error)
    };
    if ends.is_empty() || !fails(ends.len()) {
        return None;
    }
    let (mut lo, mut hi) = (1, ends.len());
    while lo < hi {
        let mid = (lo + hi) / 2;
        if fails(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let start = if lo == 1 { 0 } else { ends[lo - 2] };
    Some((lo, text[start..ends[lo - 1]].to_string()))
}
