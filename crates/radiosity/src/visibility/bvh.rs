//! Shadow rays through the renderer's BVHs: against the render [`World`], or against a
//! triangle BVH over the unsubdivided faces the patches were cut from.
//!
//! Both move the segment's ends off the two surfaces they lie on, along each patch's
//! normal towards the other end — the world past each point's rounding-error bound
//! (`World::visible`), the faces by a lift scaled to the scene — and stop a hair short of
//! the far end, so the endpoints' own surfaces never count as occluders.

use glam::{DVec3, Vec3};

use super::contact::Contacts;
use super::shaft::ShaftCuller;
use super::{ShotCull, Visibility};
use crate::mesh::meshed_scene::RadiosityScene;
use crate::mesh::patch::PatchSet;
use radiant_render::accel::TriangleBvh;
use radiant_render::geometry::Ray;
use radiant_render::geometry::SurfacePoint;
use radiant_render::world::World;

/// Patch index meaning "not on a patch" (a sensor or a light position).
pub const NO_PATCH: usize = usize::MAX;

/// Fraction of the segment left out at the far end (as `World::visible`).
const FAR_END: f32 = radiant_render::geometry::SHADOW_EPSILON;

/// Per patch, the normal and error bound its points get as segment ends.
fn segment_ends(set: &PatchSet) -> Vec<(Vec3, Vec3)> {
    (0..set.patches.len())
        .map(|i| (set.patches[i].normal.as_vec3(), set.point_error(i)))
        .collect()
}

/// The end of a segment on patch `patch` (or in free space for [`NO_PATCH`]).
#[inline]
fn segment_end(ends: &[(Vec3, Vec3)], p: DVec3, patch: usize) -> SurfacePoint {
    match ends.get(patch) {
        Some(&(n, err)) => SurfacePoint::new(p.as_vec3(), err, n),
        None => SurfacePoint::free(p.as_vec3()),
    }
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
    /// Normal and point error bound of each patch.
    ends: Vec<(Vec3, Vec3)>,
}

impl<'a> WorldVisibility<'a> {
    pub fn new(world: &'a World, set: &PatchSet) -> WorldVisibility<'a> {
        WorldVisibility {
            world,
            ends: segment_ends(set),
        }
    }
}

impl Visibility for WorldVisibility<'_> {
    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool {
        self.world.visible(
            &segment_end(&self.ends, from, from_patch),
            &segment_end(&self.ends, to, to_patch),
        )
    }
}

/// Occlusion by the faces the patches were cut from (quads as two triangles), in the
/// renderer's fast triangle BVH: the same surfaces the solver sees, with far fewer
/// triangles than patches.
///
/// Faces that cannot block anything are left out: a segment between two points of
/// the scene crosses a face's plane only if its ends lie strictly on opposite sides,
/// so a face with every vertex of the scene on one (closed) side of its plane, such as
/// the walls of a room, never occludes. The walls of the Cornell box drop out and
/// only the blocks and the light remain, which makes most shadow rays one box test.
pub struct FaceVisibility {
    bvh: TriangleBvh,
    /// Patch normals scaled by the offset that lifts ray ends off their surfaces.
    lifts: Vec<Vec3>,
    /// The length of the lifts.
    lift: f64,
    occluders: usize,
    shafts: ShaftCuller,
    /// Patches covered by a face lying on them, closer than the lift.
    contacts: Contacts,
}

/// Ray ends are lifted off their patches by this fraction of the scene's size: far
/// above f32 rounding of the coordinates (1e-7 relative), far below any feature.
const LIFT: f64 = 1e-6;

/// Vertices closer to a plane than this fraction of the scene's size count as on it.
const PLANE_TOLERANCE: f64 = 1e-7;

/// Above this many face-vertex pairs, only the scene's bounding box is tested against
/// each face plane (conservative: keeps more faces).
const EXACT_CULL_LIMIT: usize = 50_000_000;

impl FaceVisibility {
    pub fn new(scene: &RadiosityScene) -> FaceVisibility {
        let points = &scene.faces.points;
        let lower = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
        let upper = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        let size = (upper - lower).length().max(f64::MIN_POSITIVE);
        let box_corners: Vec<DVec3> = (0..8)
            .map(|k| {
                DVec3::new(
                    if k & 1 == 0 { lower.x } else { upper.x },
                    if k & 2 == 0 { lower.y } else { upper.y },
                    if k & 4 == 0 { lower.z } else { upper.z },
                )
            })
            .collect();
        let exact = scene.faces.faces.len().saturating_mul(points.len()) <= EXACT_CULL_LIMIT;
        let tested: &[DVec3] = if exact { points } else { &box_corners };
        let mut triangles: Vec<[DVec3; 3]> = Vec::with_capacity(scene.faces.faces.len() * 2);
        let can_block = |[a, b, d]: [DVec3; 3]| {
            let n = (b - a).cross(d - a);
            let length = n.length();
            if length == 0.0 {
                return false;
            }
            let n = n / length;
            let (mut front, mut back) = (false, false);
            for p in tested {
                let h = n.dot(*p - a);
                front |= h > PLANE_TOLERANCE * size;
                back |= h < -PLANE_TOLERANCE * size;
                if front && back {
                    return true;
                }
            }
            false
        };
        for f in scene.faces.faces.iter().filter(|f| !f.curved) {
            let c = f.corners;
            let halves: &[[u32; 3]] = if f.count == 4 {
                &[[c[0], c[1], c[2]], [c[0], c[2], c[3]]]
            } else {
                &[[c[0], c[1], c[2]]]
            };
            for &t in halves {
                let corners = t.map(|i| points[i as usize]);
                if can_block(corners) {
                    triangles.push(corners);
                }
            }
        }
        // Curved faces occlude with the surface their patches lie on.
        let set = &scene.patches;
        for (i, p) in set.patches.iter().enumerate().take(scene.front_count) {
            if !scene.faces.faces[scene.patch_face[i] as usize].curved {
                continue;
            }
            let c = p.corners;
            let halves: &[[u32; 3]] = if p.corner_count == 4 {
                &[[c[0], c[1], c[2]], [c[0], c[2], c[3]]]
            } else {
                &[[c[0], c[1], c[2]]]
            };
            for &t in halves {
                let corners = t.map(|k| set.points[k as usize]);
                if can_block(corners) {
                    triangles.push(corners);
                }
            }
        }
        let soup: Vec<[Vec3; 3]> = triangles.iter().map(|t| t.map(|p| p.as_vec3())).collect();
        let lift = (LIFT * size) as f32;
        // A face closer to a patch than twice the lift (both ends are lifted) is behind
        // the rays' origins and cannot occlude them: such contacts are cut explicitly.
        let contacts = Contacts::new(scene, 2.0 * LIFT * size);
        FaceVisibility {
            contacts,
            bvh: TriangleBvh::from_soup(&soup),
            lifts: patch_normals(&scene.patches)
                .into_iter()
                .map(|n| n * lift)
                .collect(),
            lift: lift as f64 * 1.001,
            occluders: triangles.len(),
            shafts: ShaftCuller::new(
                &scene.patches,
                &scene.patch_face,
                &triangles,
                scene.max_edge,
                PLANE_TOLERANCE * size,
            ),
        }
    }

    /// Number of patches covered by a face lying on them (see [`Contacts`]).
    pub fn covered_patches(&self) -> usize {
        self.contacts.covered()
    }

    /// Number of triangles that can block a shadow ray.
    pub fn occluder_count(&self) -> usize {
        self.occluders
    }

    /// Whether progressive shots are shaft-culled; where culling would cost more than
    /// it saves (see [`ShaftCuller::pays`]), every shadow ray goes through the BVH.
    pub fn culls_shots(&self) -> bool {
        self.shafts.pays()
    }

    /// Whether anything blocks `ray` before `t_max`.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.bvh.occluded(ray, t_max)
    }
}

impl Visibility for FaceVisibility {
    fn always_visible(&self) -> bool {
        self.occluders == 0 && self.contacts.covered() == 0
    }

    fn separated(&self, a: usize, b: usize) -> bool {
        self.contacts.separated(a, b)
    }

    fn prepare_shot(
        &self,
        set: &PatchSet,
        source: usize,
        shot: &mut ShotCull,
        go_on: &mut dyn FnMut() -> bool,
    ) -> bool {
        // Receivers that exchange light with the shooter lie in front of it, so every
        // ray of the shot ends at its centroid lifted along its normal.
        if !self.culls_shots() {
            // Left unprepared: every ray of the shot goes through the BVH.
            return true;
        }
        let apex = set.patches[source].centroid + self.lifts[source].as_dvec3();
        self.shafts.prepare(source, apex, self.lift, shot, go_on)
    }

    fn visible_in_shot(
        &self,
        shot: &ShotCull,
        from: DVec3,
        to: DVec3,
        from_patch: usize,
        to_patch: usize,
    ) -> bool {
        if self.contacts.separated(from_patch, to_patch) {
            return false;
        }
        if from_patch >= self.lifts.len() || to_patch >= self.lifts.len() {
            return self.visible(from, to, from_patch, to_patch);
        }
        let d = to - from;
        let lift = |patch: usize, towards: DVec3| {
            let l = self.lifts[patch].as_dvec3();
            if l.dot(towards) < 0.0 { -l } else { l }
        };
        let o = from + lift(from_patch, d);
        let target = to + lift(to_patch, -d);
        if !shot.prepared_for(to_patch, target) {
            return self.visible(from, to, from_patch, to_patch);
        }

        !self.shafts.blocked(shot, from_patch, o, FAR_END as f64)
    }

    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool {
        if self.contacts.separated(from_patch, to_patch) {
            return false;
        }
        if self.occluders == 0 {
            return true;
        }
        // Lift each end along its patch normal, towards the side the other end is on.
        let (p0, p1) = (from.as_vec3(), to.as_vec3());
        let d = p1 - p0;
        let lift = |patch: usize, towards: Vec3| {
            let l = normal_of(&self.lifts, patch);
            if l.dot(towards) < 0.0 { -l } else { l }
        };
        let o = p0 + lift(from_patch, d);
        let target = p1 + lift(to_patch, -d);
        !self.bvh.occluded(&Ray::new(o, target - o), 1.0 - FAR_END)
    }
}

/// Either source, chosen at run time by the integrator's `visibility` parameter.
pub enum SceneVisibility<'a> {
    Faces(Box<FaceVisibility>),
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

    fn always_visible(&self) -> bool {
        match self {
            SceneVisibility::Faces(v) => v.always_visible(),
            SceneVisibility::World(v) => v.always_visible(),
        }
    }

    fn separated(&self, a: usize, b: usize) -> bool {
        match self {
            SceneVisibility::Faces(v) => v.separated(a, b),
            SceneVisibility::World(v) => v.separated(a, b),
        }
    }

    fn prepare_shot(
        &self,
        set: &PatchSet,
        source: usize,
        shot: &mut ShotCull,
        go_on: &mut dyn FnMut() -> bool,
    ) -> bool {
        match self {
            SceneVisibility::Faces(v) => v.prepare_shot(set, source, shot, go_on),
            SceneVisibility::World(v) => v.prepare_shot(set, source, shot, go_on),
        }
    }

    #[inline]
    fn visible_in_shot(
        &self,
        shot: &ShotCull,
        from: DVec3,
        to: DVec3,
        from_patch: usize,
        to_patch: usize,
    ) -> bool {
        match self {
            SceneVisibility::Faces(v) => v.visible_in_shot(shot, from, to, from_patch, to_patch),
            SceneVisibility::World(v) => v.visible_in_shot(shot, from, to, from_patch, to_patch),
        }
    }
}
