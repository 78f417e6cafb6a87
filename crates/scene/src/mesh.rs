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
    /// What the file held that was read but dropped, for warnings.
    pub notes: Vec<String>,
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

/// Checks a mesh's data: finite positions and uvs, one normal and uv per vertex,
/// indices in range (non-finite or zero normals are mended by [`repair_normals`]). Returns a message naming the offending element.
pub fn validate(mesh: &MeshData) -> Result<(), String> {
    let n = mesh.positions.len();
    if let Some((i, p)) = first_non_finite3(&mesh.positions) {
        return Err(format!("vertex {i} has a non-finite position {p}"));
    }
    if let Some(normals) = &mesh.normals
        && normals.len() != n
    {
        return Err(format!("{} normals for {n} vertices", normals.len()));
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

/// Replaces each non-finite or zero vertex normal by the area-weighted normal of the
/// triangles and quads around the vertex (the geometric normal there; +z for a vertex
/// no face uses), as pbrt-v4 renders such meshes rather than refusing them. Returns how
/// many normals were replaced. Quads are taken as their two triangles (p00 p10 p11,
/// p00 p11 p01).
pub fn repair_normals(
    positions: &[Vec3],
    triangles: &[u32],
    quads: &[u32],
    normals: &mut [Vec3],
) -> usize {
    let bad = |n: Vec3| !n.is_finite() || n == Vec3::ZERO;
    if !normals.iter().any(|&n| bad(n)) {
        return 0;
    }
    let mut sum = vec![Vec3::ZERO; normals.len()];
    let mut add = |a: u32, b: u32, c: u32| {
        let (pa, pb, pc) = (
            positions[a as usize],
            positions[b as usize],
            positions[c as usize],
        );
        // Twice the area times the unit normal: area weighting for free.
        let n = (pb - pa).cross(pc - pa);
        for v in [a, b, c] {
            sum[v as usize] += n;
        }
    };
    for t in triangles.chunks_exact(3) {
        add(t[0], t[1], t[2]);
    }
    for q in quads.chunks_exact(4) {
        add(q[0], q[1], q[3]);
        add(q[0], q[3], q[2]);
    }
    let mut replaced = 0;
    for (n, s) in normals.iter_mut().zip(sum) {
        if bad(*n) {
            *n = s.try_normalize().unwrap_or(Vec3::Z);
            replaced += 1;
        }
    }
    replaced
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
    fn bad_normals_become_the_faces_normal() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.0, 0.0, 1.0)];
        // Two triangles meeting at vertices 0 and 1: one in z = 0, one in y = 0.
        let triangles = [0, 1, 2, 0, 3, 1];
        let mut normals = [Vec3::NAN, Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), Vec3::Y];
        assert_eq!(repair_normals(&positions, &triangles, &[], &mut normals), 2);
        // Equal areas: the mean of +z and +y.
        let expect = Vec3::new(0.0, 1.0, 1.0).normalize();
        assert!((normals[0] - expect).length() < 1e-6, "{}", normals[0]);
        assert!((normals[1] - expect).length() < 1e-6);
        // Good normals stay as they were, unnormalized ones too.
        assert_eq!(normals[2], Vec3::new(0.0, 0.0, 2.0));
        assert_eq!(normals[3], Vec3::Y);
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
