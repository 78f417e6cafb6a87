//! Binned SAH construction of a binary BVH, then collapse into a wide (8-child) node array.
//!
//! The binary build follows Wald, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies" (IEEE RT 2007): primitive centroids are binned into a fixed number of
//! buckets per axis, the surface area heuristic (Goldsmith & Salmon 1987; MacDonald &
//! Booth 1990) is evaluated at every bucket boundary, and the primitive references are
//! partitioned in place. Large ranges are binned in parallel and subtrees built with
//! `rayon::join`. The binary tree is then collapsed into wide nodes by repeatedly
//! opening the child with the largest surface area (as in Wald et al., "Getting Rid of
//! Packets", IEEE RT 2008, and Embree's BVH4), and flattened depth-first. Small ranges
//! that span much of the scene may instead be built bottom-up (cluster.rs).

use super::cluster::{CLUSTER_MAX, Costs, RayModel, cluster_range};
use super::node::{WIDTH, WideNode};
use crate::geometry::Aabb;
use glam::Vec3;

/// Knobs of the SAH builder.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BuildSettings {
    /// Primitives are intersected in blocks of this many (4 for SIMD triangle packets):
    /// the SAH counts ceil(n / block) intersection steps for a leaf of n.
    pub leaf_block: u32,
    /// Largest leaf the SAH may choose.
    pub max_leaf: u32,
    /// Primitives the leaf kernel tests at once (two blocks of triangles in one 8-lane
    /// test): the unit of a leaf's cost in the bottom-up build (cluster.rs).
    pub leaf_test: u32,
    /// Largest leaf the bottom-up build may choose. Its ranges are small and span much
    /// of the scene, and there a whole object (a box of 10–12 triangles) in one leaf
    /// tested in two kernel calls is cheaper than a node over its faces.
    pub max_cluster_leaf: u32,
    /// Cost of one node visit relative to one block intersection.
    pub cost_traversal: f32,
}

/// One primitive reference during the build.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrimRef {
    pub min: Vec3,
    pub id: u32,
    pub max: Vec3,
}

impl PrimRef {
    /// Twice the centroid: binning only needs it up to scale.
    #[inline]
    fn centroid2(&self) -> Vec3 {
        self.min + self.max
    }
}

/// Node of the binary build tree.
pub(crate) enum BuildNode {
    Leaf {
        bounds: Aabb,
        start: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        children: Box<[BuildNode; 2]>,
    },
}

impl BuildNode {
    fn bounds(&self) -> &Aabb {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Inner { bounds, .. } => bounds,
        }
    }
}

const BINS: usize = 32;
/// Subtrees with fewer primitives than this are built on the current thread.
const PARALLEL_MIN: usize = 4096;
/// Ranges with more primitives than this are binned in parallel chunks.
const PARALLEL_BIN_MIN: usize = 1 << 16;
/// Bound on the depth of the binary tree; traversal stacks are sized from it.
pub(crate) const MAX_DEPTH: u32 = 60;

/// Builds the binary tree over the boxes with finite, non-empty bounds (others can never
/// be hit and are left out). Returns the root (`None` when nothing remains) and the leaf
/// order: leaf ranges index into it, and it holds the original primitive indices.
///
/// `kinds` gives each primitive a kind (empty: all of one kind), and no leaf holds
/// primitives of two kinds (short of the depth bound). The triangle BVH keeps emitters apart from the rest: shadow
/// rays stop just short of the emitter they aim at, so an emitter's own flat leaf is not
/// entered by them, while a leaf that also held nearby geometry would be entered, and
/// tested, by nearly all of them (on the Cornell box, the light shared a leaf with the
/// top of the tall block, and 90 % of the shadow rays tested it).
pub(crate) fn build_binary(
    prim_bounds: &[Aabb],
    kinds: &[u8],
    settings: &BuildSettings,
) -> (Option<BuildNode>, Vec<u32>) {
    let mut refs: Vec<PrimRef> = prim_bounds
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.is_empty() && b.min.is_finite() && b.max.is_finite())
        .map(|(i, b)| PrimRef {
            min: b.min,
            id: i as u32,
            max: b.max,
        })
        .collect();
    if refs.is_empty() {
        return (None, Vec::new());
    }
    let costs = Costs {
        settings,
        rays: RayModel::inside(&range_bounds(&refs).0),
        kinds,
    };
    let mut root = build_range(&mut refs, 0, 0, &costs);
    merge_small_wide_nodes(&mut root, &refs, &costs);
    (Some(root), refs.iter().map(|r| r.id).collect())
}

/// Makes one leaf of each subtree that the collapse would make a wide node of its own
/// where the leaf is cheaper than that node's visit and its children. The build prices
/// a binary node at its share of a wide node (cluster.rs), which holds where the node is
/// absorbed into its parent's wide node; where the parent's slots are full, the subtree
/// becomes a wide node of its own after all, and its visit costs in full. On the Cornell
/// box, whose walls and light fill a wide node's slots, each block is cheaper as one
/// leaf of 10 triangles (two kernel tests) than as a node over its faces. `node` is the
/// root of a wide node; returns its cost after the merges.
fn merge_small_wide_nodes(node: &mut BuildNode, refs: &[PrimRef], c: &Costs) -> f32 {
    let mut cost = c.settings.cost_traversal * c.rays.weight(node.bounds());
    for slot in wide_children_mut(node) {
        cost += match slot {
            BuildNode::Leaf { bounds, count, .. } => c.leaf(bounds, *count),
            BuildNode::Inner { .. } => {
                let as_node = merge_small_wide_nodes(slot, refs, c);
                let (start, count) = leaf_range(slot);
                let bounds = *slot.bounds();
                let prims = &refs[start as usize..(start + count) as usize];
                let as_leaf = c.leaf(&bounds, count);
                if count <= c.settings.max_cluster_leaf
                    && c.kind_of_all(prims).is_some()
                    && as_leaf < as_node
                {
                    *slot = BuildNode::Leaf {
                        bounds,
                        start,
                        count,
                    };
                    as_leaf
                } else {
                    as_node
                }
            }
        };
    }
    cost
}

/// The contiguous range of the leaf order that a subtree covers: (start, count).
fn leaf_range(node: &BuildNode) -> (u32, u32) {
    match node {
        BuildNode::Leaf { start, count, .. } => (*start, *count),
        BuildNode::Inner { children, .. } => {
            let (start, left) = leaf_range(&children[0]);
            let (_, right) = leaf_range(&children[1]);
            (start, left + right)
        }
    }
}

/// Bounds of the boxes and of their (doubled) centroids.
fn range_bounds(refs: &[PrimRef]) -> (Aabb, Aabb) {
    let fold = |refs: &[PrimRef]| {
        refs.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), r| {
            (
                Aabb {
                    min: b.min.min(r.min),
                    max: b.max.max(r.max),
                },
                c.grow(r.centroid2()),
            )
        })
    };
    if refs.len() < PARALLEL_BIN_MIN {
        return fold(refs);
    }
    use rayon::prelude::*;
    refs.par_chunks(PARALLEL_BIN_MIN / 4).map(fold).reduce(
        || (Aabb::EMPTY, Aabb::EMPTY),
        |a, b| (a.0.union(&b.0), a.1.union(&b.1)),
    )
}

/// Per-axis bin contents.
#[derive(Clone)]
struct Bins {
    bounds: [[Aabb; BINS]; 3],
    counts: [[u32; BINS]; 3],
}

impl Bins {
    fn new() -> Bins {
        Bins {
            bounds: [[Aabb::EMPTY; BINS]; 3],
            counts: [[0; BINS]; 3],
        }
    }

    fn merge(mut self, o: &Bins) -> Bins {
        for a in 0..3 {
            for i in 0..BINS {
                self.bounds[a][i] = self.bounds[a][i].union(&o.bounds[a][i]);
                self.counts[a][i] += o.counts[a][i];
            }
        }
        self
    }
}

/// Maps doubled centroids to bin indices.
#[derive(Clone, Copy)]
struct Binner {
    origin: Vec3,
    scale: Vec3,
}

impl Binner {
    fn new(centroids: &Aabb) -> Binner {
        let extent = centroids.max - centroids.min;
        // Slightly fewer than BINS so the largest centroid still lands in the last bin.
        let k = BINS as f32 * (1.0 - 1e-5);
        let scale = Vec3::select(extent.cmpgt(Vec3::ZERO), k / extent, Vec3::ZERO);
        Binner {
            origin: centroids.min,
            scale,
        }
    }

    #[inline]
    fn bin(&self, c: Vec3) -> [usize; 3] {
        let b = ((c - self.origin) * self.scale).as_uvec3();
        [b.x as usize, b.y as usize, b.z as usize].map(|i| i.min(BINS - 1))
    }

    fn fill(&self, refs: &[PrimRef]) -> Bins {
        let mut bins = Bins::new();
        for r in refs {
            let b = self.bin(r.centroid2());
            for (a, &bin) in b.iter().enumerate() {
                let slot = &mut bins.bounds[a][bin];
                slot.min = slot.min.min(r.min);
                slot.max = slot.max.max(r.max);
                bins.counts[a][bin] += 1;
            }
        }
        bins
    }
}

struct Split {
    axis: usize,
    /// Primitives in bins `< bin` go left.
    bin: usize,
    /// SAH cost relative to the parent's area, in units of one block intersection.
    cost: f32,
}

fn best_split(bins: &Bins, parent_area: f32, settings: &BuildSettings) -> Option<Split> {
    let blocks = |n: u32| n.div_ceil(settings.leaf_block) as f32;
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        // Right-to-left sweep: area and count of everything at or after bin i.
        let mut right_cost = [0.0f32; BINS];
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        for i in (1..BINS).rev() {
            acc = acc.union(&bins.bounds[axis][i]);
            count += bins.counts[axis][i];
            right_cost[i] = if count > 0 {
                acc.surface_area() * blocks(count)
            } else {
                0.0
            };
        }
        let mut acc = Aabb::EMPTY;
        let mut count = 0;
        let total: u32 = bins.counts[axis].iter().sum();
        for (i, &right) in right_cost.iter().enumerate().skip(1) {
            acc = acc.union(&bins.bounds[axis][i - 1]);
            count += bins.counts[axis][i - 1];
            if count == 0 || count == total {
                continue;
            }
            let cost = settings.cost_traversal
                + (acc.surface_area() * blocks(count) + right) / parent_area;
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                best = Some(Split { axis, bin: i, cost });
            }
        }
    }
    best
}

/// Moves the references whose predicate holds to the front; returns how many there are.
fn partition(refs: &mut [PrimRef], goes_left: impl Fn(&PrimRef) -> bool) -> usize {
    let (mut i, mut j) = (0, refs.len());
    while i < j {
        if goes_left(&refs[i]) {
            i += 1;
        } else {
            j -= 1;
            refs.swap(i, j);
        }
    }
    i
}

fn build_range(refs: &mut [PrimRef], offset: u32, depth: u32, c: &Costs) -> BuildNode {
    let n = refs.len();
    let (bounds, centroids) = range_bounds(refs);
    if n == 1 {
        return BuildNode::Leaf {
            bounds,
            start: offset,
            count: 1,
        };
    }
    // Small ranges at the scale of the scene's rays are also built bottom-up, and the
    // tree the interior ray model finds cheaper is kept (cluster.rs).
    if n <= CLUSTER_MAX && depth + n as u32 <= MAX_DEPTH && c.rays.is_interior_scale(&bounds) {
        let mut clustered = refs.to_vec();
        let (bottom_up, bottom_up_cost) = cluster_range(&mut clustered, offset, c);
        let top_down = split_range(refs, offset, depth, c, bounds, centroids);
        if bottom_up_cost < c.tree_cost(&top_down) {
            refs.copy_from_slice(&clustered);
            return bottom_up;
        }
        return top_down;
    }
    split_range(refs, offset, depth, c, bounds, centroids)
}

/// Top-down: the best binned SAH split of the range (or a leaf), then its halves.
fn split_range(
    refs: &mut [PrimRef],
    offset: u32,
    depth: u32,
    c: &Costs,
    bounds: Aabb,
    centroids: Aabb,
) -> BuildNode {
    let s = c.settings;
    let n = refs.len();
    let leaf = BuildNode::Leaf {
        bounds,
        start: offset,
        count: n as u32,
    };
    // Small enough for a leaf, but of two kinds: one subtree per kind. The extra level
    // is not taken near the depth bound, whose fallback below must still reach single
    // primitives within it (a mixed leaf there costs speed, never a hit).
    let levels_left = usize::BITS - n.leading_zeros();
    if n <= s.max_leaf as usize
        && depth + levels_left + 2 < MAX_DEPTH
        && c.kind_of_all(refs).is_none()
    {
        let first = c.kind(&refs[0]);
        let k = partition(refs, |r| c.kind(r) == first);
        return split_inner(refs, offset, depth, c, bounds, k);
    }
    let leaf_cost = n.div_ceil(s.leaf_block as usize) as f32;
    // Near the depth bound (or with all centroids coincident) fall back to halving
    // the range, which reaches single primitives within log2(n) more levels.
    let remaining_levels = usize::BITS - (n - 1).leading_zeros();
    let force_median = depth + remaining_levels + 1 >= MAX_DEPTH;
    let split_at = if force_median || centroids.max == centroids.min {
        if n <= s.max_leaf as usize && !force_median {
            return leaf;
        }
        let axis = centroids.diagonal().max_position();
        let mid = n / 2;
        refs.select_nth_unstable_by(mid, |a, b| {
            a.centroid2()[axis].total_cmp(&b.centroid2()[axis])
        });
        mid
    } else {
        let binner = Binner::new(&centroids);
        let bins = if n < PARALLEL_BIN_MIN {
            binner.fill(refs)
        } else {
            use rayon::prelude::*;
            refs.par_chunks(PARALLEL_BIN_MIN / 4)
                .map(|c| binner.fill(c))
                .reduce(Bins::new, |a, b| a.merge(&b))
        };
        let split = best_split(&bins, bounds.surface_area().max(f32::MIN_POSITIVE), s);
        match split {
            Some(sp) if n > s.max_leaf as usize || sp.cost < leaf_cost => {
                let k = partition(refs, |r| binner.bin(r.centroid2())[sp.axis] < sp.bin);
                if k == 0 || k == n { n / 2 } else { k }
            }
            _ if n <= s.max_leaf as usize => return leaf,
            _ => n / 2,
        }
    };
    split_inner(refs, offset, depth, c, bounds, split_at)
}

/// The inner node over `refs` split after the first `k`, its halves built in turn.
fn split_inner(
    refs: &mut [PrimRef],
    offset: u32,
    depth: u32,
    c: &Costs,
    bounds: Aabb,
    k: usize,
) -> BuildNode {
    let n = refs.len();
    let (left, right) = refs.split_at_mut(k);
    let right_offset = offset + k as u32;
    let (l, r) = if n >= PARALLEL_MIN {
        rayon::join(
            || build_range(left, offset, depth + 1, c),
            || build_range(right, right_offset, depth + 1, c),
        )
    } else {
        (
            build_range(left, offset, depth + 1, c),
            build_range(right, right_offset, depth + 1, c),
        )
    };
    BuildNode::Inner {
        bounds,
        children: Box::new([l, r]),
    }
}

/// Collapses the binary tree into `WIDTH`-wide nodes (node 0 is the root). `leaf_ref`
/// turns a leaf's range of the leaf order into an encoded child reference (so the triangle
/// BVH can repack leaves into SIMD blocks).
///
/// Layout: the inner children of a node get consecutive slots, and its leaves' data is
/// packed together before any deeper level's, so that what one node visit touches lies
/// close together in memory (as in Ylitie et al., "Efficient Incoherent Ray Traversal on
/// GPUs Through Compressed Wide BVHs", HPG 2017). Parents precede their children.
pub(crate) fn collapse(
    root: &BuildNode,
    leaf_ref: &mut impl FnMut(u32, u32) -> u32,
) -> Vec<WideNode> {
    let mut nodes = vec![WideNode::empty()];
    match root {
        BuildNode::Leaf {
            bounds,
            start,
            count,
        } => nodes[0].set_child(0, bounds, leaf_ref(*start, *count)),
        BuildNode::Inner { .. } => fill(root, 0, &mut nodes, leaf_ref),
    }
    nodes
}

/// The up-to-`WIDTH` binary-tree nodes that become the children of the wide node for
/// inner node `node`: its two children, then repeatedly the inner child with the largest
/// surface area replaced by its own two children.
fn wide_children(node: &BuildNode) -> Vec<&BuildNode> {
    let BuildNode::Inner { children, .. } = node else {
        return vec![node];
    };
    let mut slots: Vec<&BuildNode> = children.iter().collect();
    while slots.len() < WIDTH {
        let Some(i) = widest_inner(slots.iter().copied()) else {
            break;
        };
        let BuildNode::Inner { children, .. } = slots.swap_remove(i) else {
            unreachable!("only inner nodes are opened")
        };
        slots.extend(children.iter());
    }
    slots
}

/// The inner node with the largest surface area among `slots` (the last on a tie), which
/// the collapse opens next.
fn widest_inner<'a>(slots: impl Iterator<Item = &'a BuildNode>) -> Option<usize> {
    slots
        .enumerate()
        .filter(|(_, c)| matches!(c, BuildNode::Inner { .. }))
        .max_by(|a, b| {
            a.1.bounds()
                .surface_area()
                .total_cmp(&b.1.bounds().surface_area())
        })
        .map(|(i, _)| i)
}

/// [`wide_children`], mutable: the same slots, in the same order.
fn wide_children_mut(node: &mut BuildNode) -> Vec<&mut BuildNode> {
    let BuildNode::Inner { children, .. } = node else {
        return vec![node];
    };
    let [a, b] = &mut **children;
    let mut slots: Vec<&mut BuildNode> = vec![a, b];
    while slots.len() < WIDTH {
        let Some(i) = widest_inner(slots.iter().map(|s| &**s)) else {
            break;
        };
        let BuildNode::Inner { children, .. } = slots.swap_remove(i) else {
            unreachable!("only inner nodes are opened")
        };
        let [a, b] = &mut **children;
        slots.push(a);
        slots.push(b);
    }
    slots
}

/// Fills the already allocated wide node `index` for binary inner node `node`, then its
/// subtree.
fn fill(
    node: &BuildNode,
    index: usize,
    nodes: &mut Vec<WideNode>,
    leaf_ref: &mut impl FnMut(u32, u32) -> u32,
) {
    let slots = wide_children(node);
    let mut inner = Vec::with_capacity(WIDTH);
    for (k, child) in slots.iter().enumerate() {
        let r = match child {
            BuildNode::Leaf { start, count, .. } => leaf_ref(*start, *count),
            BuildNode::Inner { .. } => {
                nodes.push(WideNode::empty());
                inner.push((nodes.len() - 1, *child));
                (nodes.len() - 1) as u32
            }
        };
        nodes[index].set_child(k, child.bounds(), r);
    }
    for (i, child) in inner {
        fill(child, i, nodes, leaf_ref);
    }
}
