//! Bottom-up construction of small subtrees that span much of the scene, and the ray
//! model that chooses between them and the top-down ones.
//!
//! Top-down centroid splits separate primitives by where their centres lie, so the two
//! triangles of a large quad (centres a third of the quad apart) often land on opposite
//! sides of a split, each then sharing a leaf with triangles of another wall: the leaf's
//! box spans the room, and every ray that starts in the room enters it. Agglomerative
//! clustering (Walter et al., "Fast Agglomerative Clustering for Rendering", IEEE RT
//! 2008) repeatedly merges the two clusters whose union weighs least; merging by
//! smallest union pairs each triangle with its partner (their union is the flat quad),
//! and each quad's leaf stays a thin slab, entered only by rays that cross it. The tree
//! is then cut into leaves where the model says a leaf is cheaper than its subtree (the
//! full recursive cost, not the greedy one-level estimate).
//!
//! The surface area heuristic models rays from outside the scene, under which a box
//! spanning the room costs no more than its area says and the top-down tree wins; the
//! [`RayModel`] also counts the rays that start inside a box.

use super::build::{BuildNode, BuildSettings, PrimRef};
use super::node::WIDTH;
use crate::geometry::Aabb;
use glam::Vec3;

/// Ranges of at most this many primitives are clustered. The search for the closest pair
/// is quadratic in the clusters per merge (with each cluster's nearest partner cached),
/// so this bounds the work per range; above it, binned top-down splits are as good.
pub(crate) const CLUSTER_MAX: usize = 32;

/// How likely rays are to enter a box: the surface area heuristic's model of rays from
/// outside the scene, extended to rays that start inside it (after Fabianowski, Fowler &
/// Dingliana, "A Cost Metric for Scene-Interior Ray Origins", EG 2009 short papers).
///
/// With ray origins uniform in the scene's box S and directions uniform, a box B is
/// entered by the rays that start in it (probability Vol(B) / Vol(S)) and by those whose
/// origin lies in the volume B sweeps backwards along their direction: B's projected
/// area, A(B) / 4 on average over directions (Cauchy), times the length of the sweep,
/// taken as the mean chord ℓ = 4 Vol(S) / A(S) of the scene. So P(B) ∝ A(B) + (4 / ℓ)
/// Vol(B). For boxes small against the scene the volume term vanishes and this is the
/// surface area heuristic; a box that spans a room costs more than its area says.
///
/// It is a cost for choosing between trees, not an accurate probability: the sweep
/// length of a box near the scene's boundary is shorter than ℓ, and a path tracer's
/// origins lie on surfaces, not throughout the volume. A model with origins on the
/// surfaces (a box charged for the surfaces it holds unless it is flat with them) chose
/// the slower tree on the Cornell box (docs/speed.md).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayModel {
    /// 4 / ℓ = A(S) / Vol(S); zero for a flat scene, which has no inside.
    volume_weight: f32,
}

impl RayModel {
    pub fn inside(scene: &Aabb) -> RayModel {
        let volume = volume(scene);
        let w = scene.surface_area() / volume;
        RayModel {
            volume_weight: if volume > 0.0 && w.is_finite() {
                w
            } else {
                0.0
            },
        }
    }

    /// Whether the volume term is at least a tenth of the area term for `b`. Only for such
    /// boxes does this model differ from the surface area heuristic; below that the
    /// top-down binned build stands (a bottom-up build of every small range made a
    /// million-triangle mesh's closest hits 4–9 % slower).
    pub fn is_interior_scale(&self, b: &Aabb) -> bool {
        10.0 * self.volume_weight * volume(b) >= b.surface_area()
    }

    /// A(B) + (4 / ℓ) Vol(B): proportional to the probability that a ray enters `b`.
    #[inline]
    pub fn weight(&self, b: &Aabb) -> f32 {
        b.surface_area() + self.volume_weight * volume(b)
    }
}

/// The volume of a box (zero for an empty or flat one).
fn volume(b: &Aabb) -> f32 {
    let d = (b.max - b.min).max(Vec3::ZERO);
    d.x * d.y * d.z
}

/// The build's settings with the ray model that weighs boxes in the choice between a
/// range's top-down and bottom-up subtrees.
pub(crate) struct Costs<'a> {
    pub settings: &'a BuildSettings,
    pub rays: RayModel,
    /// Each primitive's kind by its index (empty: all of one kind); no leaf mixes kinds
    /// (see `build_binary`).
    pub kinds: &'a [u8],
}

impl Costs<'_> {
    /// The kind of a primitive.
    #[inline]
    pub fn kind(&self, r: &PrimRef) -> u8 {
        self.kinds.get(r.id as usize).copied().unwrap_or(0)
    }

    /// The kind shared by all of `refs` (not empty), `None` when they mix kinds.
    pub fn kind_of_all(&self, refs: &[PrimRef]) -> Option<u8> {
        let first = self.kind(&refs[0]);
        refs.iter().all(|r| self.kind(r) == first).then_some(first)
    }

    /// The expected cost of a binary tree, unnormalised: the sum of its nodes' costs.
    pub fn tree_cost(&self, node: &BuildNode) -> f32 {
        match node {
            BuildNode::Leaf { bounds, count, .. } => self.leaf(bounds, *count),
            BuildNode::Inner { bounds, children } => {
                self.inner(bounds) + self.tree_cost(&children[0]) + self.tree_cost(&children[1])
            }
        }
    }

    /// A leaf's cost: its weight times the leaf kernel's tests (a block of four triangles
    /// and a pair of blocks both take one 8-lane test).
    pub fn leaf(&self, bounds: &Aabb, count: u32) -> f32 {
        self.rays.weight(bounds) * count.div_ceil(self.settings.leaf_test) as f32
    }

    /// An inner node's own cost: its weight times its share of a wide node's visit. The
    /// binary tree is collapsed into nodes of `WIDTH` children, each of which absorbs up
    /// to `WIDTH − 1` binary nodes, so a binary node charged a whole visit would make
    /// splits look costlier than they are: in a room, every grouping of two walls spans
    /// the room, and the cut then kept the walls together in one room-spanning leaf
    /// (entered by every ray) rather than as flat leaves of one wide node.
    fn inner(&self, bounds: &Aabb) -> f32 {
        self.settings.cost_traversal * self.rays.weight(bounds) / (WIDTH - 1) as f32
    }
}

/// A cluster during the merge: its box, its node in the merge tree and the kind its
/// primitives share (`None` when they mix kinds).
#[derive(Clone, Copy)]
struct Cluster {
    bounds: Aabb,
    node: u32,
    kind: Option<u8>,
}

/// What merging two clusters costs, compared in this order: whether it mixes kinds, how
/// much the union outweighs the heavier of the two, and the union's weight.
///
/// Clusters of one kind are merged before any two of different kinds, so that each kind
/// forms subtrees of its own, united only near the top. Shadow rays end on the emitters;
/// a box that unites an emitter with other geometry spans the space in front of the
/// emitter, which nearly every shadow ray crosses, while the emitter's own flat box is
/// entered by none of them.
///
/// The growth comes before the union's weight so that what lies within a cluster's box
/// joins it first: the faces of a block join the block before a face of the block next
/// to it, whose union with them would span both. Merging by the union's weight alone
/// (Walter et al.) joined the last faces of the Cornell box's two blocks to each other.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MergeCost {
    mixes_kinds: bool,
    growth: f32,
    weight: f32,
}

impl MergeCost {
    const NONE: MergeCost = MergeCost {
        mixes_kinds: true,
        growth: f32::INFINITY,
        weight: f32::INFINITY,
    };

    fn of(a: &Cluster, b: &Cluster, c: &Costs) -> MergeCost {
        let weight = c.rays.weight(&a.bounds.union(&b.bounds));
        let heavier = c.rays.weight(&a.bounds).max(c.rays.weight(&b.bounds));
        MergeCost {
            mixes_kinds: a.kind.is_none() || a.kind != b.kind,
            growth: (weight - heavier).max(0.0),
            weight,
        }
    }

    fn cmp(&self, other: &MergeCost) -> std::cmp::Ordering {
        (self.mixes_kinds.cmp(&other.mixes_kinds))
            .then(self.growth.total_cmp(&other.growth))
            .then(self.weight.total_cmp(&other.weight))
    }

    fn less(&self, other: &MergeCost) -> bool {
        self.cmp(other).is_lt()
    }
}

/// A merge-tree node: a primitive (an index into the range, and its kind) or two earlier
/// nodes.
#[derive(Clone, Copy)]
enum Merge {
    Prim(u32, Aabb, u8),
    Pair(u32, u32, Aabb),
}

/// Builds the subtree of `refs` (at most [`CLUSTER_MAX`], at least one) bottom-up,
/// reordering `refs` so that every subtree covers a contiguous range starting at `offset`.
/// Returns the subtree and its cost (as [`Costs::tree_cost`]).
pub(crate) fn cluster_range(refs: &mut [PrimRef], offset: u32, c: &Costs) -> (BuildNode, f32) {
    let n = refs.len();
    let boxes = refs.iter().map(|r| Aabb {
        min: r.min,
        max: r.max,
    });
    let mut tree: Vec<Merge> = boxes
        .clone()
        .zip(refs.iter())
        .enumerate()
        .map(|(i, (b, r))| Merge::Prim(i as u32, b, c.kind(r)))
        .collect();
    let mut live: Vec<Cluster> = boxes
        .zip(refs.iter())
        .enumerate()
        .map(|(i, (bounds, r))| Cluster {
            bounds,
            node: i as u32,
            kind: Some(c.kind(r)),
        })
        .collect();
    // Each cluster's cheapest partner (index into `live`) and what merging them costs.
    let nearest = |live: &[Cluster], i: usize| -> (usize, MergeCost) {
        let mut best = (usize::MAX, MergeCost::NONE);
        for (j, other) in live.iter().enumerate() {
            if j != i {
                let m = MergeCost::of(&live[i], other, c);
                if m.less(&best.1) {
                    best = (j, m);
                }
            }
        }
        best
    };
    let mut partner: Vec<(usize, MergeCost)> = (0..live.len()).map(|i| nearest(&live, i)).collect();
    while live.len() > 1 {
        // The globally cheapest pair; ties go to the lowest index, so the tree is a pure
        // function of the input order.
        let (i, &(j, _)) = partner
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.1.cmp(&b.1.1).then(a.0.cmp(&b.0)))
            .expect("at least two clusters");
        let bounds = live[i].bounds.union(&live[j].bounds);
        tree.push(Merge::Pair(live[i].node, live[j].node, bounds));
        let merged = Cluster {
            bounds,
            node: (tree.len() - 1) as u32,
            kind: if live[i].kind == live[j].kind {
                live[i].kind
            } else {
                None
            },
        };
        let (lo, hi) = (i.min(j), i.max(j));
        live[lo] = merged;
        live.swap_remove(hi);
        partner.swap_remove(hi);
        // Partners that pointed at a removed cluster, or at the moved last one, and the
        // merged cluster itself, are searched again.
        let moved_from = live.len();
        for k in 0..live.len() {
            let p = partner[k].0;
            if k == lo || p == lo || p == hi || p == moved_from {
                partner[k] = nearest(&live, k);
            } else {
                let m = MergeCost::of(&live[k], &merged, c);
                if m.less(&partner[k].1) {
                    partner[k] = (lo, m);
                }
            }
        }
    }
    let root = live[0].node;
    // Depth-first order of the primitives: every subtree becomes a contiguous range.
    let mut order = Vec::with_capacity(n);
    let mut stack = vec![root];
    while let Some(t) = stack.pop() {
        match tree[t as usize] {
            Merge::Prim(p, ..) => order.push(p),
            Merge::Pair(a, b, _) => {
                stack.push(b);
                stack.push(a);
            }
        }
    }
    let original: Vec<PrimRef> = refs.to_vec();
    for (slot, &p) in refs.iter_mut().zip(&order) {
        *slot = original[p as usize];
    }
    let mut next = offset;
    let (node, cost, _, _) = cut(&tree, root, &mut next, c);
    (node, cost)
}

/// The subtree of merge node `t` with its leaves chosen by the ray model, its cost (in
/// block intersections, unnormalised: weight times expected work), its primitive count
/// and the kind its primitives share (`None` when mixed: it is then never a leaf).
/// Assigns ranges in the depth-first order `cluster_range` laid the primitives out in.
fn cut(tree: &[Merge], t: u32, next: &mut u32, c: &Costs) -> (BuildNode, f32, u32, Option<u8>) {
    match tree[t as usize] {
        Merge::Prim(_, bounds, kind) => {
            let start = *next;
            *next += 1;
            let cost = c.leaf(&bounds, 1);
            (
                BuildNode::Leaf {
                    bounds,
                    start,
                    count: 1,
                },
                cost,
                1,
                Some(kind),
            )
        }
        Merge::Pair(a, b, bounds) => {
            let start = *next;
            let (l, lc, ln, lk) = cut(tree, a, next, c);
            let (r, rc, rn, rk) = cut(tree, b, next, c);
            let count = ln + rn;
            let kind = if lk == rk { lk } else { None };
            let split_cost = c.inner(&bounds) + lc + rc;
            let leaf_cost = c.leaf(&bounds, count);
            if count <= c.settings.max_cluster_leaf && leaf_cost <= split_cost && kind.is_some() {
                (
                    BuildNode::Leaf {
                        bounds,
                        start,
                        count,
                    },
                    leaf_cost,
                    count,
                    kind,
                )
            } else {
                (
                    BuildNode::Inner {
                        bounds,
                        children: Box::new([l, r]),
                    },
                    split_cost,
                    count,
                    kind,
                )
            }
        }
    }
}
