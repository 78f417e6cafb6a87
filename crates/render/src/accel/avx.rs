//! The node and triangle tests eight lanes at a time on AVX, for processors that have it
//! (detected at run time: the portable build stays at SSE2).
//!
//! A wide node's eight child boxes are one 256-bit slab test instead of two 128-bit ones,
//! and a leaf's two 4-triangle blocks are tested together. Every lane performs exactly the
//! operations of the 4-lane kernels ([`NodeRay::hit`](super::node::NodeRay::hit),
//! [`intersect4`](super::triangle4::intersect4)) in the same order, with the same NaN
//! behaviour of min/max and the same comparisons, so both paths give bit-identical hits
//! (and the scalar test's watertightness). Wald et al., "Embree: A Kernel Framework for
//! Efficient CPU Ray Tracing" (SIGGRAPH 2014), use the same 8-wide node and leaf layout.

use std::arch::x86_64::*;

use super::node::{ROBUST_EXIT_SCALE, WIDTH, WideNode};
use super::traverse::NodeTest;
use super::triangle4::Triangle4;
use crate::geometry::Ray;
use crate::geometry::ray::gamma;
use crate::geometry::triangle::{WatertightRay, edge_functions_f64};
use glam::Vec4;

/// Proof that this processor runs AVX: only [`Avx::detect`] makes one. Every `unsafe`
/// below is a call into AVX code, sound because one of these exists.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx {
    evex: bool,
}

impl Avx {
    pub fn detect() -> Option<Avx> {
        std::arch::is_x86_feature_detected!("avx").then(|| Avx {
            evex: std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl"),
        })
    }

    /// Whether the processor also has AVX2, AVX-512F and AVX-512VL, so that the same
    /// 256-bit kernels may be compiled with the EVEX encoding: 32 vector registers
    /// instead of 16 (the per-ray constants of a traversal no longer spill to the
    /// stack) and one-instruction broadcasts. The operations, hence the hits, are the
    /// same bit for bit.
    pub fn evex(&self) -> bool {
        self.evex
    }

    /// This proof without the EVEX kernels (for tests that compare them).
    #[cfg(test)]
    pub fn without_evex(self) -> Avx {
        Avx { evex: false }
    }
}

/// The upper and lower halves as one 256-bit vector.
/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn join(lo: Vec4, hi: Vec4) -> __m256 {
    unsafe { _mm256_set_m128(hi.into(), lo.into()) }
}

/// The eight lanes as an array.
/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn lanes_of(x: __m256) -> [f32; 8] {
    unsafe {
        let lo = Vec4::from(_mm256_castps256_ps128(x)).to_array();
        let hi = Vec4::from(_mm256_extractf128_ps::<1>(x)).to_array();
        [lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]]
    }
}

/// The lanes back from an array.
/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn from_lanes(a: [f32; 8]) -> __m256 {
    unsafe {
        join(
            Vec4::new(a[0], a[1], a[2], a[3]),
            Vec4::new(a[4], a[5], a[6], a[7]),
        )
    }
}

/// The per-ray constants of the 8-box slab test (those of
/// [`NodeRay`](super::node::NodeRay), kept as scalars and broadcast at the test).
#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeRay8 {
    o: [f32; 3],
    inv: [f32; 3],
    inv_exit: [f32; 3],
    near: [usize; 3],
    _avx: Avx,
}

impl NodeRay8 {
    #[inline(always)]
    pub fn new(ray: &Ray, avx: Avx) -> NodeRay8 {
        let inv = ray.d.recip().to_array();
        NodeRay8 {
            o: ray.o.to_array(),
            inv,
            inv_exit: inv.map(|v| v * ROBUST_EXIT_SCALE),
            near: inv.map(|v| usize::from(v < 0.0)),
            _avx: avx,
        }
    }
}

impl NodeTest for NodeRay8 {
    #[inline(always)]
    fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        // SAFETY: an `Avx` exists only when the processor has AVX.
        unsafe { hit8(self, node, t_max) }
    }
}

/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn hit8(ray: &NodeRay8, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
    unsafe {
        let mut t_in = _mm256_setzero_ps();
        let mut t_out = _mm256_set1_ps(t_max * ROBUST_EXIT_SCALE);
        for axis in 0..3 {
            let s = ray.near[axis] & 1;
            let planes = &node.bounds[axis];
            let near = join(planes[s][0], planes[s][1]);
            let far = join(planes[s ^ 1][0], planes[s ^ 1][1]);
            let o = _mm256_set1_ps(ray.o[axis]);
            let t0 = _mm256_mul_ps(_mm256_sub_ps(near, o), _mm256_set1_ps(ray.inv[axis]));
            let t1 = _mm256_mul_ps(_mm256_sub_ps(far, o), _mm256_set1_ps(ray.inv_exit[axis]));
            // The operand order of the 4-lane test, so that a NaN drops out the same way.
            t_in = _mm256_max_ps(t0, t_in);
            t_out = _mm256_min_ps(t1, t_out);
        }
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(t_in, t_out)) as u32;
        (mask, lanes_of(t_in))
    }
}

/// The watertight per-ray constants (permuted origin and shear), as scalars.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WatertightRay8 {
    k: [usize; 3],
    o: [f32; 3],
    s: [f32; 3],
    _avx: Avx,
}

impl WatertightRay8 {
    #[inline(always)]
    pub fn new(r: &WatertightRay, avx: Avx) -> WatertightRay8 {
        WatertightRay8 {
            k: [r.kx, r.ky, r.kz].map(|k| k.min(2)),
            o: [r.o[r.kx], r.o[r.ky], r.o[r.kz]],
            s: [r.sx, r.sy, r.sz],
            _avx: avx,
        }
    }

    /// Tests the triangles of blocks `a` (lanes 0–3) and `b` (lanes 4–7) at once.
    #[inline(always)]
    pub fn intersect(&self, a: &Triangle4, b: &Triangle4, t_max: f32) -> Lanes8 {
        // SAFETY: an `Avx` exists only when the processor has AVX.
        unsafe { intersect8(self, a, b, t_max) }
    }
}

/// Edge functions, determinant and scaled distance of eight lanes, and the mask of
/// those that hit.
pub(crate) struct Lanes8 {
    pub u: [f32; 8],
    pub v: [f32; 8],
    pub w: [f32; 8],
    pub t: [f32; 8],
    pub det: [f32; 8],
    pub hit: u32,
}

/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn abs8(x: __m256) -> __m256 {
    unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), x) }
}

/// Vertex `vertex` of the eight triangles in the ray's sheared frame: x, y and the
/// unscaled z, formed as `intersect4` forms them.
///
/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn shear(
    ray: &WatertightRay8,
    a: &Triangle4,
    b: &Triangle4,
    vertex: usize,
) -> (__m256, __m256, __m256) {
    unsafe {
        let [kx, ky, kz] = ray.k;
        let coordinate = |axis: usize| (a.v[vertex][axis], b.v[vertex][axis]);
        let (zl, zh) = coordinate(kz);
        let (xl, xh) = coordinate(kx);
        let (yl, yh) = coordinate(ky);
        let z = _mm256_sub_ps(join(zl, zh), _mm256_set1_ps(ray.o[2]));
        let x = _mm256_sub_ps(
            _mm256_sub_ps(join(xl, xh), _mm256_set1_ps(ray.o[0])),
            _mm256_mul_ps(_mm256_set1_ps(ray.s[0]), z),
        );
        let y = _mm256_sub_ps(
            _mm256_sub_ps(join(yl, yh), _mm256_set1_ps(ray.o[1])),
            _mm256_mul_ps(_mm256_set1_ps(ray.s[1]), z),
        );
        (x, y, z)
    }
}

/// max(|p|, |q|, |r|) lane-wise, in `intersect4`'s order.
///
/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn max_abs3(p: __m256, q: __m256, r: __m256) -> __m256 {
    unsafe { _mm256_max_ps(_mm256_max_ps(abs8(p), abs8(q)), abs8(r)) }
}

/// Safety: the processor must have AVX (an [`Avx`] exists).
#[inline(always)]
unsafe fn intersect8(ray: &WatertightRay8, a: &Triangle4, b: &Triangle4, t_max: f32) -> Lanes8 {
    unsafe {
        // Closures would not inherit the AVX context they are inlined into: plain
        // inlined functions only.
        let (ax, ay, az) = shear(ray, a, b, 0);
        let (bx, by, bz) = shear(ray, a, b, 1);
        let (cx, cy, cz) = shear(ray, a, b, 2);
        let mut u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
        let mut v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
        let mut w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
        let zero = _mm256_setzero_ps();
        let on_edge = _mm256_or_ps(
            _mm256_or_ps(
                _mm256_cmp_ps::<_CMP_EQ_OQ>(u, zero),
                _mm256_cmp_ps::<_CMP_EQ_OQ>(v, zero),
            ),
            _mm256_cmp_ps::<_CMP_EQ_OQ>(w, zero),
        );
        let on_edge = _mm256_movemask_ps(on_edge) as u32;
        if on_edge != 0 {
            refine_in_f64(on_edge, [ax, ay, bx, by, cx, cy], &mut u, &mut v, &mut w);
        }
        let lo = _mm256_min_ps(_mm256_min_ps(u, v), w);
        let hi = _mm256_max_ps(_mm256_max_ps(u, v), w);
        let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
        let num = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)),
            _mm256_mul_ps(w, cz),
        );
        let sz = _mm256_set1_ps(ray.s[2]);
        let scale = _mm256_div_ps(sz, det);
        let t = _mm256_mul_ps(num, scale);
        let in_range = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GT_OS>(t, zero),
            _mm256_cmp_ps::<_CMP_LT_OS>(t, _mm256_set1_ps(t_max)),
        );
        let mixed = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_LT_OS>(lo, zero),
            _mm256_cmp_ps::<_CMP_GT_OS>(hi, zero),
        );
        let mut hit = (_mm256_movemask_ps(in_range) & !_mm256_movemask_ps(mixed)) as u32;
        if hit != 0 {
            // The t error bound of `intersect4`, operation for operation.
            let max_x = max_abs3(ax, bx, cx);
            let max_y = max_abs3(ay, by, cy);
            let max_z = max_abs3(az, bz, cz);
            let max_e = max_abs3(u, v, w);
            let two = _mm256_set1_ps(2.0);
            let two_z = _mm256_mul_ps(two, max_z);
            let dz = _mm256_mul_ps(_mm256_set1_ps(gamma(1)), max_z);
            let dx = _mm256_mul_ps(_mm256_set1_ps(gamma(5)), _mm256_add_ps(max_x, two_z));
            let dy = _mm256_mul_ps(_mm256_set1_ps(gamma(5)), _mm256_add_ps(max_y, two_z));
            let de = _mm256_mul_ps(
                two,
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(gamma(2)), max_x), max_y),
                        _mm256_mul_ps(dy, max_x),
                    ),
                    _mm256_mul_ps(dx, max_y),
                ),
            );
            let dt = _mm256_mul_ps(
                _mm256_set1_ps(3.0),
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(gamma(3)), max_e), max_z),
                        _mm256_mul_ps(de, max_z),
                    ),
                    _mm256_mul_ps(dz, max_e),
                ),
            );
            let bound = _mm256_mul_ps(dt, abs8(_mm256_div_ps(sz, det)));
            hit &= _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OS>(t, bound)) as u32;
        }
        Lanes8 {
            u: lanes_of(u),
            v: lanes_of(v),
            w: lanes_of(w),
            t: lanes_of(t),
            det: lanes_of(det),
            hit,
        }
    }
}

/// Recomputes the edge functions of the flagged lanes in f64, as the 4-lane kernel does.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx")]
fn refine_in_f64(lanes: u32, p: [__m256; 6], u: &mut __m256, v: &mut __m256, w: &mut __m256) {
    // SAFETY: this function is compiled for AVX, which its callers have.
    unsafe {
        let p = [
            lanes_of(p[0]),
            lanes_of(p[1]),
            lanes_of(p[2]),
            lanes_of(p[3]),
            lanes_of(p[4]),
            lanes_of(p[5]),
        ];
        let (mut uu, mut vv, mut ww) = (lanes_of(*u), lanes_of(*v), lanes_of(*w));
        for lane in 0..8 {
            if lanes & (1 << lane) != 0 {
                [uu[lane], vv[lane], ww[lane]] = edge_functions_f64(
                    [p[0][lane], p[1][lane]],
                    [p[2][lane], p[3][lane]],
                    [p[4][lane], p[5][lane]],
                );
            }
        }
        *u = from_lanes(uu);
        *v = from_lanes(vv);
        *w = from_lanes(ww);
    }
}
