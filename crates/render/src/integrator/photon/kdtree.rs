//! A balanced kd-tree stored flat, without pointers: the items themselves are the
//! nodes. The node of the index range `[lo, hi)` is the median at `lo + (hi - lo) / 2`;
//! its left subtree is `[lo, mid)`, its right subtree `(mid, hi)`. This is the implicit
//! layout equivalent to Jensen's left-balanced heap ("Global Illumination using Photon
//! Maps", EGWR 1996; *Realistic Image Synthesis Using Photon Mapping*, 2001, §6.3): a
//! balanced tree with one split axis byte per node and no child pointers. Ranges are
//! disjoint, so the build recurses in parallel and gives the same tree at any thread
//! count (the median selection is deterministic).
//!
//! Ranges of at most 8 items are leaves, scanned in order rather than split further
//! (contiguous, so cheaper than descending to single items).
//!
//! Queries: the `k` nearest items within a maximum distance (a bounded max-heap,
//! Jensen's `locate_photons`), and every item within a fixed radius. Both walk the tree
//! with an explicit stack, near side first, pruning subtrees whose splitting plane lies
//! beyond the current search radius.

use glam::Vec3;

use rayon::prelude::*;

use crate::geometry::Aabb;

/// Items a [`KdTree`] can hold.
pub trait KdPoint {
    fn position(&self) -> Vec3;
}

/// Ranges smaller than this are built on the current thread.
const PARALLEL_BUILD: usize = 16 * 1024;
/// Nodes at least this large ask whether to stop before partitioning.
const POLL_BUILD: usize = 4 * 1024;
/// Ranges at least this large find their median by [`select_nth_polled`], which asks
/// whether to stop while it partitions: one `select_nth_unstable` over 10^8 photons
/// takes over a second, too long to wait for a cancelled render.
const POLL_SELECT: usize = 1 << 22;
/// Items partitioned between two questions to `stop` inside one selection.
const POLL_STRIDE: usize = 1 << 16;

/// Ranges this small are leaves: scanned in order, not split (contiguous in memory,
/// cheaper than descending to single items).
const LEAF: u32 = 8;

/// Deep enough for 2^60 items (each level adds at most one pending entry).
const STACK: usize = 64;

/// A kd-tree over items with positions.
#[derive(Clone, Debug)]
pub struct KdTree<T> {
    items: Vec<T>,
    /// Split axis (0, 1, 2) of the node at the same index.
    axes: Vec<u8>,
}

impl<T> Default for KdTree<T> {
    fn default() -> Self {
        KdTree {
            items: Vec::new(),
            axes: Vec::new(),
        }
    }
}

/// The result buffer of a k-nearest query: a max-heap on squared distance, reused
/// between queries so that lookups do not allocate.
#[derive(Clone, Debug)]
pub struct Neighbors {
    k: usize,
    /// (squared distance, item index); `heap[0]` is the farthest.
    heap: Vec<(f32, u32)>,
}

impl Neighbors {
    /// A buffer for the `k` nearest items (at least 1).
    pub fn new(k: usize) -> Neighbors {
        Neighbors {
            k: k.max(1),
            heap: Vec::with_capacity(k.max(1)),
        }
    }

    /// Changes the number of neighbours to find.
    pub fn set_k(&mut self, k: usize) {
        self.k = k.max(1);
        self.heap.clear();
        self.heap.reserve(self.k);
    }

    /// The number of neighbours asked for.
    pub fn k(&self) -> usize {
        self.k
    }

    /// Number of items found.
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// True when nothing was found.
    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }

    /// True when `k` items were found (the radius is then set by the farthest).
    pub fn is_full(&self) -> bool {
        self.heap.len() == self.k
    }

    /// Squared distance of the farthest item found (0 when none).
    pub fn max_d2(&self) -> f32 {
        if self.is_full() {
            self.heap[0].0
        } else {
            self.heap.iter().fold(0.0, |m, e| m.max(e.0))
        }
    }

    /// Index of the farthest item found.
    pub fn farthest(&self) -> Option<u32> {
        if self.is_full() {
            return Some(self.heap[0].1);
        }
        self.heap
            .iter()
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|e| e.1)
    }

    /// (item index, squared distance) of every item found, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = (u32, f32)> + '_ {
        self.heap.iter().map(|&(d2, i)| (i, d2))
    }

    fn clear(&mut self) {
        self.heap.clear();
    }

    /// Adds a candidate closer than the current bound; returns the new bound (the
    /// farthest distance once `k` are held, else `bound`). Candidates are collected
    /// unordered until the buffer is full and only then arranged as a max-heap
    /// (Jensen 2001, §6.3: heap construction is deferred until needed).
    fn offer(&mut self, d2: f32, index: u32, bound: f32) -> f32 {
        let k = self.k;
        let h = &mut self.heap;
        if h.len() < k {
            h.push((d2, index));
            if h.len() < k {
                return bound;
            }
            for i in (0..k / 2).rev() {
                sift_down(h, i);
            }
        } else {
            h[0] = (d2, index);
            sift_down(h, 0);
        }
        h[0].0
    }
}

/// Restores the max-heap property below `i`.
fn sift_down(h: &mut [(f32, u32)], mut i: usize) {
    let n = h.len();
    loop {
        let l = 2 * i + 1;
        let r = l + 1;
        let mut largest = i;
        if l < n && h[l].0 > h[largest].0 {
            largest = l;
        }
        if r < n && h[r].0 > h[largest].0 {
            largest = r;
        }
        if largest == i {
            return;
        }
        h.swap(i, largest);
        i = largest;
    }
}

impl<T: KdPoint + Send + Sync + 'static> KdTree<T> {
    /// Builds the tree (reorders the items).
    pub fn build(items: Vec<T>) -> KdTree<T> {
        KdTree::build_until(items, &|| false).expect("never stopped")
    }

    /// [`KdTree::build`], giving up (`None`) once `stop` holds. `stop` is asked at every
    /// node of at least [`POLL_BUILD`] items and every [`POLL_STRIDE`] items inside the
    /// selections of large nodes, so a stop takes effect within milliseconds.
    pub fn build_until(mut items: Vec<T>, stop: &(dyn Fn() -> bool + Sync)) -> Option<KdTree<T>> {
        // Min and max are exact, so the parallel reduction gives the same box in any order.
        let bounds = items
            .par_chunks(POLL_STRIDE)
            .map(|chunk| {
                if stop() {
                    return Aabb::EMPTY;
                }
                chunk
                    .iter()
                    .fold(Aabb::EMPTY, |b, it| b.grow(it.position()))
            })
            .reduce(|| Aabb::EMPTY, |a, b| a.union(&b));
        let mut axes = vec![0u8; items.len()];
        build_range(&mut items, &mut axes, bounds, stop);
        let tree = KdTree { items, axes };
        if stop() {
            tree.discard();
            return None;
        }
        Some(tree)
    }

    /// Drops the tree without waiting for a large one's memory to be returned (see
    /// [`release`]).
    pub fn discard(self) {
        release(self.items);
        release(self.axes);
    }
}

fn build_range<T: KdPoint + Send>(
    items: &mut [T],
    axes: &mut [u8],
    bounds: Aabb,
    stop: &(dyn Fn() -> bool + Sync),
) {
    let n = items.len();
    if n <= LEAF as usize || (n >= POLL_BUILD && stop()) {
        return;
    }
    let d = bounds.diagonal();
    let axis = if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    };
    let mid = n / 2;
    if n >= POLL_SELECT {
        if !select_nth_polled(items, mid, axis, stop) {
            return;
        }
    } else {
        items.select_nth_unstable_by(mid, |a, b| {
            a.position()[axis].total_cmp(&b.position()[axis])
        });
    }
    axes[mid] = axis as u8;
    // Children's bounds: the parent's, clipped at the splitting plane (looser than the
    // exact bounds but free, and the axis choice only affects speed).
    let split = items[mid].position()[axis];
    let (mut left_b, mut right_b) = (bounds, bounds);
    left_b.max[axis] = split;
    right_b.min[axis] = split;
    let (left, rest) = items.split_at_mut(mid);
    let right = &mut rest[1..];
    let (left_axes, rest_axes) = axes.split_at_mut(mid);
    let right_axes = &mut rest_axes[1..];
    if n >= PARALLEL_BUILD {
        rayon::join(
            || build_range(left, left_axes, left_b, stop),
            || build_range(right, right_axes, right_b, stop),
        );
    } else {
        build_range(left, left_axes, left_b, stop);
        build_range(right, right_axes, right_b, stop);
    }
}

/// Drops a buffer given up on a stop. Returning gigabytes of pages to the system
/// takes a good part of a second; a large buffer is freed on a thread of its own so
/// that the stopping caller does not wait for it.
pub fn release<T: Send + 'static>(buffer: Vec<T>) {
    let bytes = buffer.len() * std::mem::size_of::<T>();
    release_sized(buffer, bytes);
}

/// [`release`] for any owner of `bytes` of heap memory.
pub fn release_sized<B: Send + 'static>(owner: B, bytes: usize) {
    if bytes >= 64 << 20 {
        std::thread::spawn(move || drop(owner));
    }
}

/// Reorders `items` as `select_nth_unstable` does — `items[k]` is the k-th smallest
/// along `axis`, none before it larger and none after it smaller — by quickselect
/// (Hoare 1961) with three-way partitions (Dijkstra's Dutch flag, so that runs of equal
/// coordinates, such as photons on an axis-aligned wall, end the search at once) around
/// the median of nine evenly spaced items. Deterministic. Asks `stop` every
/// [`POLL_STRIDE`] items and returns false, leaving the order unfinished, once it holds.
/// Once the range is small, or when pivots keep failing to shrink it, the standard
/// library's selection (linear in the worst case) finishes the work.
fn select_nth_polled<T: KdPoint>(
    items: &mut [T],
    k: usize,
    axis: usize,
    stop: &(dyn Fn() -> bool + Sync),
) -> bool {
    let key = |it: &T| it.position()[axis];
    let (mut lo, mut hi) = (0, items.len());
    let mut poor_rounds = 0;
    while hi - lo >= POLL_SELECT && poor_rounds < 4 {
        let range = &mut items[lo..hi];
        let n = range.len();
        let mut sample: [f32; 9] = std::array::from_fn(|i| key(&range[(2 * i + 1) * n / 18]));
        sample.sort_unstable_by(f32::total_cmp);
        let pivot = sample[4];
        let (mut lt, mut i, mut gt) = (0, 0, n);
        let mut since_poll = 0;
        while i < gt {
            match key(&range[i]).total_cmp(&pivot) {
                std::cmp::Ordering::Less => {
                    range.swap(lt, i);
                    lt += 1;
                    i += 1;
                }
                std::cmp::Ordering::Greater => {
                    gt -= 1;
                    range.swap(i, gt);
                }
                std::cmp::Ordering::Equal => i += 1,
            }
            since_poll += 1;
            if since_poll == POLL_STRIDE {
                since_poll = 0;
                if stop() {
                    return false;
                }
            }
        }
        let k_in = k - lo;
        let kept = if k_in < lt {
            hi = lo + lt;
            lt
        } else if k_in >= gt {
            lo += gt;
            n - gt
        } else {
            return true;
        };
        if kept > n - n / 8 {
            poor_rounds += 1;
        }
    }
    if stop() {
        return false;
    }
    items[lo..hi].select_nth_unstable_by(k - lo, |a, b| key(a).total_cmp(&key(b)));
    true
}

impl<T: KdPoint> KdTree<T> {
    /// Number of items in the tree.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True for a tree without items.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The items in tree order (index `i` is what queries report).
    pub fn items(&self) -> &[T] {
        &self.items
    }

    /// The item at a tree index reported by a query.
    pub fn get(&self, index: u32) -> &T {
        &self.items[index as usize]
    }

    /// Finds the `out.k()` items nearest to `p` with squared distance below `max_d2`.
    pub fn nearest(&self, p: Vec3, max_d2: f32, out: &mut Neighbors) {
        self.nearest_where(p, max_d2, out, |_| true);
    }

    /// Like [`KdTree::nearest`], counting only items for which `accept` is true (the
    /// search radius then adapts to the accepted items alone).
    pub fn nearest_where(
        &self,
        p: Vec3,
        max_d2: f32,
        out: &mut Neighbors,
        accept: impl Fn(&T) -> bool,
    ) {
        out.clear();
        let mut bound = max_d2;
        // (lo, hi, squared distance from p to the range's region, lower bound).
        let mut stack = [(0u32, 0u32, 0f32); STACK];
        let mut top = 0usize;
        stack[0] = (0, self.items.len() as u32, 0.0);
        top += 1;
        while top > 0 {
            top -= 1;
            let (lo, hi, region_d2) = stack[top];
            if lo >= hi || region_d2 >= bound {
                continue;
            }
            if hi - lo <= LEAF {
                for i in lo..hi {
                    let item = &self.items[i as usize];
                    let d2 = (item.position() - p).length_squared();
                    if d2 < bound && accept(item) {
                        bound = out.offer(d2, i, bound);
                    }
                }
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            let item = &self.items[mid as usize];
            let q = item.position();
            let d2 = (q - p).length_squared();
            if d2 < bound && accept(item) {
                bound = out.offer(d2, mid, bound);
            }
            let axis = self.axes[mid as usize] as usize;
            let delta = p[axis] - q[axis];
            let (near, far) = if delta < 0.0 {
                ((lo, mid), (mid + 1, hi))
            } else {
                ((mid + 1, hi), (lo, mid))
            };
            stack[top] = (far.0, far.1, region_d2.max(delta * delta));
            stack[top + 1] = (near.0, near.1, region_d2);
            top += 2;
        }
    }

    /// Calls `visit(index, item, squared distance)` for every item with squared distance
    /// below `r2`, in tree order of discovery.
    pub fn within(&self, p: Vec3, r2: f32, mut visit: impl FnMut(u32, &T, f32)) {
        let mut stack = [(0u32, 0u32); STACK];
        let mut top = 1usize;
        stack[0] = (0, self.items.len() as u32);
        while top > 0 {
            top -= 1;
            let (lo, hi) = stack[top];
            if lo >= hi {
                continue;
            }
            if hi - lo <= LEAF {
                for i in lo..hi {
                    let item = &self.items[i as usize];
                    let d2 = (item.position() - p).length_squared();
                    if d2 < r2 {
                        visit(i, item, d2);
                    }
                }
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            let item = &self.items[mid as usize];
            let q = item.position();
            let d2 = (q - p).length_squared();
            if d2 < r2 {
                visit(mid, item, d2);
            }
            let axis = self.axes[mid as usize] as usize;
            let delta = p[axis] - q[axis];
            // Points on the plane belong to either side: visit both when it is close.
            if delta < 0.0 || delta * delta < r2 {
                stack[top] = (lo, mid);
                top += 1;
            }
            if delta >= 0.0 || delta * delta < r2 {
                stack[top] = (mid + 1, hi);
                top += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[derive(Clone, Copy, Debug, PartialEq)]
    struct Pt {
        p: Vec3,
        id: u32,
    }

    impl KdPoint for Pt {
        fn position(&self) -> Vec3 {
            self.p
        }
    }

    fn points(raw: &[(f32, f32, f32)]) -> Vec<Pt> {
        raw.iter()
            .enumerate()
            .map(|(i, &(x, y, z))| Pt {
                p: Vec3::new(x, y, z),
                id: i as u32,
            })
            .collect()
    }

    /// Coordinates snapped to a coarse grid half of the time, so that ties and
    /// duplicates (many photons on one plane) are exercised.
    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![(-100.0f32..100.0), (-8i32..8).prop_map(|i| i as f32 * 2.5)]
    }

    fn cloud() -> impl Strategy<Value = Vec<(f32, f32, f32)>> {
        prop::collection::vec((coord(), coord(), coord()), 0..600)
    }

    fn sorted(mut v: Vec<f32>) -> Vec<f32> {
        v.sort_by(f32::total_cmp);
        v
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        #[test]
        fn nearest_equals_brute_force(
            raw in cloud(),
            q in (coord(), coord(), coord()),
            k in 1usize..40,
            max_r in 0.5f32..300.0,
        ) {
            let pts = points(&raw);
            let tree = KdTree::build(pts.clone());
            let q = Vec3::new(q.0, q.1, q.2);
            let max_d2 = max_r * max_r;
            let mut out = Neighbors::new(k);
            tree.nearest(q, max_d2, &mut out);
            let brute: Vec<f32> = sorted(pts.iter().map(|p| (p.p - q).length_squared()).filter(|&d| d < max_d2).collect());
            let expect: Vec<f32> = brute.into_iter().take(k).collect();
            let got = sorted(out.iter().map(|(i, d2)| {
                assert_eq!((tree.get(i).p - q).length_squared(), d2);
                d2
            }).collect());
            prop_assert_eq!(got, expect);
        }

        #[test]
        fn within_equals_brute_force(
            raw in cloud(),
            q in (coord(), coord(), coord()),
            r in 0.0f32..150.0,
        ) {
            let pts = points(&raw);
            let tree = KdTree::build(pts.clone());
            let q = Vec3::new(q.0, q.1, q.2);
            let mut got = Vec::new();
            tree.within(q, r * r, |_, it, _| got.push(it.id));
            got.sort_unstable();
            let expect: Vec<u32> = pts.iter().filter(|p| (p.p - q).length_squared() < r * r).map(|p| p.id).collect();
            prop_assert_eq!(got, expect);
        }
    }

    /// kiddo as an independent oracle on a larger cloud (including clusters).
    #[test]
    fn nearest_agrees_with_kiddo() {
        use kiddo::{ImmutableKdTree, SquaredEuclidean};
        use std::num::NonZero;
        let mut rng = radiant_math::hash::Pcg32::new(11, 5);
        let mut raw = Vec::new();
        for i in 0..20_000 {
            let spread = if i % 3 == 0 { 1.0 } else { 100.0 };
            raw.push((
                rng.uniform() * spread,
                rng.uniform() * spread,
                rng.uniform() * spread * 0.1,
            ));
        }
        let pts = points(&raw);
        let entries: Vec<[f32; 3]> = pts.iter().map(|p| p.p.to_array()).collect();
        let oracle = ImmutableKdTree::new_from_slice(&entries).expect("kiddo builds");
        let tree = KdTree::build(pts);
        let mut out = Neighbors::new(50);
        for _ in 0..500 {
            let q = Vec3::new(
                rng.uniform() * 100.0,
                rng.uniform() * 100.0,
                rng.uniform() * 10.0,
            );
            tree.nearest(q, f32::INFINITY, &mut out);
            let got = sorted(out.iter().map(|(_, d2)| d2).collect());
            let expect: Vec<f32> = oracle
                .query(&q.to_array())
                .nearest_n::<SquaredEuclidean<f32>>(NonZero::new(50).unwrap())
                .execute()
                .iter()
                .map(|r| r.distance)
                .collect();
            assert_eq!(got.len(), expect.len());
            for (a, b) in got.iter().zip(&expect) {
                // kiddo may compute the distance with a different operation order.
                assert!((a - b).abs() <= 1e-4 * b.max(1.0), "{a} vs {b}");
            }
        }
    }

    #[test]
    fn build_is_independent_of_the_thread_count() {
        let mut rng = radiant_math::hash::Pcg32::new(2, 9);
        let raw: Vec<(f32, f32, f32)> = (0..100_000)
            .map(|_| (rng.uniform(), rng.uniform(), rng.uniform()))
            .collect();
        let build = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| KdTree::build(points(&raw)))
        };
        let (a, b) = (build(1), build(3));
        assert_eq!(a.items, b.items);
        assert_eq!(a.axes, b.axes);
    }

    /// The polled selection keeps `select_nth_unstable`'s contract on a range large
    /// enough to use it, with a third of the items on one plane (ties), and gives up
    /// when asked to stop.
    #[test]
    fn polled_selection_partitions_like_select_nth() {
        let mut rng = radiant_math::hash::Pcg32::new(5, 1);
        let n = POLL_SELECT + POLL_SELECT / 4;
        let raw: Vec<(f32, f32, f32)> = (0..n)
            .map(|i| {
                let x = if i % 3 == 0 { 0.25 } else { rng.uniform() };
                (x, rng.uniform(), 0.0)
            })
            .collect();
        for k in [0, n / 3, n / 2, n - 1] {
            let mut items = points(&raw);
            assert!(select_nth_polled(&mut items, k, 0, &|| false));
            let v = items[k].position().x;
            let mut keys: Vec<f32> = raw.iter().map(|p| p.0).collect();
            keys.sort_unstable_by(f32::total_cmp);
            assert_eq!(v, keys[k], "k = {k}");
            assert!(items[..k].iter().all(|p| p.position().x <= v));
            assert!(items[k + 1..].iter().all(|p| p.position().x >= v));
        }
        let mut items = points(&raw);
        assert!(!select_nth_polled(&mut items, n / 2, 0, &|| true));
    }
}
