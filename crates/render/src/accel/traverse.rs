//! Stack-based traversal of the wide node array, shared by the generic and the
//! triangle BVH. Leaves are handed to a visitor (a trait implemented per BVH kind, with
//! `#[inline(always)]`), so the triangle path is monomorphised and pays no indirection.
//!
//! Closest-hit traversal is ordered: of the children a ray enters, the nearest (by entry
//! distance) is visited next and the others are pushed far-to-near, each with its entry
//! distance so that it is skipped when popped if a closer hit has been found since.

use super::build::MAX_DEPTH;
use super::node::{LEAF_BIT, NodeRay, ROBUST_EXIT_SCALE, WIDTH, WideNode};

/// Each level pushes at most `WIDTH − 1` siblings and there are at most `MAX_DEPTH`
/// levels, so this bounds the stack of any tree.
pub(crate) const LARGE_STACK: usize = (WIDTH - 1) * MAX_DEPTH as usize + 4;
/// The stack for trees of at most `SMALL_STACK_DEPTH` levels: typical trees are shallow,
/// and zeroing the large stack for every ray costs measurably (~10 % on shadow rays).
pub(crate) const SMALL_STACK: usize = 96;
const SMALL_STACK_DEPTH: u32 = (SMALL_STACK as u32 - 1) / (WIDTH as u32 - 1);
/// The stack for trees of at most five levels (small scenes such as the Cornell box):
/// even the small stack's zeroing was 3 % of a path-traced sample there.
pub(crate) const TINY_STACK: usize = 36;
const TINY_STACK_DEPTH: u32 = (TINY_STACK as u32 - 1) / (WIDTH as u32 - 1);

/// Which traversal stack a tree needs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum StackSize {
    #[default]
    Tiny,
    Small,
    Large,
}

/// The flattened wide nodes (node 0 is the root) and the stack they need.
#[derive(Clone, Debug, Default)]
pub(crate) struct NodeTree {
    nodes: Vec<WideNode>,
    stack: StackSize,
}

impl NodeTree {
    pub fn new(nodes: Vec<WideNode>) -> NodeTree {
        // Children always follow their parent in the array, so one forward pass finds
        // every node's level.
        let mut level = vec![1u32; nodes.len()];
        for i in 0..nodes.len() {
            for &c in &nodes[i].child {
                if c & LEAF_BIT == 0 {
                    level[c as usize] = level[i] + 1;
                }
            }
        }
        let depth = level.iter().copied().max().unwrap_or(0);
        let stack = if depth <= TINY_STACK_DEPTH {
            StackSize::Tiny
        } else if depth <= SMALL_STACK_DEPTH {
            StackSize::Small
        } else {
            StackSize::Large
        };
        NodeTree { nodes, stack }
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn nodes(&self) -> &[WideNode] {
        &self.nodes
    }

    /// The stack the tree needs. Callers dispatch on this once per query to a
    /// monomorphised traversal (doing it here would keep the leaf closures from inlining).
    pub fn stack(&self) -> StackSize {
        self.stack
    }
}

/// The box test of a wide node for one ray: the mask of the children it enters within
/// `[0, t_max]` and their entry distances. Implemented by the 4-lane test and, where the
/// processor has it, the 8-lane AVX one (which give the same bits).
pub(crate) trait NodeTest {
    fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]);
}

impl NodeTest for NodeRay {
    #[inline(always)]
    fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        let (mask, t_in) = NodeRay::hit(self, node, t_max);
        let mut t = [0.0f32; WIDTH];
        for (g, v) in t_in.iter().enumerate() {
            t[4 * g..4 * g + 4].copy_from_slice(&v.to_array());
        }
        (mask, t)
    }
}

/// What closest-hit traversal does at a leaf: intersect its primitives with hits closer
/// than `t_max`, and return the new (smaller) `t_max` if there was one. A trait with
/// `#[inline(always)]` implementations rather than a closure, because LLVM declines to
/// inline a closure whose body (the SIMD triangle test) is large.
pub(crate) trait ClosestLeaf {
    fn visit(&mut self, leaf: u32, t_max: f32) -> Option<f32>;
    /// Loads the leaf's first data early (a software prefetch in safe Rust).
    fn touch(&self, _leaf: u32) {}
    /// Whether entered children are touched at all (see [`small_enough_to_stay_cached`]).
    fn prefetches(&self) -> bool {
        true
    }
}

/// Trees whose nodes and leaves together take at most this many bytes are not
/// prefetched: after the first rays they stay in the core's caches, and touching the
/// children of every node entered was then pure overhead (about 50 instructions a
/// closest-hit query on the Cornell box, 6 % of it). Half of a 1 MiB L2 cache.
const CACHED_TREE_BYTES: usize = 512 << 10;

/// True when a tree of `bytes` (nodes and leaf data) is [`CACHED_TREE_BYTES`] or less.
pub(crate) fn small_enough_to_stay_cached(bytes: usize) -> bool {
    bytes <= CACHED_TREE_BYTES
}

/// Starts loading every entered child's data at once, so that their cache misses overlap
/// instead of being taken one after another when each is visited.
#[inline(always)]
fn touch_children(nodes: &[WideNode], node: &WideNode, mut mask: u32, touch_leaf: impl Fn(u32)) {
    while mask != 0 {
        let c = node.child[mask.trailing_zeros() as usize % WIDTH];
        mask &= mask - 1;
        if c & LEAF_BIT == 0 {
            if let Some(n) = nodes.get(c as usize) {
                // A word in each cache line of the node (each axis, then the children).
                for axis in &n.bounds {
                    std::hint::black_box(axis[0][0].x);
                }
                std::hint::black_box(n.child[0]);
            }
        } else {
            touch_leaf(c);
        }
    }
}

/// What any-hit traversal does at a leaf: report whether it holds an occluder.
pub(crate) trait AnyLeaf {
    fn visit(&mut self, leaf: u32, t_max: f32) -> bool;
    /// Loads the leaf's first data early (a software prefetch in safe Rust).
    fn touch(&self, _leaf: u32) {}
    /// Whether entered children are touched at all (as [`ClosestLeaf::prefetches`]).
    fn prefetches(&self) -> bool {
        true
    }
}

#[derive(Clone, Copy, Default)]
struct Entry {
    node: u32,
    t_in: f32,
}

/// Visits the leaves that may hold a hit closer than `t_max`, nearest first.
/// `leaf.visit(reference, t_max)` returns the new, smaller `t_max` when it found a hit.
/// Returns the final `t_max`.
#[inline(always)]
pub(crate) fn closest<const STACK_SIZE: usize>(
    nodes: &[WideNode],
    ray: &impl NodeTest,
    mut t_max: f32,
    leaf: &mut impl ClosestLeaf,
) -> f32 {
    if nodes.is_empty() {
        return t_max;
    }
    let mut stack = [Entry::default(); STACK_SIZE];
    let mut sp = 0usize;
    let mut cur = 0u32;
    loop {
        if cur & LEAF_BIT == 0 {
            let node = &nodes[cur as usize];
            let (mut mask, t) = ray.hit(node, t_max);
            if mask != 0 {
                if leaf.prefetches() {
                    touch_children(nodes, node, mask, |c| leaf.touch(c));
                }
                let i0 = mask.trailing_zeros() as usize % WIDTH;
                mask &= mask - 1;
                if mask == 0 {
                    cur = node.child[i0];
                    continue;
                }
                let i1 = mask.trailing_zeros() as usize % WIDTH;
                mask &= mask - 1;
                if mask == 0 {
                    let (near, far) = if t[i0] <= t[i1] { (i0, i1) } else { (i1, i0) };
                    stack[sp] = Entry {
                        node: node.child[far],
                        t_in: t[far],
                    };
                    sp += 1;
                    cur = node.child[near];
                    continue;
                }
                // Three or more children: sort by entry distance (insertion sort), nearest
                // last, and push all but the nearest.
                let mut c = [Entry::default(); WIDTH];
                let mut k = 0;
                for i in [i0, i1] {
                    c[k] = Entry {
                        node: node.child[i],
                        t_in: t[i],
                    };
                    k += 1;
                }
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize % WIDTH;
                    mask &= mask - 1;
                    c[k % WIDTH] = Entry {
                        node: node.child[i],
                        t_in: t[i],
                    };
                    k += 1;
                }
                let k = k.min(WIDTH);
                for i in 1..k {
                    let mut j = i;
                    while j > 0 && c[j - 1].t_in < c[j].t_in {
                        c.swap(j - 1, j);
                        j -= 1;
                    }
                }
                for e in &c[..k - 1] {
                    stack[sp] = *e;
                    sp += 1;
                }
                cur = c[k - 1].node;
                continue;
            }
        } else if let Some(t) = leaf.visit(cur, t_max) {
            t_max = t;
        }
        // Pop the nearest pending subtree that can still hold a closer hit.
        loop {
            if sp == 0 {
                return t_max;
            }
            sp -= 1;
            let e = stack[sp];
            // Padded like the box test: t_in may be rounded up by a few ulps.
            if e.t_in <= t_max * ROBUST_EXIT_SCALE {
                cur = e.node;
                break;
            }
        }
    }
}

/// Visits leaves until `leaf.visit(reference, t_max)` reports an occluder; returns whether one did.
#[inline(always)]
pub(crate) fn any<const STACK_SIZE: usize>(
    nodes: &[WideNode],
    ray: &impl NodeTest,
    t_max: f32,
    leaf: &mut impl AnyLeaf,
) -> bool {
    if nodes.is_empty() {
        return false;
    }
    let mut stack = [0u32; STACK_SIZE];
    let mut sp = 0usize;
    let mut cur = 0u32;
    loop {
        if cur & LEAF_BIT == 0 {
            let node = &nodes[cur as usize];
            let (mask, _) = ray.hit(node, t_max);
            if mask != 0 {
                if leaf.prefetches() {
                    touch_children(nodes, node, mask, |c| leaf.touch(c));
                }
                // Branch-free compaction: every child is written, only entered ones count.
                for (i, &c) in node.child.iter().enumerate() {
                    stack[sp.min(STACK_SIZE - 1)] = c;
                    sp += ((mask >> i) & 1) as usize;
                }
            }
        } else if leaf.visit(cur, t_max) {
            return true;
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        cur = stack[sp];
    }
}
