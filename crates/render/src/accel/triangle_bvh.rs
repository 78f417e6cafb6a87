//! The triangle-only BVH: leaves hold triangles copied in leaf order into 4-lane SIMD
//! blocks ([`Triangle4`]), intersected inline during traversal with no callback. This is
//! the hot path of the renderer.

#[cfg(target_arch = "x86_64")]
use super::avx::{Avx, NodeRay8, WatertightRay8};
use super::build::{BuildSettings, build_binary, collapse};
use super::node::{MAX_LEAF_ITEMS, NodeRay, WideNode, decode_leaf, encode_leaf};
use super::traverse::{
    self, AnyLeaf, ClosestLeaf, LARGE_STACK, NodeTree, SMALL_STACK, StackSize, TINY_STACK,
};
use super::triangle4::{Triangle4, WatertightRay4, intersect4};
use crate::geometry::triangle::WatertightRay;
use crate::geometry::{Aabb, Ray};
use glam::Vec3;

/// A closest hit on a [`TriangleBvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct MeshHit {
    /// Barycentric weights of the triangle's three vertices at the hit.
    pub b: [f32; 3],
    pub t: f32,
    /// Index of the triangle in the list given to the build.
    pub prim: u32,
}

/// A BVH over triangles that owns a leaf-ordered copy of their vertices.
#[derive(Clone, Debug, Default)]
pub struct TriangleBvh {
    nodes: NodeTree,
    packets: Vec<Triangle4>,
    /// Triangle index of each lane of each block.
    packet_prims: Vec<[u32; 4]>,
    order: Vec<u32>,
    bounds: Aabb,
    /// Whether traversal touches the children it enters ahead of visiting them: only for
    /// trees too large to stay in cache (`traverse::small_enough_to_stay_cached`).
    prefetch: bool,
    /// Set when the processor has AVX: queries then test eight boxes and eight triangles
    /// at once (the same hits, bit for bit).
    #[cfg(target_arch = "x86_64")]
    avx: Option<Avx>,
}

/// SAH costs in units of one 4-triangle block test, a binary build node charged the same;
/// up to 8 triangles (two blocks) per leaf. On the benchmark scene, cheaper nodes (0.3,
/// 0.5) or single-block leaves made deeper trees and slower traversal. The bottom-up
/// build of small room-spanning ranges counts 8-triangle kernel tests and allows leaves
/// of up to 16 (cluster.rs).
pub(super) const SETTINGS: BuildSettings = BuildSettings {
    leaf_block: 4,
    max_leaf: 8,
    leaf_test: 8,
    max_cluster_leaf: 16,
    cost_traversal: 1.0,
};

/// `$self.$query::<STACK>(args)` with the traversal stack the tree needs: each stack size
/// is its own monomorphised query, chosen once per query.
macro_rules! by_stack {
    ($self:ident, $query:ident($($arg:expr),*)) => {
        match $self.nodes.stack() {
            StackSize::Tiny => $self.$query::<TINY_STACK>($($arg),*),
            StackSize::Small => $self.$query::<SMALL_STACK>($($arg),*),
            StackSize::Large => $self.$query::<LARGE_STACK>($($arg),*),
        }
    };
}

impl TriangleBvh {
    /// Builds over `triangles` (vertex indices into `vertices`). Triangles with an index
    /// out of range or a non-finite vertex are left out (mesh loaders report those);
    /// zero-area triangles are kept and never hit. Capacity: 2^30 triangles (leaf
    /// references hold 28-bit block indices).
    ///
    /// Binned SAH build (Wald 2007), subtrees in parallel with rayon; leaves of up to 8
    /// triangles in 4-triangle SIMD blocks; 8-wide nodes.
    pub fn build(vertices: &[Vec3], triangles: &[[u32; 3]]) -> TriangleBvh {
        TriangleBvh::build_with_emitters(vertices, triangles, &[])
    }

    /// [`build`](Self::build) where `emitting[i]` says whether triangle i emits light
    /// (empty: none does): emitting triangles never share a leaf with others, which shadow
    /// rays, ending just short of an emitter, would then enter (`build_binary`).
    pub fn build_with_emitters(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        emitting: &[bool],
    ) -> TriangleBvh {
        let corners = |t: &[u32; 3]| -> Option<[Vec3; 3]> {
            let p = [
                *vertices.get(t[0] as usize)?,
                *vertices.get(t[1] as usize)?,
                *vertices.get(t[2] as usize)?,
            ];
            p.iter().all(|v| v.is_finite()).then_some(p)
        };
        // A triangle with two equal corners is left out: no ray hits it (the watertight
        // test's edge functions of the repeated pair cancel exactly, in f32 as in the
        // f64 fallback), and its edge function of zero would send every ray that meets
        // its leaf to that fallback. Real meshes carry many (staircase2: 8 %).
        let bounds: Vec<Aabb> = triangles
            .iter()
            .map(|t| match corners(t) {
                Some(p) if p[0] != p[1] && p[1] != p[2] && p[2] != p[0] => Aabb::from_points(&p),
                _ => Aabb::EMPTY,
            })
            .collect();
        let kinds: Vec<u8> = emitting.iter().map(|&e| u8::from(e)).collect();
        let (root, order) = build_binary(&bounds, &kinds, &SETTINGS);
        let Some(root) = root else {
            return TriangleBvh::default();
        };
        let mut packets = Vec::with_capacity(order.len() / 3);
        let mut packet_prims = Vec::with_capacity(order.len() / 3);
        let mut tris = Vec::with_capacity(MAX_LEAF_ITEMS as usize);
        let nodes = NodeTree::new(collapse(&root, &mut |start, count| {
            let first = packets.len() as u32;
            let prims = &order[start as usize..(start + count) as usize];
            for chunk in prims.chunks(4) {
                tris.clear();
                // Indices were validated when the bounds were made.
                tris.extend(
                    chunk
                        .iter()
                        .filter_map(|&i| corners(&triangles[i as usize])),
                );
                let (block, lanes) = Triangle4::new(&tris, chunk);
                packets.push(block);
                packet_prims.push(lanes);
            }
            encode_leaf(first, packets.len() as u32 - first)
        }));
        let bounds = order
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(&bounds[i as usize]));
        let bytes = nodes.len() * std::mem::size_of::<WideNode>()
            + packets.len() * std::mem::size_of::<Triangle4>();
        TriangleBvh {
            nodes,
            packets,
            packet_prims,
            order,
            bounds,
            prefetch: !traverse::small_enough_to_stay_cached(bytes),
            #[cfg(target_arch = "x86_64")]
            avx: Avx::detect(),
        }
    }

    /// The same tree queried with the 4-lane kernels only (for tests that compare them).
    #[cfg(test)]
    pub(crate) fn without_avx(self) -> TriangleBvh {
        TriangleBvh {
            #[cfg(target_arch = "x86_64")]
            avx: None,
            ..self
        }
    }

    /// The same tree queried with the AVX kernels in their VEX encoding only (for tests
    /// that compare them with the EVEX one).
    #[cfg(all(test, target_arch = "x86_64"))]
    pub(crate) fn without_evex(self) -> TriangleBvh {
        TriangleBvh {
            avx: self.avx.map(Avx::without_evex),
            ..self
        }
    }

    /// Whether queries use the 8-lane AVX kernels compiled with the EVEX encoding.
    pub fn uses_evex(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        return self.avx.is_some_and(|a| a.evex());
        #[cfg(not(target_arch = "x86_64"))]
        return false;
    }

    /// Whether queries use the 8-lane AVX kernels.
    pub fn uses_avx(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        return self.avx.is_some();
        #[cfg(not(target_arch = "x86_64"))]
        return false;
    }

    /// Builds from a triangle soup (three corners per triangle).
    pub fn from_soup(triangles: &[[Vec3; 3]]) -> TriangleBvh {
        TriangleBvh::from_soup_with_emitters(triangles, &[])
    }

    /// [`from_soup`](Self::from_soup) with the emitting triangles marked, as
    /// [`build_with_emitters`](Self::build_with_emitters).
    pub fn from_soup_with_emitters(triangles: &[[Vec3; 3]], emitting: &[bool]) -> TriangleBvh {
        let vertices: Vec<Vec3> = triangles.iter().flatten().copied().collect();
        let indices: Vec<[u32; 3]> = (0..triangles.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        TriangleBvh::build_with_emitters(&vertices, &indices, emitting)
    }

    /// Closest hit with 0 < t < t_max (watertight, two-sided).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<MeshHit> {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx) = self.avx {
            // SAFETY: `avx` proves that this processor runs AVX code, and AVX2,
            // AVX-512F and AVX-512VL code where `avx.evex()`.
            #[allow(unsafe_code)]
            return unsafe {
                if avx.evex() {
                    by_stack!(self, intersect_evex(avx, ray, t_max))
                } else {
                    by_stack!(self, intersect_avx(avx, ray, t_max))
                }
            };
        }
        by_stack!(self, intersect_with(ray, t_max))
    }

    #[inline(always)]
    fn intersect_with<const STACK: usize>(&self, ray: &Ray, t_max: f32) -> Option<MeshHit> {
        let wr = WatertightRay4::new(&WatertightRay::new(ray));
        let mut best: Option<BlockHit> = None;
        let mut leaves = ClosestBlocks {
            bvh: self,
            ray: &wr,
            best: &mut best,
        };
        traverse::closest::<STACK>(self.nodes.nodes(), &NodeRay::new(ray), t_max, &mut leaves);
        best.map(|h| MeshHit {
            t: h.t,
            prim: self.packet_prims[h.block as usize][h.lane as usize & 3],
            b: h.b,
        })
    }

    /// [`intersect_with`](Self::intersect_with) with the 8-lane tests, compiled for AVX
    /// (with everything it inlines: no closure may carry the kernels, as closures are
    /// not compiled for their caller's features).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn intersect_avx<const STACK: usize>(
        &self,
        avx: Avx,
        ray: &Ray,
        t_max: f32,
    ) -> Option<MeshHit> {
        self.intersect_wide::<STACK>(avx, ray, t_max)
    }

    /// The same, compiled with the EVEX encoding (see [`Avx::evex`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,avx512f,avx512vl")]
    fn intersect_evex<const STACK: usize>(
        &self,
        avx: Avx,
        ray: &Ray,
        t_max: f32,
    ) -> Option<MeshHit> {
        self.intersect_wide::<STACK>(avx, ray, t_max)
    }

    /// The 8-lane closest-hit query, inlined into the functions above, which choose the
    /// instruction set it is compiled for.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_wide<const STACK: usize>(
        &self,
        avx: Avx,
        ray: &Ray,
        t_max: f32,
    ) -> Option<MeshHit> {
        let wr = WatertightRay8::new(&WatertightRay::new(ray), avx);
        let mut best: Option<BlockHit> = None;
        let mut leaves = ClosestBlocks8 {
            bvh: self,
            ray: &wr,
            best: &mut best,
        };
        traverse::closest::<STACK>(
            self.nodes.nodes(),
            &NodeRay8::new(ray, avx),
            t_max,
            &mut leaves,
        );
        best.map(|h| MeshHit {
            t: h.t,
            prim: self.packet_prims[h.block as usize][h.lane as usize & 3],
            b: h.b,
        })
    }

    /// [`leaf_closest`](Self::leaf_closest) with the leaf's blocks tested two at a time (an
    /// odd last block is paired with itself and its copy's lanes ignored). The nearest of
    /// the eight lanes, the lower lane on a tie, is what testing the two blocks in turn
    /// finds, so both kernels record the same hit.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn leaf_closest8(
        &self,
        wr: &WatertightRay8,
        leaf: u32,
        mut t_max: f32,
        best: &mut Option<BlockHit>,
    ) -> Option<f32> {
        let (start, count) = decode_leaf(leaf);
        let blocks = &self.packets[start..start + count];
        let mut hit = false;
        for (pair, chunk) in blocks.chunks(2).enumerate() {
            let (a, b, valid) = match chunk {
                [a, b] => (a, b, 0xff),
                [a] => (a, a, 0x0f),
                _ => continue,
            };
            let lanes = wr.intersect(a, b, t_max);
            let lanes_hit = lanes.hit & valid;
            if lanes_hit == 0 {
                continue;
            }
            let t = lanes.t;
            let lane = nearest_lane(lanes_hit, &t);
            let inv = 1.0 / lanes.det[lane];
            t_max = t[lane];
            hit = true;
            *best = Some(BlockHit {
                t: t_max,
                block: (start + 2 * pair + lane / 4) as u32,
                lane: (lane % 4) as u32,
                b: [
                    lanes.u[lane] * inv,
                    lanes.v[lane] * inv,
                    lanes.w[lane] * inv,
                ],
            });
        }
        hit.then_some(t_max)
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn leaf_occluded8(&self, wr: &WatertightRay8, leaf: u32, t_max: f32) -> bool {
        let (start, count) = decode_leaf(leaf);
        // A loop, not `any` with a closure: closures are not compiled for AVX.
        for chunk in self.packets[start..start + count].chunks(2) {
            let hit = match chunk {
                [a, b] => wr.intersect(a, b, t_max).hit,
                [a] => wr.intersect(a, a, t_max).hit & 0x0f,
                _ => 0,
            };
            if hit != 0 {
                return true;
            }
        }
        false
    }

    /// [`occluded_with`](Self::occluded_with) with the 8-lane tests, compiled for AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn occluded_avx<const STACK: usize>(&self, avx: Avx, ray: &Ray, t_max: f32) -> bool {
        self.occluded_wide::<STACK>(avx, ray, t_max)
    }

    /// The same, compiled with the EVEX encoding (see [`Avx::evex`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,avx512f,avx512vl")]
    fn occluded_evex<const STACK: usize>(&self, avx: Avx, ray: &Ray, t_max: f32) -> bool {
        self.occluded_wide::<STACK>(avx, ray, t_max)
    }

    /// The 8-lane any-hit query, inlined into the functions above.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn occluded_wide<const STACK: usize>(&self, avx: Avx, ray: &Ray, t_max: f32) -> bool {
        let wr = WatertightRay8::new(&WatertightRay::new(ray), avx);
        let mut leaves = AnyBlock8 {
            bvh: self,
            ray: &wr,
        };
        traverse::any::<STACK>(
            self.nodes.nodes(),
            &NodeRay8::new(ray, avx),
            t_max,
            &mut leaves,
        )
    }

    /// Intersects a leaf's blocks; records a closer hit in `best` and returns its distance.
    #[inline(always)]
    fn leaf_closest(
        &self,
        wr: &WatertightRay4,
        leaf: u32,
        mut t_max: f32,
        best: &mut Option<BlockHit>,
    ) -> Option<f32> {
        let (start, count) = decode_leaf(leaf);
        let mut hit = false;
        for (block, packet) in self.packets[start..start + count].iter().enumerate() {
            let lanes = intersect4(wr, packet, t_max);
            if lanes.hit == 0 {
                continue;
            }
            let t = lanes.t.to_array();
            let lane = nearest_lane(lanes.hit, &t);
            let inv = 1.0 / lanes.det[lane];
            t_max = t[lane];
            hit = true;
            *best = Some(BlockHit {
                t: t_max,
                block: (start + block) as u32,
                lane: lane as u32,
                b: [
                    lanes.u[lane] * inv,
                    lanes.v[lane] * inv,
                    lanes.w[lane] * inv,
                ],
            });
        }
        hit.then_some(t_max)
    }

    #[inline(always)]
    fn touch_leaf(&self, leaf: u32) {
        let (start, _) = decode_leaf(leaf);
        if let Some(p) = self.packets.get(start) {
            // One word in each cache line a 144-byte block can span.
            std::hint::black_box(p.v[0][0].x);
            std::hint::black_box(p.v[1][1].x);
            std::hint::black_box(p.v[2][2].w);
        }
    }

    #[inline(always)]
    fn leaf_occluded(&self, wr: &WatertightRay4, leaf: u32, t_max: f32) -> bool {
        let (start, count) = decode_leaf(leaf);
        self.packets[start..start + count]
            .iter()
            .any(|p| intersect4(wr, p, t_max).hit != 0)
    }

    /// Whether anything is hit with 0 < t < t_max.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx) = self.avx {
            // SAFETY: as for `intersect`.
            #[allow(unsafe_code)]
            return unsafe {
                if avx.evex() {
                    by_stack!(self, occluded_evex(avx, ray, t_max))
                } else {
                    by_stack!(self, occluded_avx(avx, ray, t_max))
                }
            };
        }
        by_stack!(self, occluded_with(ray, t_max))
    }

    #[inline(always)]
    fn occluded_with<const STACK: usize>(&self, ray: &Ray, t_max: f32) -> bool {
        let wr = WatertightRay4::new(&WatertightRay::new(ray));
        let mut leaves = AnyBlock {
            bvh: self,
            ray: &wr,
        };
        traverse::any::<STACK>(self.nodes.nodes(), &NodeRay::new(ray), t_max, &mut leaves)
    }

    /// Triangle indices in leaf order (see [`Bvh::prim_order`](super::Bvh::prim_order)).
    pub fn prim_order(&self) -> &[u32] {
        &self.order
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of triangles in the tree.
    pub fn triangle_count(&self) -> usize {
        self.order.len()
    }

    /// (wide nodes, 4-triangle blocks), for statistics.
    pub fn size(&self) -> (usize, usize) {
        (self.nodes.len(), self.packets.len())
    }
}

/// Of the lanes set in `hits` (not empty), the one with the smallest `t`, the lowest on
/// a tie: the rule both kernels share, so that they pick the same triangle.
#[inline(always)]
fn nearest_lane<const N: usize>(hits: u32, t: &[f32; N]) -> usize {
    let mut lane = hits.trailing_zeros() as usize % N;
    let mut rest = hits & hits.wrapping_sub(1);
    while rest != 0 {
        let l = rest.trailing_zeros() as usize % N;
        if t[l] < t[lane] {
            lane = l;
        }
        rest &= rest - 1;
    }
    lane
}

/// The closest hit so far, by block and lane (the triangle index is looked up once, at the end).
#[derive(Clone, Copy)]
struct BlockHit {
    t: f32,
    block: u32,
    lane: u32,
    b: [f32; 3],
}

struct ClosestBlocks<'a> {
    bvh: &'a TriangleBvh,
    ray: &'a WatertightRay4,
    best: &'a mut Option<BlockHit>,
}

impl ClosestLeaf for ClosestBlocks<'_> {
    #[inline(always)]
    fn visit(&mut self, leaf: u32, t_max: f32) -> Option<f32> {
        self.bvh.leaf_closest(self.ray, leaf, t_max, self.best)
    }

    #[inline(always)]
    fn touch(&self, leaf: u32) {
        self.bvh.touch_leaf(leaf);
    }

    #[inline(always)]
    fn prefetches(&self) -> bool {
        self.bvh.prefetch
    }
}

struct AnyBlock<'a> {
    bvh: &'a TriangleBvh,
    ray: &'a WatertightRay4,
}

impl AnyLeaf for AnyBlock<'_> {
    #[inline(always)]
    fn visit(&mut self, leaf: u32, t_max: f32) -> bool {
        self.bvh.leaf_occluded(self.ray, leaf, t_max)
    }

    #[inline(always)]
    fn touch(&self, leaf: u32) {
        self.bvh.touch_leaf(leaf);
    }

    #[inline(always)]
    fn prefetches(&self) -> bool {
        self.bvh.prefetch
    }
}

#[cfg(target_arch = "x86_64")]
struct ClosestBlocks8<'a> {
    bvh: &'a TriangleBvh,
    ray: &'a WatertightRay8,
    best: &'a mut Option<BlockHit>,
}

#[cfg(target_arch = "x86_64")]
impl ClosestLeaf for ClosestBlocks8<'_> {
    #[inline(always)]
    fn visit(&mut self, leaf: u32, t_max: f32) -> Option<f32> {
        self.bvh.leaf_closest8(self.ray, leaf, t_max, self.best)
    }

    #[inline(always)]
    fn touch(&self, leaf: u32) {
        self.bvh.touch_leaf(leaf);
    }

    #[inline(always)]
    fn prefetches(&self) -> bool {
        self.bvh.prefetch
    }
}

#[cfg(target_arch = "x86_64")]
struct AnyBlock8<'a> {
    bvh: &'a TriangleBvh,
    ray: &'a WatertightRay8,
}

#[cfg(target_arch = "x86_64")]
impl AnyLeaf for AnyBlock8<'_> {
    #[inline(always)]
    fn visit(&mut self, leaf: u32, t_max: f32) -> bool {
        self.bvh.leaf_occluded8(self.ray, leaf, t_max)
    }

    #[inline(always)]
    fn touch(&self, leaf: u32) {
        self.bvh.touch_leaf(leaf);
    }

    #[inline(always)]
    fn prefetches(&self) -> bool {
        self.bvh.prefetch
    }
}
