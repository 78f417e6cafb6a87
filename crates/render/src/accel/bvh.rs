//! The generic BVH: any primitive behind a closure. This is the two-level entry point too:
//! a primitive may be an instance whose closure transforms the ray and traverses another
//! `Bvh` or `TriangleBvh` (see the instancing test below).

use super::build::{BuildSettings, build_binary, collapse};
use super::node::{NodeRay, decode_leaf, encode_leaf};
use super::traverse::{
    self, AnyLeaf, ClosestLeaf, LARGE_STACK, NodeTree, SMALL_STACK, StackSize, TINY_STACK,
};
use crate::geometry::{Aabb, Ray};

/// An 8-wide BVH over caller-owned primitives given by their bounding boxes.
///
/// Two-level instancing: the top level's primitives are instances, and the closure moves
/// the ray into the instance's space and traverses the shared object-level BVH. An affine
/// map keeps the ray parameter (the direction is transformed, not renormalised), so
/// `t_max` passes straight through.
///
/// ```
/// use radiant_math::{Transform, Vec3};
/// use radiant_render::accel::{Bvh, TriangleBvh};
/// use radiant_render::geometry::{Aabb, Ray};
///
/// let mesh = TriangleBvh::from_soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
/// let instances = [
///     Transform::translate(Vec3::new(0.0, 0.0, 9.0)),
///     Transform::translate(Vec3::new(0.0, 0.0, 5.0)),
/// ];
/// // (Transforming two corners is enough for translations; in general use all eight.)
/// let bounds: Vec<Aabb> = instances
///     .iter()
///     .map(|x| Aabb::new(x.point(mesh.bounds().min), x.point(mesh.bounds().max)))
///     .collect();
/// let scene = Bvh::build(&bounds);
///
/// let ray = Ray::new(Vec3::new(0.2, 0.2, 0.0), Vec3::Z);
/// let mut hit = None;
/// let t = scene.closest_hit(&ray, f32::INFINITY, |i, t_max| {
///     let to_object = instances[i as usize].inverse();
///     let local = Ray::new(to_object.point(ray.o), to_object.vector(ray.d));
///     let h = mesh.intersect(&local, t_max)?;
///     hit = Some((i, h.prim, h.b));
///     Some(h.t)
/// });
/// assert!((t.unwrap() - 5.0).abs() < 1e-5);
/// assert_eq!(hit.map(|h| h.0), Some(1));
/// ```
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: NodeTree,
    order: Vec<u32>,
    bounds: Aabb,
}

/// Leaves of up to 4 primitives; a node visit costs about as much as one intersection
/// of a generic primitive (instances and analytic shapes cost more, which favours small leaves).
const SETTINGS: BuildSettings = BuildSettings {
    leaf_block: 1,
    max_leaf: 4,
    leaf_test: 1,
    max_cluster_leaf: 4,
    cost_traversal: 1.0,
};

impl Bvh {
    /// Binned SAH build (Wald 2007), parallel with rayon for large inputs, collapsed to an
    /// 8-wide node array. Primitives whose box is empty or not
    /// finite can never be hit and are left out.
    pub fn build(prim_bounds: &[Aabb]) -> Bvh {
        let (root, order) = build_binary(prim_bounds, &[], &SETTINGS);
        let Some(root) = root else {
            return Bvh::default();
        };
        let nodes = NodeTree::new(collapse(&root, &mut encode_leaf));
        let bounds = order
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(&prim_bounds[i as usize]));
        Bvh {
            nodes,
            order,
            bounds,
        }
    }

    /// Closest hit in (0, t_max): calls `intersect_prim(prim_index, t_max)` for candidate
    /// primitives, nearest subtrees first; the closure returns `Some(t)` for a hit closer
    /// than the `t_max` it was given (and records whatever it needs), and the traversal
    /// shrinks `t_max` to it. Returns the closest `t`.
    #[inline]
    pub fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        intersect_prim: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<f32> {
        match self.nodes.stack() {
            StackSize::Tiny => self.closest_with::<TINY_STACK>(ray, t_max, intersect_prim),
            StackSize::Small => self.closest_with::<SMALL_STACK>(ray, t_max, intersect_prim),
            StackSize::Large => self.closest_with::<LARGE_STACK>(ray, t_max, intersect_prim),
        }
    }

    #[inline(always)]
    fn closest_with<const STACK: usize>(
        &self,
        ray: &Ray,
        t_max: f32,
        intersect_prim: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<f32> {
        let mut leaves = ClosestPrims {
            order: &self.order,
            intersect_prim,
            found: false,
        };
        let t =
            traverse::closest::<STACK>(self.nodes.nodes(), &NodeRay::new(ray), t_max, &mut leaves);
        let found = leaves.found;
        found.then_some(t)
    }

    /// Any hit in (0, t_max): stops at the first primitive for which
    /// `occludes(prim_index, t_max)` returns true.
    #[inline]
    pub fn any_hit(&self, ray: &Ray, t_max: f32, occludes: impl FnMut(u32, f32) -> bool) -> bool {
        match self.nodes.stack() {
            StackSize::Tiny => self.any_with::<TINY_STACK>(ray, t_max, occludes),
            StackSize::Small => self.any_with::<SMALL_STACK>(ray, t_max, occludes),
            StackSize::Large => self.any_with::<LARGE_STACK>(ray, t_max, occludes),
        }
    }

    #[inline(always)]
    fn any_with<const STACK: usize>(
        &self,
        ray: &Ray,
        t_max: f32,
        occludes: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        let mut leaves = AnyPrim {
            order: &self.order,
            occludes,
        };
        traverse::any::<STACK>(self.nodes.nodes(), &NodeRay::new(ray), t_max, &mut leaves)
    }

    /// The primitive indices in leaf order: `prim_order()[k]` is the primitive in the k-th
    /// leaf slot. A caller may permute its arrays into this order for locality and then
    /// call [`Bvh::renumber_in_leaf_order`].
    pub fn prim_order(&self) -> &[u32] {
        &self.order
    }

    /// After the caller has permuted its primitive arrays by `prim_order()` (new index k
    /// holds old primitive `prim_order()[k]`), makes the closures receive the new indices.
    pub fn renumber_in_leaf_order(&mut self) {
        for (k, p) in self.order.iter_mut().enumerate() {
            *p = k as u32;
        }
    }

    /// Bounds of all primitives in the tree.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of wide nodes (for statistics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    #[cfg(test)]
    pub(crate) fn stack_size(&self) -> StackSize {
        self.nodes.stack()
    }

    /// A tree from hand-made nodes (tests of the traversal's limits).
    #[cfg(test)]
    pub(crate) fn from_parts(
        nodes: Vec<super::node::WideNode>,
        order: Vec<u32>,
        bounds: Aabb,
    ) -> Bvh {
        Bvh {
            nodes: NodeTree::new(nodes),
            order,
            bounds,
        }
    }
}

struct ClosestPrims<'a, F> {
    order: &'a [u32],
    intersect_prim: F,
    found: bool,
}

impl<F: FnMut(u32, f32) -> Option<f32>> ClosestLeaf for ClosestPrims<'_, F> {
    #[inline(always)]
    fn visit(&mut self, leaf: u32, mut t_max: f32) -> Option<f32> {
        let (start, count) = decode_leaf(leaf);
        let mut hit = false;
        for &prim in &self.order[start..start + count] {
            if let Some(t) = (self.intersect_prim)(prim, t_max).filter(|&t| t < t_max) {
                t_max = t;
                hit = true;
            }
        }
        self.found |= hit;
        hit.then_some(t_max)
    }
}

struct AnyPrim<'a, F> {
    order: &'a [u32],
    occludes: F,
}

impl<F: FnMut(u32, f32) -> bool> AnyLeaf for AnyPrim<'_, F> {
    #[inline(always)]
    fn visit(&mut self, leaf: u32, t_max: f32) -> bool {
        let (start, count) = decode_leaf(leaf);
        self.order[start..start + count]
            .iter()
            .any(|&prim| (self.occludes)(prim, t_max))
    }
}
