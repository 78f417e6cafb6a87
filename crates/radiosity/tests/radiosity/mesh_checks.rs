//! Mesh checks shared by the meshing and refinement tests.

use std::collections::HashMap;

use radiant_math::DVec3;
use radiant_radiosity::mesh::meshed_scene::RadiosityScene;
use radiant_radiosity::output::display::DisplayMesh;

/// Distance from `p` to the segment `a b`.
pub fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    (a + t * (b - a) - p).length()
}

/// Edges of display vertices (one per point and surface) used by a single patch must
/// lie on an input face's boundary: one inside a face would be a T-junction (a
/// neighbour with a vertex in the middle of it); and no edge is used twice the same
/// way. Returns the number of such boundary edges, with `display` the mesh checked.
pub fn assert_conforming(scene: &RadiosityScene) -> (usize, DisplayMesh) {
    let mesh = DisplayMesh::new(scene);
    let mut uses = HashMap::new();
    for (p, c) in scene.patches.patches.iter().zip(&mesh.corner_vertex) {
        let n = p.corner_count as usize;
        for k in 0..n {
            *uses.entry((c[k], c[(k + 1) % n])).or_insert(0) += 1;
        }
    }
    let face_edges: Vec<(DVec3, DVec3)> = scene
        .faces
        .faces
        .iter()
        .flat_map(|f| {
            let n = f.count as usize;
            (0..n).map(move |k| (f.corners[k], f.corners[(k + 1) % n]))
        })
        .map(|(a, b)| {
            (
                scene.faces.points[a as usize],
                scene.faces.points[b as usize],
            )
        })
        .collect();
    let mut boundary = 0;
    for (&(a, b), &count) in &uses {
        assert_eq!(count, 1, "edge used {count} times the same way");
        if uses.contains_key(&(b, a)) {
            continue;
        }
        boundary += 1;
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let on_input_edge = face_edges
            .iter()
            .any(|&(u, v)| segment_distance(pa, u, v) < 1e-9 && segment_distance(pb, u, v) < 1e-9);
        assert!(on_input_edge, "edge {pa} - {pb} is open inside a face");
    }
    (boundary, mesh)
}
