//! BVH tests: every query must equal brute force over the same primitives.

use super::displaced_sphere::geodesic_sphere;
use super::{Bvh, TriangleBvh};
use crate::geometry::triangle::{WatertightRay, intersect_triangle};
use crate::geometry::{Aabb, Ray, Sphere};
use glam::{Vec2, Vec3};
use radiant_math::Transform;
use radiant_math::hash::Pcg32;
use radiant_math::sampling::uniform_sphere;

fn rv(rng: &mut Pcg32) -> Vec3 {
    Vec3::new(rng.uniform(), rng.uniform(), rng.uniform())
}

/// A soup mixing ordinary, axis-aligned, zero-area (collinear, coincident) and very thin
/// triangles, with shared vertices and coordinates snapped to a coarse grid so that many
/// rays pass exactly through edges and vertices and lie exactly in faces.
fn soup(rng: &mut Pcg32, n: usize) -> Vec<[Vec3; 3]> {
    let snap = |v: Vec3| (v * 8.0).round() / 8.0;
    let mut tris = Vec::with_capacity(n);
    for i in 0..n {
        let c = rv(rng) * 10.0;
        let p = [c + rv(rng) - 0.5, c + rv(rng) - 0.5, c + rv(rng) - 0.5].map(snap);
        let t = match i % 6 {
            0 => [p[0], p[1], 0.5 * (p[0] + p[1])],      // collinear
            1 => [p[0], p[0], p[0]],                     // a point
            2 => p.map(|v| Vec3::new(v.x, v.y, p[0].z)), // in a plane z = const
            3 => [p[0], p[1], p[1] + Vec3::splat(1e-6)], // sliver
            _ => p,
        };
        tris.push(t);
    }
    tris
}

/// Rays from random points towards random vertices, edge midpoints and random points,
/// with some exactly axis-parallel directions and some in a face's plane.
fn rays(rng: &mut Pcg32, tris: &[[Vec3; 3]], n: usize) -> Vec<Ray> {
    (0..n)
        .map(|i| {
            let o = rv(rng) * 14.0 - Vec3::splat(2.0);
            let t = tris[(rng.next_u32() as usize) % tris.len()];
            let target = match i % 5 {
                0 => t[0],
                1 => 0.5 * (t[1] + t[2]),
                2 => rv(rng) * 10.0,
                3 => return Ray::new(t[0] - Vec3::X * 5.0 * rng.uniform(), Vec3::X), // along x
                _ => return Ray::new(t[0] - (t[1] - t[0]), t[1] - t[0]), // in the face plane
            };
            Ray::new(o, target - o)
        })
        .collect()
}

fn brute_closest(tris: &[[Vec3; 3]], ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
    let wr = WatertightRay::new(ray);
    let mut best: Option<(f32, u32)> = None;
    for (i, t) in tris.iter().enumerate() {
        let limit = best.map_or(t_max, |b| b.0);
        if let Some(h) = intersect_triangle(&wr, t[0], t[1], t[2], limit) {
            best = Some((h.t, i as u32));
        }
    }
    best
}

fn tri_bounds(tris: &[[Vec3; 3]]) -> Vec<Aabb> {
    tris.iter().map(|t| Aabb::from_points(t)).collect()
}

#[test]
fn triangle_bvh_and_generic_bvh_equal_brute_force() {
    let mut rng = Pcg32::new(42, 7);
    let mut checked_hits = 0;
    for (round, n) in [1usize, 2, 5, 17, 100, 1000, 3000].into_iter().enumerate() {
        let tris = soup(&mut rng, n);
        let tbvh = TriangleBvh::from_soup(&tris);
        // The same soup with a third of it emitting: a tree whose leaves keep them apart.
        let emitting: Vec<bool> = (0..n).map(|i| i % 3 == 1).collect();
        let split = TriangleBvh::from_soup_with_emitters(&tris, &emitting);
        let bvh = Bvh::build(&tri_bounds(&tris));
        // Those with two equal corners (the points, and any the grid snapped) are left
        // out; the brute force below still tests them.
        let kept = tris
            .iter()
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
            .count();
        assert_eq!(tbvh.triangle_count(), kept);
        assert_eq!(split.triangle_count(), kept);
        for ray in rays(&mut rng, &tris, 1500) {
            let wr = WatertightRay::new(&ray);
            for t_max in [f32::INFINITY, 5.0 + round as f32] {
                let expect = brute_closest(&tris, &ray, t_max);
                let got = tbvh.intersect(&ray, t_max);
                // Equal distances (bit-exact: same kernel); the triangle may differ on a tie.
                assert_eq!(got.map(|h| h.t), expect.map(|e| e.0), "n={n} {ray:?}");
                let got_split = split.intersect(&ray, t_max);
                assert_eq!(got_split.map(|h| h.t), expect.map(|e| e.0), "n={n} {ray:?}");
                assert_eq!(split.occluded(&ray, t_max), expect.is_some());
                if let (Some(g), Some(e)) = (got, expect) {
                    checked_hits += 1;
                    let gp = tris[g.prim as usize];
                    let again =
                        intersect_triangle(&wr, gp[0], gp[1], gp[2], f32::INFINITY).unwrap();
                    assert_eq!(again.t, e.0);
                    assert_eq!(again.b, g.b);
                }
                let mut hit_prim = None;
                let generic = bvh.closest_hit(&ray, t_max, |i, t_max| {
                    let p = tris[i as usize];
                    let h = intersect_triangle(&wr, p[0], p[1], p[2], t_max)?;
                    hit_prim = Some(i);
                    Some(h.t)
                });
                assert_eq!(generic, expect.map(|e| e.0));
                assert_eq!(generic.is_some(), hit_prim.is_some());
                let any = expect.is_some();
                assert_eq!(tbvh.occluded(&ray, t_max), any);
                let generic_any = bvh.any_hit(&ray, t_max, |i, t_max| {
                    let p = tris[i as usize];
                    intersect_triangle(&wr, p[0], p[1], p[2], t_max).is_some()
                });
                assert_eq!(generic_any, any);
            }
        }
    }
    // Hits on the slivers (one ulp wide) have a distance whose sign the triangle test's
    // rounding-error bound cannot certify; they are refused alike by every kernel.
    assert!(checked_hits > 4500, "{checked_hits}");
}

/// The 8-lane AVX kernels (in both encodings) and the 4-lane ones must report the same hit, bit for bit
/// (distance, triangle on ties, barycentrics), and the same occlusion: on the edge-case
/// soups, where rays run through edges, vertices and face planes, and on a closed mesh.
#[test]
fn avx_and_sse_kernels_give_identical_hits() {
    let mut rng = Pcg32::new(11, 5);
    let mut scenes: Vec<Vec<[Vec3; 3]>> = [3usize, 9, 36, 500, 4000]
        .into_iter()
        .map(|n| soup(&mut rng, n))
        .collect();
    let sphere = geodesic_sphere(20);
    scenes.push(
        sphere
            .triangles
            .iter()
            .map(|t| t.map(|i| sphere.vertices[i as usize]))
            .collect(),
    );
    let mut hits = 0;
    for tris in &scenes {
        let wide = TriangleBvh::from_soup(tris);
        let narrow = wide.clone().without_avx();
        assert!(!narrow.uses_avx());
        #[cfg(target_arch = "x86_64")]
        let vex = wide.clone().without_evex();
        #[cfg(not(target_arch = "x86_64"))]
        let vex = wide.clone();
        assert!(!vex.uses_evex());
        let mut queries = rays(&mut rng, tris, 3000);
        // Rays from inside the sphere too, so that closest hits lie behind other leaves.
        queries.extend((0..500).map(|_| Ray::new((rv(&mut rng) - 0.5) * 0.5, rv(&mut rng) - 0.5)));
        for ray in &queries {
            for t_max in [f32::INFINITY, 3.0, 0.5] {
                let (a, b) = (wide.intersect(ray, t_max), narrow.intersect(ray, t_max));
                assert_eq!(a, b, "{ray:?} t_max {t_max}");
                assert_eq!(vex.intersect(ray, t_max), b, "{ray:?} t_max {t_max}");
                hits += usize::from(a.is_some());
                assert_eq!(wide.occluded(ray, t_max), narrow.occluded(ray, t_max));
                assert_eq!(vex.occluded(ray, t_max), narrow.occluded(ray, t_max));
            }
        }
    }
    assert!(hits > 10_000, "{hits}");
    if !TriangleBvh::from_soup(&scenes[0]).uses_avx() {
        eprintln!("this processor has no AVX: only the 4-lane kernels were compared");
    } else if !TriangleBvh::from_soup(&scenes[0]).uses_evex() {
        eprintln!("this processor has no AVX-512VL: the EVEX kernels were not compared");
    }
}

#[test]
fn closed_mesh_does_not_leak_through_the_bvh() {
    // The watertight test survives the box culling (Ize's conservative exit distance):
    // rays from inside a closed sphere towards its vertices and edge midpoints all hit.
    let m = geodesic_sphere(12);
    let bvh = TriangleBvh::build(&m.vertices, &m.triangles);
    let mut rng = Pcg32::new(3, 3);
    let mut misses = 0;
    let mut n = 0;
    for (k, t) in m.triangles.iter().enumerate() {
        let o = (rv(&mut rng) - 0.5) * 0.8 * (k % 7) as f32 / 7.0;
        let p = t.map(|i| m.vertices[i as usize]);
        for target in [p[0], 0.5 * (p[0] + p[1]), 0.5 * (p[1] + p[2])] {
            n += 1;
            misses += usize::from(
                bvh.intersect(&Ray::new(o, target - o), f32::INFINITY)
                    .is_none(),
            );
            misses += usize::from(!bvh.occluded(&Ray::new(o, target - o), f32::INFINITY));
        }
    }
    assert!(n > 8000);
    assert_eq!(misses, 0);
}

#[test]
fn generic_bvh_over_spheres_equals_brute_force() {
    let mut rng = Pcg32::new(5, 9);
    let spheres: Vec<(Vec3, f32)> = (0..500)
        .map(|_| (rv(&mut rng) * 20.0, 0.05 + rng.uniform() * 0.6))
        .collect();
    let shape = |i: u32| {
        let (c, r) = spheres[i as usize];
        (c, Sphere::full(r).unwrap())
    };
    let bounds: Vec<Aabb> = spheres
        .iter()
        .map(|&(c, r)| Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r)))
        .collect();
    let bvh = Bvh::build(&bounds);
    let hit = |i: u32, ray: &Ray, t_max: f32| {
        let (c, s) = shape(i);
        s.intersect(&Ray::new(ray.o - c, ray.d), t_max).map(|h| h.t)
    };
    let mut hits = 0;
    for _ in 0..3000 {
        let o = rv(&mut rng) * 24.0 - Vec3::splat(2.0);
        let ray = Ray::new(o, uniform_sphere(Vec2::new(rng.uniform(), rng.uniform())));
        let brute = (0..spheres.len() as u32)
            .filter_map(|i| hit(i, &ray, f32::INFINITY))
            .min_by(f32::total_cmp);
        let got = bvh.closest_hit(&ray, f32::INFINITY, |i, t| hit(i, &ray, t));
        assert_eq!(got, brute);
        assert_eq!(
            bvh.any_hit(&ray, 8.0, |i, t| hit(i, &ray, t).is_some()),
            brute.is_some_and(|t| t < 8.0)
        );
        hits += usize::from(got.is_some());
    }
    assert!(hits > 300, "{hits}");
}

#[test]
fn two_level_instancing_matches_flattened_geometry() {
    // Top level: a generic Bvh over instances; each instance's closure moves the ray into
    // object space and traverses a shared TriangleBvh. The affine map keeps t unchanged
    // (the direction is transformed, not renormalised), so t_max passes straight through.
    let mut rng = Pcg32::new(8, 8);
    let base = soup(&mut rng, 200);
    let object = TriangleBvh::from_soup(&base);
    let instances: Vec<Transform> = (0..40)
        .map(|i| {
            let offset = rv(&mut rng) * 60.0;
            let spin = Transform::rotate(37.0 * i as f32, Vec3::new(1.0, 2.0, 0.5)).unwrap();
            let scale = Transform::scale(Vec3::splat(0.5 + rng.uniform())).unwrap();
            Transform::translate(offset).compose(&spin.compose(&scale))
        })
        .collect();
    let world_bounds: Vec<Aabb> = instances
        .iter()
        .map(|x| {
            let b = object.bounds();
            let corners: Vec<Vec3> = (0..8)
                .map(|c| {
                    let pick = |bit: usize, lo: f32, hi: f32| if c & bit != 0 { hi } else { lo };
                    x.point(Vec3::new(
                        pick(1, b.min.x, b.max.x),
                        pick(2, b.min.y, b.max.y),
                        pick(4, b.min.z, b.max.z),
                    ))
                })
                .collect();
            Aabb::from_points(&corners)
        })
        .collect();
    let top = Bvh::build(&world_bounds);
    let flat: Vec<[Vec3; 3]> = instances
        .iter()
        .flat_map(|x| base.iter().map(move |t| t.map(|p| x.point(p))))
        .collect();
    let flat_bvh = TriangleBvh::from_soup(&flat);
    let (mut hits, mut disagree, mut ties) = (0, 0, 0);
    for _ in 0..10_000 {
        let o = rv(&mut rng) * 80.0 - Vec3::splat(10.0);
        let target =
            instances[rng.next_u32() as usize % instances.len()].point(rv(&mut rng) * 10.0);
        let ray = Ray::new(o, target - o);
        let mut which = None;
        let got = top.closest_hit(&ray, f32::INFINITY, |i, t_max| {
            let inv = instances[i as usize].inverse();
            let local = Ray::new(inv.point(ray.o), inv.vector(ray.d));
            let h = object.intersect(&local, t_max)?;
            which = Some((i, h.prim));
            Some(h.t)
        });
        let expect = flat_bvh.intersect(&ray, f32::INFINITY);
        match (got, expect) {
            (Some(t), Some(e)) => {
                hits += 1;
                // Same surface up to the rounding of the transforms (~1e-5 relative).
                assert!((t - e.t).abs() < 1e-4 * e.t, "{t} {}", e.t);
                let (i, prim) = which.unwrap();
                if i * 200 + prim != e.prim {
                    // Only a near-tie between overlapping triangles may pick another one.
                    disagree += 1;
                    ties += usize::from((t - e.t).abs() < 1e-4 * e.t);
                }
            }
            (None, None) => {}
            // Transform rounding may flip a ray grazing an edge.
            _ => disagree += 1,
        }
    }
    assert!(hits > 800, "{hits}");
    assert!(disagree * 100 < hits, "{disagree} of {hits} ({ties} ties)");
}

/// Triangles with two equal corners are never hit, so the tree leaves them out, and
/// the hits of a mesh full of them are those of the scalar test over all its triangles.
#[test]
fn triangles_with_two_equal_corners_are_left_out_and_change_no_hit() {
    let mut rng = Pcg32::new(41, 2);
    let mut point = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
    let mut soup: Vec<[Vec3; 3]> = Vec::new();
    for i in 0..600 {
        let (a, b, c) = (point(), point(), point());
        soup.push(match i % 4 {
            0 => [a, a, c],
            1 => [a, b, b],
            2 => [c, b, c],
            _ => [a, b, c],
        });
    }
    let bvh = TriangleBvh::from_soup(&soup);
    assert_eq!(bvh.triangle_count(), 150);
    let mut hits = 0;
    for _ in 0..4000 {
        let o = point() * 2.0;
        let ray = Ray::new(o, (point() - o).normalize());
        let wr = WatertightRay::new(&ray);
        let mut best: Option<(f32, usize)> = None;
        for (i, t) in soup.iter().enumerate() {
            let t_max = best.map_or(f32::INFINITY, |b| b.0);
            if let Some(h) = intersect_triangle(&wr, t[0], t[1], t[2], t_max) {
                assert_eq!(i % 4, 3, "a triangle with two equal corners was hit");
                best = Some((h.t, i));
            }
        }
        let found = bvh
            .intersect(&ray, f32::INFINITY)
            .map(|h| (h.t, h.prim as usize));
        assert_eq!(found, best);
        hits += best.is_some() as u32;
    }
    assert!(hits > 1000, "{hits}");
}

#[test]
fn empty_and_degenerate_inputs() {
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let empty = Bvh::build(&[]);
    assert!(empty.closest_hit(&ray, 1.0, |_, _| Some(0.5)).is_none());
    assert!(!empty.any_hit(&ray, 1.0, |_, _| true));
    assert!(empty.bounds().is_empty());
    let t = TriangleBvh::build(&[Vec3::ZERO], &[[0, 0, 5]]); // index out of range: left out
    assert_eq!(t.triangle_count(), 0);
    assert!(t.intersect(&ray, f32::INFINITY).is_none());
    // Many identical boxes cannot be split by the SAH; the builder must still terminate
    // and return every primitive.
    let same = vec![Aabb::new(Vec3::ONE, Vec3::splat(2.0)); 10_000];
    let bvh = Bvh::build(&same);
    let mut seen = 0;
    bvh.closest_hit(&Ray::new(Vec3::ZERO, Vec3::ONE), f32::INFINITY, |_, _| {
        seen += 1;
        None
    });
    assert_eq!(seen, 10_000);
    let mut order = bvh.prim_order().to_vec();
    order.sort_unstable();
    assert!(order.iter().enumerate().all(|(k, &p)| k as u32 == p));
}

#[test]
fn every_stack_size_holds_its_deepest_tree_exactly() {
    // The deepest trees each stack accepts, and one level more: a stack one entry short
    // of the bound would drop pending subtrees and miss hits here.
    use super::traverse::StackSize;
    for (levels, stack) in [
        (5, StackSize::Tiny),
        (6, StackSize::Small),
        (13, StackSize::Small),
        (14, StackSize::Large),
        (30, StackSize::Large),
    ] {
        worst_case_chain_is_exact(levels, stack);
    }
}

/// A hand-made worst case for the traversal stack: a chain of `levels` wide nodes whose
/// boxes all enclose the whole scene, each with one inner child and WIDTH − 1 leaves, so
/// a ray pushes WIDTH − 1 entries per level. The tree must get the stack `stack` and
/// answer exactly (against brute force) for closest and any hits.
fn worst_case_chain_is_exact(levels: usize, stack: super::traverse::StackSize) {
    use super::node::{WIDTH, WideNode, encode_leaf};
    let per_level = WIDTH - 1;
    let mut rng = Pcg32::new(77, levels as u64);
    let spheres: Vec<(Vec3, f32)> = (0..levels * per_level)
        .map(|_| (rv(&mut rng), 0.02 + 0.05 * rng.uniform()))
        .collect();
    let all = Aabb::new(Vec3::splat(-1.0), Vec3::splat(2.0));
    let nodes: Vec<WideNode> = (0..levels)
        .map(|level| {
            let mut node = WideNode::empty();
            for k in 0..per_level {
                node.set_child(k, &all, encode_leaf((level * per_level + k) as u32, 1));
            }
            if level + 1 < levels {
                node.set_child(per_level, &all, level as u32 + 1);
            }
            node
        })
        .collect();
    let order: Vec<u32> = (0..spheres.len() as u32).collect();
    let bvh = Bvh::from_parts(nodes, order, all);
    assert_eq!(bvh.stack_size(), stack, "{levels} levels");
    let hit = |i: u32, ray: &Ray, t_max: f32| {
        let (c, r) = spheres[i as usize];
        Sphere::full(r)
            .unwrap()
            .intersect(&Ray::new(ray.o - c, ray.d), t_max)
            .map(|h| h.t)
    };
    let mut hits = 0;
    for _ in 0..2000 {
        let o = Vec3::new(-0.5, rng.uniform(), rng.uniform());
        let ray = Ray::new(o, rv(&mut rng) - o);
        let brute = (0..spheres.len() as u32)
            .filter_map(|i| hit(i, &ray, f32::INFINITY))
            .min_by(f32::total_cmp);
        assert_eq!(
            bvh.closest_hit(&ray, f32::INFINITY, |i, t| hit(i, &ray, t)),
            brute
        );
        let mut visited = 0;
        let any = bvh.any_hit(&ray, f32::INFINITY, |i, t| {
            visited += 1;
            hit(i, &ray, t).is_some()
        });
        assert_eq!(any, brute.is_some());
        if !any {
            assert_eq!(
                visited,
                spheres.len(),
                "a miss must test every primitive here"
            );
        }
        hits += usize::from(brute.is_some());
    }
    assert!(hits > 100, "{levels} levels: {hits}");
}

/// The canonical Cornell box's triangles (`radiant_scene::builtin::cornell_box`), scaled
/// by `scale` and moved by `offset`, each with the index of the shape it belongs to: the
/// five walls are shapes 0 to 4, two triangles each.
fn cornell_box(offset: Vec3, scale: f32) -> (Vec<[Vec3; 3]>, Vec<usize>) {
    use radiant_scene::Geometry;
    let mut tris = Vec::new();
    let mut shape_of = Vec::new();
    for (shape, desc) in radiant_scene::builtin::cornell_box()
        .shapes
        .iter()
        .enumerate()
    {
        let Geometry::TriangleMesh {
            positions, indices, ..
        } = &desc.geometry
        else {
            continue;
        };
        for t in indices.chunks(3) {
            tris.push(
                [0, 1, 2].map(|k| {
                    offset + scale * desc.render_from_object.point(positions[t[k] as usize])
                }),
            );
            shape_of.push(shape);
        }
    }
    (tris, shape_of)
}

/// The leaves of a binary build tree: each one's box and the primitives in its range.
fn build_leaves(node: &super::build::BuildNode, order: &[u32], out: &mut Vec<(Aabb, Vec<u32>)>) {
    use super::build::BuildNode;
    match node {
        BuildNode::Leaf {
            bounds,
            start,
            count,
        } => out.push((
            *bounds,
            order[*start as usize..(*start + *count) as usize].to_vec(),
        )),
        BuildNode::Inner { children, .. } => {
            build_leaves(&children[0], order, out);
            build_leaves(&children[1], order, out);
        }
    }
}

/// In the Cornell box every leaf box the top-down build makes spans the room, and rays
/// start inside it: under the interior ray model the bottom-up tree is cheaper, and in
/// it each of the five walls is a leaf of its own, a slab entered only by the rays that
/// reach it. The same leaves at any scale and offset, and every leaf holds exactly its
/// range.
#[test]
fn the_cornell_boxs_walls_are_leaves_of_their_own_at_any_scale() {
    // The triangle BVH's settings, as the renderer builds with them.
    let settings = super::triangle_bvh::SETTINGS;
    // The light marked, as the renderer builds it (unmarked, it would share a flat leaf
    // with the ceiling 0.1 mm above it).
    let kinds: Vec<u8> = cornell_box_emitting()
        .iter()
        .map(|&e| u8::from(e))
        .collect();
    let mut first: Option<Vec<Vec<u32>>> = None;
    for (offset, scale) in [
        (Vec3::ZERO, 1.0),
        (Vec3::new(-3e-3, 2e-3, 7e-3), 1e-5),
        (Vec3::new(4e6, -9e6, 2e6), 1e4),
    ] {
        let (tris, shape_of) = cornell_box(offset, scale);
        let (root, order) = super::build::build_binary(&tri_bounds(&tris), &kinds, &settings);
        let mut leaves = Vec::new();
        build_leaves(&root.expect("a tree"), &order, &mut leaves);
        let mut seen = vec![false; tris.len()];
        for (bounds, prims) in &leaves {
            assert!(prims.len() <= settings.max_cluster_leaf as usize);
            for &i in prims {
                assert!(!std::mem::replace(&mut seen[i as usize], true));
                let b = Aabb::from_points(&tris[i as usize]);
                assert!(bounds.min.cmple(b.min).all() && bounds.max.cmpge(b.max).all());
            }
        }
        assert!(seen.iter().all(|&s| s));
        for wall in 0..5 {
            let (bounds, prims) = leaves
                .iter()
                .find(|(_, p)| p.iter().any(|&i| shape_of[i as usize] == wall))
                .expect("every triangle is in a leaf");
            assert_eq!(prims.len(), 2, "wall {wall} at scale {scale}: {prims:?}");
            assert!(prims.iter().all(|&i| shape_of[i as usize] == wall));
            // Flat but for the measured box's out-of-plane left wall (6.4 mm).
            let thickness = bounds.diagonal().min_element();
            assert!(thickness <= 6.5 * scale, "wall {wall}: {thickness}");
        }
        let mut shape: Vec<Vec<u32>> = leaves.into_iter().map(|(_, p)| p).collect();
        shape.iter_mut().for_each(|p| p.sort());
        shape.sort();
        match &first {
            None => first = Some(shape),
            Some(f) => assert_eq!(&shape, f, "scale {scale}"),
        }
    }
}

/// Whether each of the canonical Cornell box's triangles (in [`cornell_box`]'s order)
/// belongs to an emitting shape.
fn cornell_box_emitting() -> Vec<bool> {
    use radiant_scene::Geometry;
    radiant_scene::builtin::cornell_box()
        .shapes
        .iter()
        .filter_map(|desc| match &desc.geometry {
            Geometry::TriangleMesh { indices, .. } => {
                Some(vec![desc.area_light.is_some(); indices.len() / 3])
            }
            _ => None,
        })
        .flatten()
        .collect()
}

/// Emitting triangles never share a leaf with others: shadow rays end just short of the
/// light, so the light's own flat leaf is not entered by them. Without the rule the
/// bottom-up build put the Cornell box's light in one leaf with the top of the tall
/// block, a box that nearly every shadow ray entered. Held at three scales and offsets,
/// and for random soups with random emitters.
#[test]
fn emitting_triangles_are_in_leaves_of_their_own() {
    // The triangle BVH's settings, as the renderer builds with them.
    let settings = super::triangle_bvh::SETTINGS;
    let emitting = cornell_box_emitting();
    assert_eq!(emitting.iter().filter(|&&e| e).count(), 2);
    let kinds: Vec<u8> = emitting.iter().map(|&e| u8::from(e)).collect();
    let mut rng = Pcg32::new(8, 1);
    let mut cases = vec![];
    for (offset, scale) in [
        (Vec3::ZERO, 1.0),
        (Vec3::new(-3e-3, 2e-3, 7e-3), 1e-5),
        (Vec3::new(4e6, -9e6, 2e6), 1e4),
    ] {
        cases.push((cornell_box(offset, scale).0, kinds.clone()));
    }
    for n in [3, 9, 17, 40, 200] {
        let tris = soup(&mut rng, n);
        let kinds = (0..n).map(|_| u8::from(rng.uniform() < 0.3)).collect();
        cases.push((tris, kinds));
    }
    for (tris, kinds) in &cases {
        let (root, order) = super::build::build_binary(&tri_bounds(tris), kinds, &settings);
        let mut leaves = Vec::new();
        build_leaves(&root.expect("a tree"), &order, &mut leaves);
        let mut seen = vec![false; tris.len()];
        for (_, prims) in &leaves {
            assert!(prims.len() <= settings.max_cluster_leaf as usize);
            let kind = kinds[prims[0] as usize];
            assert!(
                prims.iter().all(|&i| kinds[i as usize] == kind),
                "a leaf mixes emitters and others: {prims:?}"
            );
            prims.iter().for_each(|&i| seen[i as usize] = true);
        }
        assert!(seen.iter().all(|&s| s));
    }
}

/// The Cornell box's tree against brute force, for rays from points on its surfaces (as a
/// path tracer casts them), for rays along the floor, and at two scales.
#[test]
fn the_cornell_box_built_bottom_up_equals_brute_force() {
    let mut rng = Pcg32::new(5, 3);
    for (offset, scale) in [(Vec3::ZERO, 1.0), (Vec3::new(-4e3, 1e3, 2e3), 0.01)] {
        let (tris, _) = cornell_box(offset, scale);
        let tbvh = TriangleBvh::from_soup(&tris);
        let with_light = TriangleBvh::from_soup_with_emitters(&tris, &cornell_box_emitting());
        let mut hits = 0;
        for i in 0..20_000 {
            let t = tris[rng.next_u32() as usize % tris.len()];
            let u = Vec2::new(rng.uniform(), rng.uniform());
            let b = radiant_math::sampling::uniform_triangle(u);
            let on = t[0] * b[0] + t[1] * b[1] + t[2] * b[2];
            let d = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
            let ray = match i % 4 {
                // Along the floor's edge at the right wall, and across the floor.
                0 => Ray::new(
                    offset + scale * Vec3::new(0.0, 0.0, 559.2 * rng.uniform()),
                    Vec3::X,
                ),
                _ => Ray::new(on + d * (1e-3 * scale), d),
            };
            for t_max in [f32::INFINITY, 300.0 * scale] {
                let expect = brute_closest(&tris, &ray, t_max);
                assert_eq!(
                    tbvh.intersect(&ray, t_max).map(|h| h.t),
                    expect.map(|e| e.0)
                );
                assert_eq!(tbvh.occluded(&ray, t_max), expect.is_some());
                assert_eq!(
                    with_light.intersect(&ray, t_max).map(|h| h.t),
                    expect.map(|e| e.0)
                );
                assert_eq!(with_light.occluded(&ray, t_max), expect.is_some());
                hits += usize::from(expect.is_some());
            }
        }
        assert!(hits > 20_000, "{hits}");
    }
}

/// The interior ray model's weight: the surface area heuristic for boxes small against the
/// scene, twice it for the scene's own box (every ray starts in it), the area alone in a
/// flat scene, and only ratios of scene and box: the same at any scale.
#[test]
fn the_interior_ray_model_weighs_boxes_by_area_and_by_volume_in_chords() {
    use super::cluster::RayModel;
    let cube = |min: Vec3, side: f32| Aabb {
        min,
        max: min + Vec3::splat(side),
    };
    let room = Aabb {
        min: Vec3::ZERO,
        max: Vec3::new(4.0, 3.0, 5.0),
    };
    let model = RayModel::inside(&room);
    let small = cube(Vec3::splat(1.0), 1e-3);
    assert!((model.weight(&small) / small.surface_area() - 1.0).abs() < 1e-3);
    assert!(!model.is_interior_scale(&small));
    assert!((model.weight(&room) / room.surface_area() - 2.0).abs() < 1e-6);
    assert!(model.is_interior_scale(&room));
    // A flat box has no volume, whatever its size.
    let slab = Aabb {
        min: Vec3::ZERO,
        max: Vec3::new(4.0, 0.0, 5.0),
    };
    assert_eq!(model.weight(&slab), slab.surface_area());
    let flat = RayModel::inside(&slab);
    assert_eq!(flat.weight(&room), room.surface_area());
    assert!(!flat.is_interior_scale(&room));
    let half = cube(Vec3::ZERO, 1.5);
    for (offset, k) in [
        (Vec3::new(1e3, -2e3, 5e2), 100.0f32),
        (Vec3::splat(-1e-2), 1e-3),
    ] {
        let at = |b: &Aabb| Aabb {
            min: offset + k * b.min,
            max: offset + k * b.max,
        };
        let scaled = RayModel::inside(&at(&room));
        let ratio = |m: &RayModel, a: &Aabb, b: &Aabb| m.weight(a) / m.weight(b);
        let expect = ratio(&model, &half, &slab);
        let got = ratio(&scaled, &at(&half), &at(&slab));
        assert!(
            (got / expect - 1.0).abs() < 1e-3,
            "{got} against {expect} at scale {k}"
        );
    }
}

/// The triangles of an axis-aligned box's six faces.
fn box_triangles(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 3]> {
    let c = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let faces = [
        [0, 2, 6, 4],
        [1, 5, 7, 3],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 6, 7, 5],
    ];
    faces
        .iter()
        .flat_map(|f| [[c(f[0]), c(f[1]), c(f[2])], [c(f[0]), c(f[2]), c(f[3])]])
        .collect()
}

/// A room of five separate walls (a floor, a ceiling and three walls, two triangles each),
/// a light just under the ceiling and two closed boxes of twelve triangles: more triangles
/// than one bottom-up range takes, so the top-down build splits first. Every wall is
/// still a flat leaf of its own: a leaf grouping walls spans the room and is entered by
/// every ray (the binary cost of the nodes that separate walls once hid that a wide node
/// absorbs them). The light's triangles are a leaf of their own as well.
#[test]
fn separate_walls_of_a_room_are_flat_leaves_at_any_scale() {
    // The triangle BVH's settings, as the renderer builds with them.
    let settings = super::triangle_bvh::SETTINGS;
    for (offset, scale) in [
        (Vec3::ZERO, 1.0),
        (Vec3::new(-3e-3, 2e-3, 7e-3), 1e-5),
        (Vec3::new(4e6, -9e6, 2e6), 1e4),
    ] {
        let p = |x: f32, y: f32, z: f32| offset + scale * Vec3::new(x, y, z);
        let quad = |a: Vec3, b: Vec3, c: Vec3, d: Vec3| [[a, b, c], [a, c, d]];
        let mut tris: Vec<[Vec3; 3]> = Vec::new();
        let mut group: Vec<usize> = Vec::new();
        let walls = [
            quad(
                p(-1., 0., -1.),
                p(1., 0., -1.),
                p(1., 0., 1.),
                p(-1., 0., 1.),
            ),
            quad(
                p(-1., 2., -1.),
                p(-1., 2., 1.),
                p(1., 2., 1.),
                p(1., 2., -1.),
            ),
            quad(
                p(-1., 0., -1.),
                p(-1., 2., -1.),
                p(1., 2., -1.),
                p(1., 0., -1.),
            ),
            quad(
                p(-1., 0., -1.),
                p(-1., 0., 1.),
                p(-1., 2., 1.),
                p(-1., 2., -1.),
            ),
            quad(p(1., 0., -1.), p(1., 2., -1.), p(1., 2., 1.), p(1., 0., 1.)),
            quad(
                p(-0.2, 1.98, -0.2),
                p(0.2, 1.98, -0.2),
                p(0.2, 1.98, 0.2),
                p(-0.2, 1.98, 0.2),
            ),
        ];
        for (g, w) in walls.iter().enumerate() {
            tris.extend(w);
            group.extend([g, g]);
        }
        for (g, (lo, hi)) in [
            (p(-0.7, 0., -0.7), p(0.05, 1.2, 0.1)),
            (p(0.0, 0., 0.2), p(0.7, 0.6, 0.75)),
        ]
        .into_iter()
        .enumerate()
        {
            let b = box_triangles(lo, hi);
            group.extend(std::iter::repeat_n(6 + g, b.len()));
            tris.extend(b);
        }
        let kinds: Vec<u8> = group.iter().map(|&g| u8::from(g == 5)).collect();
        let (root, order) = super::build::build_binary(&tri_bounds(&tris), &kinds, &settings);
        let mut leaves = Vec::new();
        build_leaves(&root.expect("a tree"), &order, &mut leaves);
        for wall in 0..6 {
            let (bounds, prims) = leaves
                .iter()
                .find(|(_, p)| p.iter().any(|&i| group[i as usize] == wall))
                .expect("every triangle is in a leaf");
            assert!(
                prims.iter().all(|&i| group[i as usize] == wall),
                "wall {wall} at scale {scale} shares a leaf: {:?}",
                prims.iter().map(|&i| group[i as usize]).collect::<Vec<_>>()
            );
            assert_eq!(
                bounds.diagonal().min_element(),
                0.0,
                "wall {wall} at scale {scale}"
            );
        }
    }
}

/// The bottom-up build merges clusters of one kind before any two of different kinds,
/// so each kind's primitives form one subtree of their own (random soups, random kinds).
#[test]
fn clusters_of_one_kind_merge_first() {
    use super::build::{BuildNode, PrimRef};
    use super::cluster::{Costs, RayModel, cluster_range};
    // The triangle BVH's settings, as the renderer builds with them.
    let settings = super::triangle_bvh::SETTINGS;
    /// The kinds under `node` (a bit each), and the number of maximal one-kind subtrees
    /// found under it, per kind.
    fn kinds_under(node: &BuildNode, order: &[u32], kinds: &[u8], pure: &mut [u32; 2]) -> u8 {
        match node {
            BuildNode::Leaf { start, count, .. } => order
                [*start as usize..(*start + *count) as usize]
                .iter()
                .fold(0, |m, &i| m | 1 << kinds[i as usize]),
            BuildNode::Inner { children, .. } => {
                let l = kinds_under(&children[0], order, kinds, pure);
                let r = kinds_under(&children[1], order, kinds, pure);
                if l | r == 3 {
                    // A mixed node: its one-kind children are maximal.
                    for m in [l, r] {
                        if m != 3 {
                            pure[m as usize >> 1] += 1;
                        }
                    }
                }
                l | r
            }
        }
    }
    let mut rng = Pcg32::new(31, 7);
    for n in [2, 5, 9, 17, 32] {
        for _ in 0..20 {
            let tris = soup(&mut rng, n);
            let kinds: Vec<u8> = (0..n).map(|_| u8::from(rng.uniform() < 0.3)).collect();
            let mut refs: Vec<PrimRef> = tri_bounds(&tris)
                .iter()
                .enumerate()
                .map(|(i, b)| PrimRef {
                    min: b.min,
                    id: i as u32,
                    max: b.max,
                })
                .collect();
            let scene = tri_bounds(&tris)
                .iter()
                .fold(Aabb::EMPTY, |a, b| a.union(b));
            let costs = Costs {
                settings: &settings,
                rays: RayModel::inside(&scene),
                kinds: &kinds,
            };
            let (root, _) = cluster_range(&mut refs, 0, &costs);
            let order: Vec<u32> = refs.iter().map(|r| r.id).collect();
            let mut pure = [0u32; 2];
            let all = kinds_under(&root, &order, &kinds, &mut pure);
            if all == 3 {
                assert_eq!(pure, [1, 1], "n {n}: each kind in one subtree");
            }
        }
    }
}

/// The canonical Cornell box's five walls, light and two blocks fill the eight slots of
/// one wide node: each block is one leaf (a node over its faces would cost a second
/// node visit to every ray that enters the block's box), each wall and the light a leaf
/// of its own. At three scales and offsets.
#[test]
fn the_cornell_box_is_one_wide_node_of_whole_shapes_at_any_scale() {
    // The triangle BVH's settings, as the renderer builds with them.
    let settings = super::triangle_bvh::SETTINGS;
    let emitting = cornell_box_emitting();
    let kinds: Vec<u8> = emitting.iter().map(|&e| u8::from(e)).collect();
    for (offset, scale) in [
        (Vec3::ZERO, 1.0),
        (Vec3::new(-3e-3, 2e-3, 7e-3), 1e-5),
        (Vec3::new(4e6, -9e6, 2e6), 1e4),
    ] {
        let (tris, shape_of) = cornell_box(offset, scale);
        let bvh = TriangleBvh::from_soup_with_emitters(&tris, &emitting);
        assert_eq!(bvh.size().0, 1, "wide nodes at scale {scale}");
        let (root, order) = super::build::build_binary(&tri_bounds(&tris), &kinds, &settings);
        let mut leaves = Vec::new();
        build_leaves(&root.expect("a tree"), &order, &mut leaves);
        let shapes = shape_of.iter().max().unwrap() + 1;
        assert_eq!(leaves.len(), shapes, "scale {scale}");
        for (_, prims) in &leaves {
            let shape = shape_of[prims[0] as usize];
            let whole = shape_of.iter().filter(|&&s| s == shape).count();
            assert_eq!(prims.len(), whole, "shape {shape} at scale {scale}");
        }
    }
}
