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
    let (models, _materials) = tobj::load_obj(path, &options)
        .map_err(|e| SceneError::file(path, format!("cannot read OBJ file: {e}")))?;

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
