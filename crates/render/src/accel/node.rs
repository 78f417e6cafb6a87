//! The wide BVH node and the per-ray constants of its box test.

use crate::geometry::{Aabb, Ray};
use glam::Vec4;

/// Set in a child reference that points at a leaf; clear for an inner node index.
pub(crate) const LEAF_BIT: u32 = 1 << 31;
/// Child slot with no child (its box is inverted, so it is never hit).
pub(crate) const EMPTY_CHILD: u32 = u32::MAX;
/// A leaf reference holds (start << 3) | (count − 1): up to 8 items from 2^28 − 1 starts.
pub(crate) const MAX_LEAF_ITEMS: u32 = 8;
pub(crate) const MAX_LEAF_START: u32 = (1 << 28) - 1;

#[inline]
pub(crate) fn encode_leaf(start: u32, count: u32) -> u32 {
    assert!(
        start <= MAX_LEAF_START && (1..=MAX_LEAF_ITEMS).contains(&count),
        "BVH leaf out of encodable range (more than 2^28 leaf items?)"
    );
    LEAF_BIT | (start << 3) | (count - 1)
}

/// (start, count) of a leaf reference.
#[inline(always)]
pub(crate) fn decode_leaf(r: u32) -> (usize, usize) {
    (((r & !LEAF_BIT) >> 3) as usize, ((r & 7) + 1) as usize)
}

/// SIMD groups of four lanes per node; the node is `WIDTH = 4 · GROUPS` wide.
pub(crate) const GROUPS: usize = 2;
/// Children per node.
pub(crate) const WIDTH: usize = 4 * GROUPS;

/// `WIDTH` child boxes in structure-of-arrays layout, so that one SSE operation tests one
/// slab of four children (Dammertz et al., "Shallow Bounding Volume Hierarchies for Fast
/// SIMD Ray Tracing of Incoherent Rays", EGSR 2008; Ernst & Greiner, "Multi Bounding Volume
/// Hierarchies", IEEE RT 2008; Wald et al., "Embree", SIGGRAPH 2014, for 8-wide nodes).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct WideNode {
    /// `bounds[axis][0][g]` holds the minima along `axis` of children 4g..4g+3, `[1]` the maxima.
    pub bounds: [[[Vec4; GROUPS]; 2]; 3],
    pub child: [u32; WIDTH],
}

impl WideNode {
    pub fn empty() -> WideNode {
        WideNode {
            bounds: [[[Vec4::INFINITY; GROUPS], [Vec4::NEG_INFINITY; GROUPS]]; 3],
            child: [EMPTY_CHILD; WIDTH],
        }
    }

    pub fn set_child(&mut self, k: usize, b: &Aabb, child: u32) {
        for axis in 0..3 {
            self.bounds[axis][0][k / 4][k % 4] = b.min[axis];
            self.bounds[axis][1][k / 4][k % 4] = b.max[axis];
        }
        self.child[k] = child;
    }
}

/// 1 + 2γ(3) with γ(n) = nε / (1 − nε), ε = 2⁻²⁴: padding the reciprocal direction used for
/// the exit planes by it makes the slab test conservative under f32 round-off (Ize, "Robust
/// BVH Ray Traversal", JCGT 2013), so the box test never culls a hit the watertight triangle
/// test would report.
pub(crate) const ROBUST_EXIT_SCALE: f32 = 1.000_000_4;

/// Per-ray constants of the four-box slab test (Kay & Kajiya 1986; Williams et al., "An
/// Efficient and Robust Ray-Box Intersection Algorithm", JGT 2005): the reciprocal
/// direction, and for each axis which of min/max is the entry plane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeRay {
    o: [Vec4; 3],
    inv: [Vec4; 3],
    /// `inv` padded by [`ROBUST_EXIT_SCALE`], for the exit planes.
    inv_exit: [Vec4; 3],
    near: [usize; 3],
}

impl NodeRay {
    #[inline(always)]
    pub fn new(ray: &Ray) -> NodeRay {
        let inv = ray.d.recip().to_array();
        NodeRay {
            o: [
                Vec4::splat(ray.o.x),
                Vec4::splat(ray.o.y),
                Vec4::splat(ray.o.z),
            ],
            inv: inv.map(Vec4::splat),
            inv_exit: inv.map(|v| Vec4::splat(v * ROBUST_EXIT_SCALE)),
            near: inv.map(|v| usize::from(v < 0.0)),
        }
    }

    /// Entry distances of the child boxes and the bitmask of those the ray enters
    /// within `[0, t_max]`.
    #[inline(always)]
    pub fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [Vec4; GROUPS]) {
        let mut mask = 0;
        let mut entry = [Vec4::ZERO; GROUPS];
        for g in 0..GROUPS {
            let mut t_in = Vec4::ZERO;
            // The computed entry distance may exceed the true one by the same round-off, so
            // the limit is padded too: a box entered just before t_max is never culled.
            let mut t_out = Vec4::splat(t_max * ROBUST_EXIT_SCALE);
            for axis in 0..3 {
                let s = self.near[axis] & 1;
                let planes = &node.bounds[axis];
                let t0 = (planes[s][g] - self.o[axis]) * self.inv[axis];
                let t1 = (planes[s ^ 1][g] - self.o[axis]) * self.inv_exit[axis];
                // A zero direction component gives inv = ±∞, and a ray starting exactly on a
                // slab plane then gives 0 · ∞ = NaN. The operand order makes the NaN drop out
                // (SSE min/max return the second operand when either is NaN, and f32::min/max
                // ignore NaN), which treats the ray as inside that slab: correct, as it lies
                // on the plane.
                t_in = t0.max(t_in);
                t_out = t1.min(t_out);
            }
            mask |= t_in.cmple(t_out).bitmask() << (4 * g);
            entry[g] = t_in;
        }
        (mask, entry)
    }
}
