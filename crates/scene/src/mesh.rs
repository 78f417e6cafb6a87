//! Mesh data read from files (PLY, OBJ) and the checks every mesh passes, whether it
//! comes from a file or from `trianglemesh` / `bilinearmesh` parameters.

use glam::{Vec2, Vec3};

/// A polygon mesh in object space: triangles, and quads kept as bilinear patches.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, when the file has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, when the file has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Three indices per triangle.
    pub triangles: Vec<u32>,
    /// Four indices per quad in pbrt's bilinear-patch order (p00, p10, p01, p11).
    pub quads: Vec<u32>,
    /// Polygons with more than four vertices, split into triangle fans.
    pub polygons_split: usize,
    /// Faces with fewer than three vertices, dropped.
    pub faces_skipped: usize,
}

/// A quad listed around its boundary (v0, v1, v2, v3), as PLY and OBJ list faces, in
/// pbrt's bilinear-patch order: p00 = v0, p10 = v1, p11 = v2, p01 = v3.
pub fn quad_to_patch(v: [u32; 4]) -> [u32; 4] {
    [v[0], v[1], v[3], v[2]]
}

/// The first non-finite vector, as (index, value).
pub fn first_non_finite3(values: &[Vec3]) -> Option<(usize, Vec3)> {
    values
        .iter()
        .copied()
        .enumerate()
        .find(|(_, v)| !v.is_finite())
}

/// The first non-finite 2-vector, as (index, value).
pub fn first_non_finite2(values: &[Vec2]) -> Option<(usize, Vec2)> {
    values
        .iter()
        .copied()
        .enumerate()
        .find(|(_, v)| !v.is_finite())
}

/// The first index that does not address one of `vertex_count` vertices, as
/// (position in the index list, index).
pub fn first_out_of_range(indices: &[u32], vertex_count: usize) -> Option<(usize, u32)> {
    indices
        .iter()
        .copied()
        .enumerate()
        .find(|&(_, i)| i as usize >= vertex_count)
}

/// Checks a mesh's data: finite positions, normals and uvs with one entry per vertex,
/// indices in range. Returns a message naming the offending element.
pub fn validate(mesh: &MeshData) -> Result<(), String> {
    let n = mesh.positions.len();
    if let Some((i, p)) = first_non_finite3(&mesh.positions) {
        return Err(format!("vertex {i} has a non-finite position {p}"));
    }
    if let Some(normals) = &mesh.normals {
        if normals.len() != n {
            return Err(format!("{} normals for {n} vertices", normals.len()));
        }
        if let Some((i, v)) = first_non_finite3(normals) {
            return Err(format!("vertex {i} has a non-finite normal {v}"));
        }
    }
    if let Some(uvs) = &mesh.uvs {
        if uvs.len() != n {
            return Err(format!("{} uvs for {n} vertices", uvs.len()));
        }
        if let Some((i, v)) = first_non_finite2(uvs) {
            return Err(format!("vertex {i} has a non-finite uv {v}"));
        }
    }
    for (what, list, per) in [("triangle", &mesh.triangles, 3), ("quad", &mesh.quads, 4)] {
        if let Some((k, i)) = first_out_of_range(list, n) {
            return Err(format!(
                "{what} {} uses vertex {i}, but there are only {n} vertices",
                k / per
            ));
        }
    }
    Ok(())
}

/// Area of the bilinear patch (p00, p10, p01, p11): the integral of |∂p/∂u × ∂p/∂v|
/// over the unit square by 4×4 Gauss–Legendre quadrature (exact for planar patches,
/// and accurate to < 1e-4 relative for the gently twisted ones scenes use).
pub fn bilinear_patch_area(p: [Vec3; 4]) -> f32 {
    const NODES: [f32; 4] = [0.069_431_85, 0.330_009_5, 0.669_990_5, 0.930_568_2];
    const WEIGHTS: [f32; 4] = [0.173_927_42, 0.326_072_58, 0.326_072_58, 0.173_927_42];
    let [p00, p10, p01, p11] = p;
    let mut area = 0.0;
    for (u, wu) in NODES.iter().zip(WEIGHTS) {
        for (v, wv) in NODES.iter().zip(WEIGHTS) {
            let dpdu = (p10 - p00) * (1.0 - v) + (p11 - p01) * *v;
            let dpdv = (p01 - p00) * (1.0 - u) + (p11 - p10) * *u;
            area += wu * wv * dpdu.cross(dpdv).length();
        }
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_bad_element() {
        let mut m = MeshData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![0, 1, 2],
            ..Default::default()
        };
        assert!(validate(&m).is_ok());
        m.triangles.extend([0, 1, 3]);
        assert!(
            validate(&m)
                .unwrap_err()
                .contains("triangle 1 uses vertex 3")
        );
        m.triangles.truncate(3);
        m.positions[2].y = f32::NAN;
        assert!(validate(&m).unwrap_err().contains("vertex 2"));
    }

    #[test]
    fn patch_area_of_a_planar_quad_and_a_twisted_one() {
        let square = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        assert!((bilinear_patch_area(square) - 1.0).abs() < 1e-6);
        // Hyperbolic paraboloid z = uv over the unit square: area
        // ∫∫ sqrt(1 + u² + v²) du dv = 1.28079 (numerical value of the closed form).
        let twisted = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 1.0)];
        assert!((bilinear_patch_area(twisted) - 1.28079).abs() < 1e-4);
    }
}
