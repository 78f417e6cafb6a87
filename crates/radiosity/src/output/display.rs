//! Display of a solution: radiosities at the mesh vertices and their interpolation
//! across patches (Gouraud, "Continuous Shading of Curved Surfaces", IEEE Trans.
//! Computers 1971), and ray queries against the patches themselves.
//!
//! A vertex gets the area-weighted mean of the patches around it *on the same surface*:
//! patches of one material whose normals lie within [`SMOOTH_ANGLE_DEG`] of each other
//! (so the floor is never blended with a wall, while a tessellated sphere is smooth).
//! Where a surface's patches meet, each corner therefore has one display vertex per
//! surface, and values are continuous across every shared edge of a surface.

use glam::DVec3;

use crate::mesh::meshed_scene::{NO_TWIN, RadiosityScene};
use crate::mesh::patch::PatchSet;
use radiant_render::accel::TriangleBvh;
use radiant_render::geometry::Ray;

/// Patches whose normals differ by less than this are blended at shared vertices.
pub const SMOOTH_ANGLE_DEG: f64 = 35.0;

/// The display vertices of a patch mesh.
#[derive(Clone, Debug, Default)]
pub struct DisplayMesh {
    pub positions: Vec<DVec3>,
    /// Area-weighted mean normal of the patches sharing the vertex (unit).
    pub normals: Vec<DVec3>,
    /// For every patch corner (in patch corner order), its display vertex.
    pub corner_vertex: Vec<[u32; 4]>,
}

impl DisplayMesh {
    /// Groups the patch corners at every point into surfaces.
    pub fn new(scene: &RadiosityScene) -> DisplayMesh {
        let set = &scene.patches;
        let cos_limit = SMOOTH_ANGLE_DEG.to_radians().cos();
        // Incidence point -> (patch, corner), by counting sort.
        let mut start = vec![0u32; set.points.len() + 1];
        for p in &set.patches {
            for &c in &p.corners[..p.corner_count as usize] {
                start[c as usize + 1] += 1;
            }
        }
        for k in 1..start.len() {
            start[k] += start[k - 1];
        }
        let mut fill = start.clone();
        let mut incident = vec![(0u32, 0u8); start[set.points.len()] as usize];
        for (i, p) in set.patches.iter().enumerate() {
            for (k, &c) in p.corners[..p.corner_count as usize].iter().enumerate() {
                incident[fill[c as usize] as usize] = (i as u32, k as u8);
                fill[c as usize] += 1;
            }
        }
        let mut mesh = DisplayMesh {
            positions: Vec::new(),
            normals: Vec::new(),
            corner_vertex: vec![[u32::MAX; 4]; set.len()],
        };
        // Per point: clusters as (material, emitting, first normal, vertex).
        let mut clusters: Vec<(u32, bool, DVec3, u32)> = Vec::new();
        for point in 0..set.points.len() {
            clusters.clear();
            for &(i, k) in &incident[start[point] as usize..start[point + 1] as usize] {
                let patch = &set.patches[i as usize];
                let tag = scene.tag(i as usize);
                let emitting = tag.emission != [0.0; 3];
                let found = clusters.iter().find(|c| {
                    c.0 == tag.material && c.1 == emitting && c.2.dot(patch.normal) >= cos_limit
                });
                let vertex = match found {
                    Some(c) => c.3,
                    None => {
                        let v = mesh.positions.len() as u32;
                        mesh.positions.push(set.points[point]);
                        mesh.normals.push(DVec3::ZERO);
                        clusters.push((tag.material, emitting, patch.normal, v));
                        v
                    }
                };
                mesh.normals[vertex as usize] += patch.area * patch.normal;
                mesh.corner_vertex[i as usize][k as usize] = vertex;
            }
        }
        for n in &mut mesh.normals {
            *n = n.normalize_or_zero();
        }
        mesh
    }

    /// Number of display vertices.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Per-vertex values: the mean of `values` over the patches at each vertex, weighted
    /// by area times `weight` (e.g. zero for patches hidden inside solids).
    pub fn vertex_values(
        &self,
        set: &PatchSet,
        values: &[[f64; 3]],
        weight: impl Fn(usize) -> f64,
    ) -> Vec<[f64; 3]> {
        let mut sum = vec![[0.0; 3]; self.len()];
        let mut total = vec![0.0; self.len()];
        let mut plain = vec![[0.0; 3]; self.len()];
        let mut plain_total = vec![0.0; self.len()];
        for (i, patch) in set.patches.iter().enumerate() {
            let w = patch.area * weight(i);
            for &v in &self.corner_vertex[i][..patch.corner_count as usize] {
                let v = v as usize;
                for b in 0..3 {
                    sum[v][b] += w * values[i][b];
                    plain[v][b] += patch.area * values[i][b];
                }
                total[v] += w;
                plain_total[v] += patch.area;
            }
        }
        (0..self.len())
            .map(|v| {
                // Fall back to plain area weights where every patch had weight zero.
                let (s, t) = if total[v] > 0.0 {
                    (sum[v], total[v])
                } else {
                    (plain[v], plain_total[v])
                };
                s.map(|x| if t > 0.0 { x / t } else { 0.0 })
            })
            .collect()
    }
}

/// A ray hit on a patch, with the interpolation weights of its corners.
#[derive(Clone, Copy, Debug)]
pub struct PatchHit {
    pub t: f32,
    /// The patch facing the ray: the hit patch, or its back twin when the ray arrives
    /// from behind. `None` when it arrives at the back of a one-sided patch.
    pub patch: Option<usize>,
    /// The patch the ray struck (front side mesh).
    pub struck: usize,
    pub p: DVec3,
    /// Weights of the facing patch's corners (sum to 1).
    pub weights: [f64; 4],
    /// Weights of the struck patch's corners.
    pub weights_struck: [f64; 4],
}

/// Ray queries against the front patches (quads as two triangles).
pub struct PatchTracer {
    bvh: TriangleBvh,
    /// Triangle -> (patch, second half of a quad).
    triangles: Vec<(u32, bool)>,
}

impl PatchTracer {
    pub fn new(scene: &RadiosityScene) -> PatchTracer {
        let set = &scene.patches;
        let vertices: Vec<glam::Vec3> = set.points.iter().map(|p| p.as_vec3()).collect();
        let mut indices = Vec::new();
        let mut triangles = Vec::new();
        for (i, p) in set.patches.iter().enumerate().take(scene.front_count) {
            let c = p.corners;
            indices.push([c[0], c[1], c[2]]);
            triangles.push((i as u32, false));
            if p.corner_count == 4 {
                indices.push([c[0], c[2], c[3]]);
                triangles.push((i as u32, true));
            }
        }
        PatchTracer {
            bvh: TriangleBvh::build(&vertices, &indices),
            triangles,
        }
    }

    /// Whether anything blocks `ray` before `t_max`.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.bvh.occluded(ray, t_max)
    }

    /// The closest patch along `ray`.
    pub fn intersect(&self, scene: &RadiosityScene, ray: &Ray, t_max: f32) -> Option<PatchHit> {
        let hit = self.bvh.intersect(ray, t_max)?;
        let (patch, second) = self.triangles[hit.prim as usize];
        let i = patch as usize;
        let set = &scene.patches;
        let p = &set.patches[i];
        let b = hit.b.map(|v| v as f64);
        let corners = set.polygon(i);
        let c = corners.as_slice();
        let (point, mut weights) = if p.corner_count == 3 {
            (
                b[0] * c[0] + b[1] * c[1] + b[2] * c[2],
                [b[0], b[1], b[2], 0.0],
            )
        } else {
            let tri = if second {
                [c[0], c[2], c[3]]
            } else {
                [c[0], c[1], c[2]]
            };
            let x = b[0] * tri[0] + b[1] * tri[1] + b[2] * tri[2];
            (x, bilinear_weights(c, p.normal, x))
        };
        let weights_struck = weights;
        let front = ray.d.as_dvec3().dot(p.normal) < 0.0;
        let facing = if front {
            Some(i)
        } else {
            match scene.twin[i] {
                NO_TWIN => None,
                twin => {
                    // The twin lists the same corners in reverse order.
                    let n = p.corner_count as usize;
                    let mut reversed = [0.0; 4];
                    for k in 0..n {
                        reversed[n - 1 - k] = weights[k];
                    }
                    weights = reversed;
                    Some(twin as usize)
                }
            }
        };
        Some(PatchHit {
            t: hit.t,
            patch: facing,
            struck: i,
            p: point,
            weights,
            weights_struck,
        })
    }
}

/// Corner weights of the point `x` on the planar convex quad `c` for bilinear
/// interpolation: `(u, v)` with `x = (1-u)(1-v) c0 + u(1-v) c1 + uv c2 + (1-u)v c3`.
/// Eliminating `v` leaves a quadratic in `u` (solved in the quad's plane).
pub fn bilinear_weights(c: &[DVec3], normal: DVec3, x: DVec3) -> [f64; 4] {
    let (s, t) = crate::mesh::patch::tangent_frame(normal);
    let to2 = |v: DVec3| glam::DVec2::new(v.dot(s), v.dot(t));
    let q = to2(x - c[0]);
    let e1 = to2(c[1] - c[0]);
    let e2 = to2(c[3] - c[0]);
    let e3 = to2(c[0] - c[1] + c[2] - c[3]);
    let cross = |a: glam::DVec2, b: glam::DVec2| a.x * b.y - a.y * b.x;
    // cross(q, e2 + u e3) = u cross(e1, e2 + u e3)
    let a = cross(e1, e3);
    let b = cross(e1, e2) - cross(q, e3);
    let cc = -cross(q, e2);
    let scale = e1.length_squared().max(e2.length_squared());
    let u = if a.abs() <= 1e-12 * scale {
        if b != 0.0 { -cc / b } else { 0.0 }
    } else {
        let disc = (b * b - 4.0 * a * cc).max(0.0).sqrt();
        let r1 = (-b + disc) / (2.0 * a);
        let r2 = (-b - disc) / (2.0 * a);
        // The root inside [0, 1] (the other lies outside for a convex quad).
        if (r1 - 0.5).abs() <= (r2 - 0.5).abs() {
            r1
        } else {
            r2
        }
    }
    .clamp(0.0, 1.0);
    let side = e2 + u * e3;
    let v = if side.length_squared() > 0.0 {
        (q - u * e1).dot(side) / side.length_squared()
    } else {
        0.0
    }
    .clamp(0.0, 1.0);
    [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::RadiositySettings;
    use glam::Vec3;
    use radiant_scene::builtin::cornell_box;
    use radiant_scene::{FileLoc, ShapeDesc};

    /// A 4 x 3 rectangle in the plane y = 0 facing +y, and a wall x = 0 facing +x
    /// sharing its edge, both white.
    fn floor_and_wall(two_sided: bool) -> RadiosityScene {
        let mut desc = cornell_box();
        let quad = |p: [Vec3; 4]| ShapeDesc::quads(&[p], 0, FileLoc::builtin("test"));
        desc.shapes = vec![
            quad([
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, 3.0),
                Vec3::new(4.0, 0.0, 3.0),
                Vec3::new(4.0, 0.0, 0.0),
            ]),
            quad([
                Vec3::ZERO,
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::new(0.0, 2.0, 3.0),
                Vec3::new(0.0, 0.0, 3.0),
            ]),
        ];
        let settings = RadiositySettings {
            max_patch_area: Some(0.25),
            two_sided,
            ..RadiositySettings::default()
        };
        RadiosityScene::from_desc(&desc, &settings).unwrap()
    }

    #[test]
    fn vertices_reproduce_a_linear_field_and_keep_surfaces_apart() {
        // On a regular grid the area-weighted mean of the four cells' centre values of
        // a linear field is the field at their shared corner, to rounding.
        let scene = floor_and_wall(false);
        let mesh = DisplayMesh::new(&scene);
        let field = |p: DVec3| 1.0 + 2.0 * p.x - 0.5 * p.z + 3.0 * p.y;
        let values: Vec<[f64; 3]> = scene
            .patches
            .patches
            .iter()
            .map(|p| [field(p.centroid); 3])
            .collect();
        let at_vertex = mesh.vertex_values(&scene.patches, &values, |_| 1.0);
        let mut interior = 0;
        for (v, p) in mesh.positions.iter().enumerate() {
            let inside_floor = p.y == 0.0 && p.x > 0.0 && p.x < 4.0 && p.z > 0.0 && p.z < 3.0;
            if inside_floor {
                interior += 1;
                assert!((at_vertex[v][0] - field(*p)).abs() < 1e-12);
            }
        }
        assert_eq!(interior, 7 * 5);
        // The shared edge x = 0, y = 0 has one display vertex per surface.
        let on_edge = mesh
            .positions
            .iter()
            .filter(|p| p.x == 0.0 && p.y == 0.0)
            .count();
        assert_eq!(on_edge, 2 * 7);
        // Normals are the surfaces' own.
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!(n.y > 0.999 || n.x > 0.999, "{p} {n}");
        }
    }

    #[test]
    fn two_sided_surfaces_get_back_twins_that_rays_find_from_behind() {
        let scene = floor_and_wall(true);
        assert_eq!(scene.patches.len(), 2 * scene.front_count);
        for i in 0..scene.front_count {
            let twin = scene.twin[i] as usize;
            assert_eq!(scene.twin[twin] as usize, i);
            assert!(
                (scene.patches.patches[twin].normal + scene.patches.patches[i].normal).length()
                    < 1e-12
            );
        }
        let tracer = PatchTracer::new(&scene);
        let from_below = Ray::new(Vec3::new(1.1, -1.0, 1.3), Vec3::Y);
        let hit = tracer
            .intersect(&scene, &from_below, f32::INFINITY)
            .unwrap();
        let facing = hit.patch.unwrap();
        assert_eq!(facing, scene.twin[hit.struck] as usize);
        assert!(scene.patches.patches[facing].normal.y < -0.999);
        let one_sided = floor_and_wall(false);
        let hit = PatchTracer::new(&one_sided)
            .intersect(&one_sided, &from_below, f32::INFINITY)
            .unwrap();
        assert!(hit.patch.is_none());
    }

    #[test]
    fn bilinear_weights_invert_the_bilinear_map() {
        let c = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(3.0, 2.0, 0.0),
            DVec3::new(0.5, 3.0, 0.0),
        ];
        for &(u, v) in &[(0.2, 0.7), (0.9, 0.1), (0.5, 0.5), (0.0, 1.0)] {
            let x = (1.0 - u) * (1.0 - v) * c[0]
                + u * (1.0 - v) * c[1]
                + u * v * c[2]
                + (1.0 - u) * v * c[3];
            let w = bilinear_weights(&c, DVec3::Z, x);
            let expected = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
            for k in 0..4 {
                assert!((w[k] - expected[k]).abs() < 1e-12, "{w:?} vs {expected:?}");
            }
        }
    }
}
