//! Flat primitive storage and the per-primitive intersection behind the BVH.

use glam::{Vec2, Vec3};

use super::{NO_LIGHT, SurfaceHit};
use crate::accel::{Bvh, TriangleBvh};
use crate::geometry::bilinear::BilinearPatch;
use crate::geometry::disk::Disk;
use crate::geometry::ray::{barycentric_error, transform_point_with_error};
use crate::geometry::sphere::Sphere;
use crate::geometry::{Aabb, Ray};
use radiant_math::Transform;
use radiant_scene::FloatParam;

/// Which array a primitive of the generic BVH lives in, and its index there.
/// Triangles have their own SIMD BVH and never appear here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PrimRef {
    Sphere(u32),
    Disk(u32),
    /// A curved bilinear patch (planar ones are stored as two triangles).
    Bilinear(u32),
    Instance(u32),
}

/// Per-triangle shading data.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriangleAttr {
    pub mesh: u32,
    /// Triangle number within its mesh (its indices are `3 * index ..`).
    pub index: u32,
    pub material: u32,
    pub light: u32,
    /// −1 when the geometric normal (p1−p0)×(p2−p0) must be flipped (pbrt's
    /// ReverseOrientation xor a handedness-swapping transform), +1 otherwise.
    pub orientation: f32,
}

/// Per-vertex attributes of a mesh, in render space.
#[derive(Clone, Debug, Default)]
pub(crate) struct MeshAttrs {
    pub indices: Vec<u32>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    /// The triangles are the halves (p00, p10, p11), (p00, p11, p01) of planar
    /// bilinear patches, in pairs: without `uvs` they take the patch's parameterisation
    /// (corners (0,0), (1,0), (0,1), (1,1), as pbrt-v4 gives a bilinear patch).
    pub bilinear_halves: bool,
    /// The shape's `alpha` cut-out, if any.
    pub alpha: Option<FloatParam>,
}

/// A quadric placed in render space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placed<S> {
    pub shape: S,
    pub render_from_object: Transform,
    pub material: u32,
    pub light: u32,
    /// ReverseOrientation: the front (emitting) side is the inside.
    pub reverse: bool,
    pub alpha: Option<FloatParam>,
}

/// A curved bilinear patch in render space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BilinearPrim {
    pub patch: BilinearPatch,
    pub material: u32,
    pub light: u32,
    /// −1 when the front is opposite ∂p/∂u × ∂p/∂v (ReverseOrientation xor a mirror).
    pub orientation: f32,
    pub alpha: Option<FloatParam>,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Instance {
    pub prototype: u32,
    pub render_from_instance: Transform,
}

/// A set of primitives with its BVHs: the scene's top level, or an instance prototype.
/// Triangles — nearly always the bulk — sit in a SIMD triangle BVH; spheres, disks and
/// instances in a generic one. A ray visits both, the second with the first's hit
/// distance as its limit.
#[derive(Default)]
pub struct ShapeSet {
    pub(crate) triangles: Vec<[Vec3; 3]>,
    pub(crate) triangle_attrs: Vec<TriangleAttr>,
    pub(crate) meshes: Vec<MeshAttrs>,
    pub(crate) spheres: Vec<Placed<Sphere>>,
    pub(crate) disks: Vec<Placed<Disk>>,
    pub(crate) bilinears: Vec<BilinearPrim>,
    pub(crate) instances: Vec<Instance>,
    pub(crate) triangle_bvh: TriangleBvh,
    /// Generic BVH primitive index → primitive.
    pub(crate) prims: Vec<PrimRef>,
    pub(crate) bvh: Bvh,
}

/// What the traversal remembers of the closest hit so far.
#[derive(Clone, Copy, Debug)]
enum RawHit {
    Triangle {
        index: u32,
        b: [f32; 3],
    },
    Quadric {
        prim: PrimRef,
        p_obj: Vec3,
        p_error: Vec3,
        n_obj: Vec3,
        uv: Vec2,
    },
}

impl ShapeSet {
    /// Number of primitives: triangles, quadrics and instances.
    pub fn len(&self) -> usize {
        self.triangles.len() + self.prims.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Builds both BVHs; prototypes must be finished before the sets that instance them.
    pub(crate) fn finish(&mut self, prototypes: &[ShapeSet]) {
        let emitting: Vec<bool> = self
            .triangle_attrs
            .iter()
            .map(|a| a.light != NO_LIGHT)
            .collect();
        self.triangle_bvh = TriangleBvh::from_soup_with_emitters(&self.triangles, &emitting);
        self.bvh = Bvh::build(&self.prim_bounds(prototypes));
    }

    pub(crate) fn bounds(&self) -> Aabb {
        self.triangle_bvh.bounds().union(&self.bvh.bounds())
    }

    /// Render-space bounds of every primitive, in `prims` order.
    pub(crate) fn prim_bounds(&self, prototypes: &[ShapeSet]) -> Vec<Aabb> {
        self.prims
            .iter()
            .map(|prim| match *prim {
                PrimRef::Sphere(i) => {
                    let s = &self.spheres[i as usize];
                    let r = s.shape.radius;
                    transformed_box(
                        &s.render_from_object,
                        Aabb::new(
                            Vec3::new(-r, -r, s.shape.z_min),
                            Vec3::new(r, r, s.shape.z_max),
                        ),
                    )
                }
                PrimRef::Disk(i) => {
                    let d = &self.disks[i as usize];
                    let r = d.shape.radius;
                    let h = d.shape.height;
                    transformed_box(
                        &d.render_from_object,
                        Aabb::new(Vec3::new(-r, -r, h), Vec3::new(r, r, h)),
                    )
                }
                PrimRef::Bilinear(i) => {
                    let b = &self.bilinears[i as usize].patch;
                    Aabb::from_points(&[b.p00, b.p10, b.p01, b.p11])
                }
                PrimRef::Instance(i) => {
                    let inst = &self.instances[i as usize];
                    transformed_box(
                        &inst.render_from_instance,
                        prototypes[inst.prototype as usize].bounds(),
                    )
                }
            })
            .collect()
    }

    /// Bounding spheres (centre, radius) of the primitives whose material satisfies
    /// `pick`, in render space: one per mesh (over its picked triangles), one per
    /// quadric or curved patch (exact for spheres), one per instance whose prototype
    /// holds any. Used to aim photons at specular objects (projection maps).
    pub(crate) fn bounding_spheres_where(
        &self,
        prototypes: &[ShapeSet],
        pick: &dyn Fn(u32) -> bool,
    ) -> Vec<(Vec3, f32)> {
        let box_sphere = |b: &Aabb| (b.center(), 0.5 * b.diagonal().length());
        let mut per_mesh = vec![Aabb::EMPTY; self.meshes.len()];
        for (tri, attr) in self.triangles.iter().zip(&self.triangle_attrs) {
            if pick(attr.material) {
                let b = &mut per_mesh[attr.mesh as usize];
                *b = b.union(&Aabb::from_points(tri));
            }
        }
        let mut out = Vec::new();
        for (prim, bounds) in self.prims.iter().zip(self.prim_bounds(prototypes)) {
            match *prim {
                PrimRef::Sphere(i) if pick(self.spheres[i as usize].material) => {
                    let s = &self.spheres[i as usize];
                    // The largest axis scale bounds the transformed sphere.
                    let m = glam::Mat3::from_mat4(s.render_from_object.m);
                    let scale = m
                        .x_axis
                        .length()
                        .max(m.y_axis.length())
                        .max(m.z_axis.length());
                    let exact = (
                        s.render_from_object.point(Vec3::ZERO),
                        s.shape.radius * scale,
                    );
                    let loose = box_sphere(&bounds);
                    out.push(if exact.1 <= loose.1 { exact } else { loose });
                }
                PrimRef::Disk(i) if pick(self.disks[i as usize].material) => {
                    out.push(box_sphere(&bounds))
                }
                PrimRef::Bilinear(i) if pick(self.bilinears[i as usize].material) => {
                    out.push(box_sphere(&bounds))
                }
                PrimRef::Instance(i) => {
                    let proto = &prototypes[self.instances[i as usize].prototype as usize];
                    if !proto.bounding_spheres_where(&[], pick).is_empty() {
                        out.push(box_sphere(&bounds));
                    }
                }
                _ => {}
            }
        }
        out.extend(per_mesh.iter().filter(|b| !b.is_empty()).map(box_sphere));
        out
    }

    fn intersect_raw(
        &self,
        ray: &Ray,
        t_max: f32,
        prototypes: &[ShapeSet],
    ) -> Option<(f32, RawHit, Option<u32>)> {
        let mut best: Option<(f32, RawHit, Option<u32>)> = None;
        let mut t_max = t_max;
        if let Some(h) = self.triangle_bvh.intersect(ray, t_max) {
            t_max = h.t;
            best = Some((
                h.t,
                RawHit::Triangle {
                    index: h.prim,
                    b: h.b,
                },
                None,
            ));
        }
        if self.prims.is_empty() {
            return best;
        }
        let mut quadric: Option<(RawHit, Option<u32>)> = None;
        let t = self
            .bvh
            .closest_hit(ray, t_max, |prim, t_max| match self.prims[prim as usize] {
                PrimRef::Sphere(i) => {
                    let s = &self.spheres[i as usize];
                    let h = s
                        .shape
                        .intersect(&object_ray(&s.render_from_object, ray), t_max)?;
                    quadric = Some((
                        RawHit::Quadric {
                            prim: PrimRef::Sphere(i),
                            p_obj: h.p,
                            p_error: h.p_error,
                            n_obj: h.n,
                            uv: h.uv,
                        },
                        None,
                    ));
                    Some(h.t)
                }
                PrimRef::Disk(i) => {
                    let d = &self.disks[i as usize];
                    let h = d
                        .shape
                        .intersect(&object_ray(&d.render_from_object, ray), t_max)?;
                    quadric = Some((
                        RawHit::Quadric {
                            prim: PrimRef::Disk(i),
                            p_obj: h.p,
                            // Exactly in the disk's plane.
                            p_error: Vec3::ZERO,
                            n_obj: Vec3::Z,
                            uv: h.uv,
                        },
                        None,
                    ));
                    Some(h.t)
                }
                PrimRef::Bilinear(i) => {
                    let h = self.bilinears[i as usize].patch.intersect(ray, t_max)?;
                    quadric = Some((
                        RawHit::Quadric {
                            prim: PrimRef::Bilinear(i),
                            p_obj: h.p,
                            p_error: h.p_error,
                            n_obj: h.n,
                            uv: h.uv,
                        },
                        None,
                    ));
                    Some(h.t)
                }
                PrimRef::Instance(i) => {
                    let inst = &self.instances[i as usize];
                    let local = object_ray(&inst.render_from_instance, ray);
                    let (t, raw, _) =
                        prototypes[inst.prototype as usize].intersect_raw(&local, t_max, &[])?;
                    quadric = Some((raw, Some(i)));
                    Some(t)
                }
            });
        match (t, quadric) {
            (Some(t), Some((raw, inst))) => Some((t, raw, inst)),
            _ => best,
        }
    }

    #[inline(always)]
    pub(crate) fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        prototypes: &[ShapeSet],
    ) -> Option<SurfaceHit> {
        if self.prims.is_empty() {
            // Triangles only: the mesh hit expands straight into the surface hit, with
            // no raw hit stored in between (its fields, written one by one and read
            // back as wider words, stalled store-to-load forwarding).
            let h = self.triangle_bvh.intersect(ray, t_max)?;
            return Some(self.triangle_hit(h.t, h.prim, h.b));
        }
        let (t, raw, instance) = self.intersect_raw(ray, t_max, prototypes)?;
        match instance {
            None => Some(self.surface_hit(t, raw)),
            Some(i) => {
                let inst = &self.instances[i as usize];
                let mut hit = prototypes[inst.prototype as usize].surface_hit(t, raw);
                let to_render = &inst.render_from_instance;
                (hit.p, hit.p_error) = transform_point_with_error(to_render, hit.p, hit.p_error);
                hit.ng = to_render.normal(hit.ng).normalize();
                hit.ns = to_render.normal(hit.ns).normalize();
                hit.dpdu = to_render.vector(hit.dpdu);
                hit.dpdv = to_render.vector(hit.dpdv);
                Some(hit)
            }
        }
    }

    pub(crate) fn occluded(&self, ray: &Ray, t_max: f32, prototypes: &[ShapeSet]) -> bool {
        if self.triangle_bvh.occluded(ray, t_max) {
            return true;
        }
        !self.prims.is_empty()
            && self
                .bvh
                .any_hit(ray, t_max, |prim, t_max| match self.prims[prim as usize] {
                    PrimRef::Sphere(i) => {
                        let s = &self.spheres[i as usize];
                        s.shape
                            .intersect(&object_ray(&s.render_from_object, ray), t_max)
                            .is_some()
                    }
                    PrimRef::Disk(i) => {
                        let d = &self.disks[i as usize];
                        d.shape
                            .intersect(&object_ray(&d.render_from_object, ray), t_max)
                            .is_some()
                    }
                    PrimRef::Bilinear(i) => self.bilinears[i as usize]
                        .patch
                        .intersect(ray, t_max)
                        .is_some(),
                    PrimRef::Instance(i) => {
                        let inst = &self.instances[i as usize];
                        let local = object_ray(&inst.render_from_instance, ray);
                        prototypes[inst.prototype as usize].occluded(&local, t_max, &[])
                    }
                })
    }

    fn surface_hit(&self, t: f32, raw: RawHit) -> SurfaceHit {
        match raw {
            RawHit::Triangle { index, b } => self.triangle_hit(t, index, b),
            RawHit::Quadric {
                prim: PrimRef::Bilinear(i),
                p_obj,
                p_error,
                n_obj,
                uv,
            } => {
                let b = &self.bilinears[i as usize];
                let n = n_obj * b.orientation;
                let tangents = b.patch.tangents(uv);
                SurfaceHit {
                    t,
                    p: p_obj,
                    p_error,
                    ng: n,
                    ns: n,
                    uv,
                    dpdu: tangents.0,
                    dpdv: tangents.1,
                    dpdx: Vec3::ZERO,
                    dpdy: Vec3::ZERO,
                    material: b.material,
                    light: b.light,
                    alpha: b.alpha,
                }
            }
            RawHit::Quadric {
                prim,
                p_obj,
                p_error,
                n_obj,
                uv,
            } => {
                let (xf, material, light, reverse, phi_max, alpha, dpdv_obj) = match prim {
                    PrimRef::Sphere(i) => {
                        let s = &self.spheres[i as usize];
                        let phi_max = s.shape.phi_max;
                        (
                            &s.render_from_object,
                            s.material,
                            s.light,
                            s.reverse,
                            phi_max,
                            s.alpha,
                            s.shape.dpdv(p_obj),
                        )
                    }
                    PrimRef::Disk(i) => {
                        let d = &self.disks[i as usize];
                        let phi_max = d.shape.phi_max;
                        (
                            &d.render_from_object,
                            d.material,
                            d.light,
                            d.reverse,
                            phi_max,
                            d.alpha,
                            d.shape.dpdv(p_obj),
                        )
                    }
                    _ => unreachable!("bilinear patches are handled above; instances are resolved"),
                };
                let mut n = xf.normal(n_obj).normalize();
                if reverse {
                    n = -n;
                }
                let (p, p_error) = transform_point_with_error(xf, p_obj, p_error);
                // u = φ / φ_max on spheres and disks alike: ∂p/∂u = φ_max (−y, x, 0).
                let dpdu = xf.vector(phi_max * Vec3::new(-p_obj.y, p_obj.x, 0.0));
                SurfaceHit {
                    t,
                    p,
                    p_error,
                    ng: n,
                    ns: n,
                    uv,
                    dpdu,
                    dpdv: xf.vector(dpdv_obj),
                    dpdx: Vec3::ZERO,
                    dpdy: Vec3::ZERO,
                    material,
                    light,
                    alpha,
                }
            }
        }
    }

    #[inline(always)]
    fn triangle_hit(&self, t: f32, index: u32, b: [f32; 3]) -> SurfaceHit {
        let [p0, p1, p2] = self.triangles[index as usize];
        let attr = self.triangle_attrs[index as usize];
        let p = b[0] * p0 + b[1] * p1 + b[2] * p2;
        let p_error = barycentric_error(b, [p0, p1, p2]);
        let mut ng = (p1 - p0).cross(p2 - p0).normalize_or_zero() * attr.orientation;
        let mesh = &self.meshes[attr.mesh as usize];
        let tri = 3 * attr.index as usize;
        let vi = [
            mesh.indices[tri],
            mesh.indices[tri + 1],
            mesh.indices[tri + 2],
        ]
        .map(|v| v as usize);
        let mut ns = ng;
        if let Some(normals) = &mesh.normals {
            let n = (b[0] * normals[vi[0]] + b[1] * normals[vi[1]] + b[2] * normals[vi[2]])
                .normalize_or_zero();
            if n != Vec3::ZERO {
                ns = n;
                // With shading normals the geometric normal follows them (pbrt-v4).
                if ng.dot(ns) < 0.0 {
                    ng = -ng;
                }
            }
        }
        let tuv = triangle_uvs(
            mesh.uvs.as_deref(),
            vi,
            attr.index as usize,
            mesh.bilinear_halves,
        );
        let uv = b[0] * tuv[0] + b[1] * tuv[1] + b[2] * tuv[2];
        let (dpdu, dpdv) = triangle_tangents([p0, p1, p2], tuv);
        SurfaceHit {
            t,
            p,
            p_error,
            ng,
            ns,
            uv,
            dpdu,
            dpdv,
            dpdx: Vec3::ZERO,
            dpdy: Vec3::ZERO,
            material: attr.material,
            light: attr.light,
            alpha: mesh.alpha,
        }
    }
}

/// The (u, v) at the vertices `vi` of triangle `index` of a mesh: its `uvs`, or
/// pbrt's default (0,0), (1,0), (1,1); for the halves of planar bilinear patches, in
/// pairs, the patch's own parameterisation.
pub(super) fn triangle_uvs(
    uvs: Option<&[Vec2]>,
    vi: [usize; 3],
    index: usize,
    bilinear_halves: bool,
) -> [Vec2; 3] {
    match uvs {
        Some(uvs) => vi.map(|v| uvs[v]),
        // The two halves of a planar bilinear patch: (p00, p10, p11), (p00, p11, p01).
        None if bilinear_halves && index.is_multiple_of(2) => [Vec2::ZERO, Vec2::X, Vec2::ONE],
        None if bilinear_halves => [Vec2::ZERO, Vec2::ONE, Vec2::Y],
        None => [Vec2::ZERO, Vec2::X, Vec2::ONE],
    }
}

/// ∂p/∂u and ∂p/∂v of a triangle from its vertex uvs (the inverse of the 2×2 uv Jacobian, as in
/// pbrt-v4's triangle); zero when the uvs are degenerate, so that the shading frame
/// falls back to an arbitrary tangent.
#[inline(always)]
fn triangle_tangents(p: [Vec3; 3], uv: [Vec2; 3]) -> (Vec3, Vec3) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() < 1e-9 {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let dpdu = (duv12.y * dp02 - duv02.y * dp12) / det;
    let dpdv = (duv02.x * dp12 - duv12.x * dp02) / det;
    if dpdu.is_finite() && dpdv.is_finite() {
        (dpdu, dpdv)
    } else {
        (Vec3::ZERO, Vec3::ZERO)
    }
}

/// The ray in a shape's object space. The direction is not renormalised, so hit
/// distances are the same in both spaces.
fn object_ray(render_from_object: &Transform, ray: &Ray) -> Ray {
    let inv = render_from_object.inverse();
    Ray::new(inv.point(ray.o), inv.vector(ray.d))
}

fn transformed_box(xf: &Transform, b: Aabb) -> Aabb {
    let mut out = Aabb::EMPTY;
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        out = out.grow(xf.point(c));
    }
    out
}

impl Default for TriangleAttr {
    fn default() -> Self {
        TriangleAttr {
            mesh: 0,
            index: 0,
            material: 0,
            light: NO_LIGHT,
            orientation: 1.0,
        }
    }
}
