//! Four triangles tested at once: the watertight test of Woop, Benthin & Wald (JCGT 2013)
//! in structure-of-arrays form on SSE lanes (glam's `Vec4`).
//!
//! Every lane performs exactly the operations of the scalar
//! [`intersect_triangle`](crate::geometry::triangle::intersect_triangle), in the same
//! order (Rust never contracts to FMA), so the SIMD and scalar kernels agree bit for bit and
//! the packed BVH inherits the scalar test's watertightness.

use crate::geometry::ray::gamma;
use crate::geometry::triangle::{WatertightRay, edge_functions_f64};
use glam::{BVec4A, Vec3, Vec4};

/// Four triangles, vertex coordinates by lane: `v[vertex][axis]` (144 bytes; the triangle
/// indices live in a parallel array, read once per query for the final hit). Unused lanes
/// repeat a triangle of the same leaf, which changes no result.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Triangle4 {
    pub v: [[Vec4; 3]; 3],
}

impl Triangle4 {
    /// Packs up to four triangles; returns the block and the triangle index of each lane.
    pub fn new(tris: &[[Vec3; 3]], prims: &[u32]) -> (Triangle4, [u32; 4]) {
        let mut t = Triangle4 {
            v: [[Vec4::ZERO; 3]; 3],
        };
        let mut lanes = [0; 4];
        let last = tris.len() - 1;
        for (lane, prim) in lanes.iter_mut().enumerate() {
            let k = lane.min(last);
            for (vertex, p) in tris[k].iter().enumerate() {
                for axis in 0..3 {
                    t.v[vertex][axis][lane] = p[axis];
                }
            }
            *prim = prims[k];
        }
        (t, lanes)
    }
}

/// The watertight per-ray constants broadcast to four lanes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WatertightRay4 {
    k: [usize; 3],
    o: [Vec4; 3],
    s: [Vec4; 3],
}

impl WatertightRay4 {
    #[inline(always)]
    pub fn new(r: &WatertightRay) -> WatertightRay4 {
        WatertightRay4 {
            k: [r.kx, r.ky, r.kz],
            o: [r.o[r.kx], r.o[r.ky], r.o[r.kz]].map(Vec4::splat),
            s: [r.sx, r.sy, r.sz].map(Vec4::splat),
        }
    }
}

/// Edge functions, determinant, scaled distance and the mask of lanes that hit.
pub(crate) struct Lanes {
    pub u: Vec4,
    pub v: Vec4,
    pub w: Vec4,
    pub t: Vec4,
    pub det: Vec4,
    pub hit: u32,
}

#[inline(always)]
pub(crate) fn intersect4(ray: &WatertightRay4, tri: &Triangle4, t_max: f32) -> Lanes {
    let [kx, ky, kz] = ray.k.map(|k| k.min(2));
    let [ox, oy, oz] = ray.o;
    let [sx, sy, sz] = ray.s;
    let shear = |p: &[Vec4; 3]| {
        let z = p[kz] - oz;
        (((p[kx] - ox) - sx * z), ((p[ky] - oy) - sy * z), z)
    };
    let (ax, ay, az) = shear(&tri.v[0]);
    let (bx, by, bz) = shear(&tri.v[1]);
    let (cx, cy, cz) = shear(&tri.v[2]);
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    let zero = u.cmpeq(Vec4::ZERO) | v.cmpeq(Vec4::ZERO) | w.cmpeq(Vec4::ZERO);
    if zero.any() {
        refine_in_f64(zero, [ax, ay, bx, by, cx, cy], &mut u, &mut v, &mut w);
    }
    // Mixed edge signs miss: min < 0 < max (the scalar kernel's sign tests, with fewer
    // operations; lanes with NaN end up with t = NaN and are rejected by the range test).
    let lo = u.min(v).min(w);
    let hi = u.max(v).max(w);
    let det = u + v + w;
    let t = (u * az + v * bz + w * cz) * (sz / det);
    // det = 0 gives t = ±∞ or NaN, which the range test rejects, as the scalar kernel does.
    let in_range = t.cmpgt(Vec4::ZERO) & t.cmplt(Vec4::splat(t_max));
    let mut hit = in_range.bitmask() & !(lo.cmplt(Vec4::ZERO) & hi.cmpgt(Vec4::ZERO)).bitmask();
    if hit != 0 {
        // The scalar kernel's t_error_bound, lane-wise: only hits with a provably
        // positive t remain.
        let max_x = ax.abs().max(bx.abs()).max(cx.abs());
        let max_y = ay.abs().max(by.abs()).max(cy.abs());
        let max_z = az.abs().max(bz.abs()).max(cz.abs());
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let g = |n: i32| Vec4::splat(gamma(n));
        let two = Vec4::splat(2.0);
        let dz = g(1) * max_z;
        let dx = g(5) * (max_x + two * max_z);
        let dy = g(5) * (max_y + two * max_z);
        let de = two * (g(2) * max_x * max_y + dy * max_x + dx * max_y);
        let dt = Vec4::splat(3.0) * (g(3) * max_e * max_z + de * max_z + dz * max_e);
        hit &= t.cmpgt(dt * (sz / det).abs()).bitmask();
    }
    Lanes {
        u,
        v,
        w,
        t,
        det,
        hit,
    }
}

/// Recomputes the edge functions of the flagged lanes in f64 (all three, as the scalar
/// kernel does), so a ray through a shared edge gets a consistent sign on both sides.
#[cold]
#[inline(never)]
fn refine_in_f64(lanes: BVec4A, p: [Vec4; 6], u: &mut Vec4, v: &mut Vec4, w: &mut Vec4) {
    let bits = lanes.bitmask();
    let p = p.map(|x| x.to_array());
    for lane in 0..4 {
        if bits & (1 << lane) != 0 {
            let [uu, vv, ww] = edge_functions_f64(
                [p[0][lane], p[1][lane]],
                [p[2][lane], p[3][lane]],
                [p[4][lane], p[5][lane]],
            );
            u[lane] = uu;
            v[lane] = vv;
            w[lane] = ww;
        }
    }
}
