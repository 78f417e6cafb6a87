//! Shadow rays through the renderer's BVHs: against the render [`World`], or against a
//! triangle BVH over the unsubdivided faces the patches were cut from.
//!
//! Both offset the segment off the two surfaces it joins, along each patch's normal
//! towards the other end (the world's self-intersection offset), and stop a hair short
//! of the far end, so the endpoints' own surfaces never count as occluders.

use glam::{DVec3, Vec3};

use super::patch::PatchSet;
use super::scene::RadiosityScene;
use super::visibility::Visibility;
use crate::render::accel::TriangleBvh;
use crate::render::geometry::Ray;
use crate::render::geometry::ray::offset_origin;
use crate::render::world::World;

/// Patch index meaning "not on a patch" (a sensor or a light position).
pub const NO_PATCH: usize = usize::MAX;

/// Fraction of the segment left out at the far end (as `World::visible`).
const FAR_END: f32 = 1e-4;

/// The segment `p0 -> p1` offset off both surfaces (normals `n0`, `n1`; zero for a point
/// in free space), as a ray with `t` in `[0, 1 - FAR_END)`.
#[inline]
fn offset_segment(p0: Vec3, n0: Vec3, p1: Vec3, n1: Vec3) -> Ray {
    let o = offset_origin(p0, n0, p1 - p0);
    let target = offset_origin(p1, n1, o - p1);
    Ray::new(o, target - o)
}

fn patch_normals(set: &PatchSet) -> Vec<Vec3> {
    set.patches.iter().map(|p| p.normal.as_vec3()).collect()
}

#[inline]
fn normal_of(normals: &[Vec3], patch: usize) -> Vec3 {
    normals.get(patch).copied().unwrap_or(Vec3::ZERO)
}

/// Occlusion by the render world (analytic spheres and disks, instances). Exact when the
/// patches lie on the world's surfaces (planar shapes); the faceted patches of curved
/// shapes lie inside them and would shadow themselves, so use [`FaceVisibility`] there.
pub struct WorldVisibility<'a> {
    world: &'a World,
    normals: Vec<Vec3>,
}

impl<'a> WorldVisibility<'a> {
    pub fn new(world: &'a World, set: &PatchSet) -> WorldVisibility<'a> {
        WorldVisibility {
            world,
            normals: patch_normals(set),
        }
    }
}

impl Visibility for WorldVisibility<'_> {
    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool {
        let ray = offset_segment(
            from.as_vec3(),
            normal_of(&self.normals, from_patch),
            to.as_vec3(),
            normal_of(&self.normals, to_patch),
        );
        !self.world.occluded(&ray, 1.0 - FAR_END)
    }
}

/// Occlusion by the faces the patches were cut from (quads as two triangles), in the
/// renderer's fast triangle BVH: the same surfaces the solver sees, with far fewer
/// triangles than patches.
pub struct FaceVisibility {
    bvh: TriangleBvh,
    normals: Vec<Vec3>,
}

impl FaceVisibility {
    pub fn new(scene: &RadiosityScene) -> FaceVisibility {
        let vertices: Vec<Vec3> = scene.faces.points.iter().map(|p| p.as_vec3()).collect();
        let mut triangles = Vec::with_capacity(scene.faces.faces.len() * 2);
        for f in &scene.faces.faces {
            let c = f.corners;
            triangles.push([c[0], c[1], c[2]]);
            if f.count == 4 {
                triangles.push([c[0], c[2], c[3]]);
            }
        }
        FaceVisibility {
            bvh: TriangleBvh::build(&vertices, &triangles),
            normals: patch_normals(&scene.patches),
        }
    }

    /// Whether anything blocks `ray` before `t_max`.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.bvh.occluded(ray, t_max)
    }
}

impl Visibility for FaceVisibility {
    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool {
        let ray = offset_segment(
            from.as_vec3(),
            normal_of(&self.normals, from_patch),
            to.as_vec3(),
            normal_of(&self.normals, to_patch),
        );
        !self.bvh.occluded(&ray, 1.0 - FAR_END)
    }
}

/// Either source, chosen at run time by the integrator's `visibility` parameter.
pub enum SceneVisibility<'a> {
    Faces(FaceVisibility),
    World(WorldVisibility<'a>),
}

impl Visibility for SceneVisibility<'_> {
    #[inline]
    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool {
        match self {
            SceneVisibility::Faces(v) => v.visible(from, to, from_patch, to_patch),
            SceneVisibility::World(v) => v.visible(from, to, from_patch, to_patch),
        }
    }
}
