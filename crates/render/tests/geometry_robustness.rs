//! Rays leaving a surface never find that surface again, at any scene scale.
//!
//! Points are found on large triangles lying in the coordinate planes x = 0, y = 0,
//! z = 0 (where a surface point's coordinate along the normal is exactly zero, so a
//! relative offset vanishes) and in planes beside them, on spheres and on tilted disks,
//! for scene scales from 1e-2 to 1e4 and placements far from the origin. From each, rays
//! are spawned in uniformly random and in grazing directions: a plane (or disk) alone in
//! the scene can never be hit by a ray leaving it, nor a sphere by a ray leaving it
//! outwards, and a ray entering a sphere must travel (nearly) the chord before it meets
//! the sphere again. `World::visible` must succeed to points that nothing hides: points
//! in front of a plane, however grazing the segment, and across a sphere's interior
//! from one of its points to another.

use glam::{Vec2, Vec3};
use radiant_math::hash::Pcg32;
use radiant_math::{Frame, Transform, sampling};
use radiant_render::geometry::{Ray, SurfacePoint};
use radiant_render::world::{SurfaceHit, World};
use radiant_scene::builtin::cornell_box;
use radiant_scene::{Geometry, SceneDesc, ShapeDesc};

const SCALES: [f32; 5] = [1e-2, 1e-1, 1.0, 1e2, 1e4];
/// Directions spawned per surface point and kind.
const RANDOM_DIRECTIONS: usize = 24;
/// How far below the tangent plane grazing directions point (as a tangent of the angle).
const GRAZING: [f32; 5] = [1e-1, 1e-2, 1e-3, 1e-4, 1e-6];

fn world_of(shapes: Vec<ShapeDesc>) -> World {
    let mut desc: SceneDesc = cornell_box();
    desc.shapes = shapes;
    desc.lights = Vec::new();
    World::build(&desc).expect("the world builds").0
}

fn shape(geometry: Geometry, render_from_object: Transform) -> ShapeDesc {
    let mut s = cornell_box().shapes.remove(0);
    s.geometry = geometry;
    s.render_from_object = render_from_object;
    s.reverse_orientation = false;
    s.area_light = None;
    s
}

/// A square of half-size `half` centred at `centre`, in the plane through `centre`
/// perpendicular to `axis`, as two triangles.
fn square(axis: usize, centre: Vec3, half: f32) -> ShapeDesc {
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    let corner = |a: f32, b: f32| {
        let mut p = centre;
        p[i] += a * half;
        p[j] += b * half;
        p
    };
    let positions = vec![
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    shape(
        Geometry::TriangleMesh {
            positions,
            indices: vec![0, 1, 2, 0, 2, 3],
            normals: None,
            uvs: None,
        },
        Transform::IDENTITY,
    )
}

fn rand2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

/// A unit direction tangent to the surface with normal `n`, tilted by `tan` towards `n`
/// (negative: away from it).
fn grazing(n: Vec3, tan: f32, rng: &mut Pcg32) -> Vec3 {
    let phi = 2.0 * std::f32::consts::PI * rng.uniform();
    let t = Frame::from_normal(n).to_world(Vec3::new(phi.cos(), phi.sin(), 0.0));
    (t + tan * n).normalize()
}

/// The directions spawned from a point with normal `n`: uniform over the sphere, and
/// grazing on both sides.
fn directions(n: Vec3, rng: &mut Pcg32) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = (0..RANDOM_DIRECTIONS)
        .map(|_| sampling::uniform_sphere(rand2(rng)))
        .collect();
    for tan in GRAZING {
        out.push(grazing(n, tan, rng));
        out.push(grazing(n, -tan, rng));
    }
    out
}

#[derive(Default)]
struct Tally {
    points: usize,
    rays: usize,
    self_hits: usize,
    blocked: usize,
    first: Option<String>,
}

impl Tally {
    fn fail(&mut self, what: String) {
        if self.first.is_none() {
            self.first = Some(what);
        }
    }

    fn assert_clean(&self, name: &str) {
        println!(
            "{name}: {} points, {} rays, {} self-hits, {} blocked segments",
            self.points, self.rays, self.self_hits, self.blocked
        );
        assert!(self.points > 0, "{name}: no surface points found");
        assert!(
            self.self_hits == 0 && self.blocked == 0,
            "{name}: {} of {} rays hit their own surface, {} free segments blocked; first: {}",
            self.self_hits,
            self.rays,
            self.blocked,
            self.first.as_deref().unwrap_or("")
        );
    }
}

/// Points on a flat shape seen from `eye`: every spawned ray must miss (the shape is
/// alone), and segments to points in front of it must be free.
fn check_flat(world: &World, eye: Vec3, targets: &[Vec3], size: f32, tally: &mut Tally) {
    let mut rng = Pcg32::new(targets.len() as u64, 17);
    for &target in targets {
        let Some(hit) = world.intersect(&Ray::new(eye, target - eye), f32::INFINITY) else {
            continue;
        };
        tally.points += 1;
        let sp = hit.surface_point();
        for w in directions(hit.ng, &mut rng) {
            tally.rays += 1;
            if let Some(h) = world.intersect(&sp.spawn_ray(w), f32::INFINITY) {
                tally.self_hits += 1;
                tally.fail(format!("p {} w {w} hit at t {}", hit.p, h.t));
            }
        }
        // Free points on the eye's side, from steep to grazing segments.
        let n = if hit.ng.dot(eye - hit.p) > 0.0 {
            hit.ng
        } else {
            -hit.ng
        };
        for tan in GRAZING {
            let to = hit.p + size * (grazing(n, tan, &mut rng) * 0.1);
            // Only points that are in front once rounded to f32 (clearly above the
            // rounding of their own coordinates).
            if (to - hit.p).dot(n) <= 1e-5 * to.abs().max_element() {
                continue;
            }
            if !world.visible(&sp, &SurfacePoint::free(to)) {
                tally.blocked += 1;
                tally.fail(format!("p {} to {to} blocked", hit.p));
            }
        }
        // And far points in front, as a light across a room is.
        for _ in 0..RANDOM_DIRECTIONS {
            let w = sampling::uniform_sphere(rand2(&mut rng));
            let to = hit.p + size * 2.0 * if w.dot(n) < 0.0 { -w } else { w };
            if (to - hit.p).dot(n) <= 1e-5 * to.abs().max_element() {
                continue;
            }
            tally.rays += 1;
            if !world.visible(&sp, &SurfacePoint::free(to)) {
                tally.blocked += 1;
                tally.fail(format!("p {} to {to} blocked", hit.p));
            }
        }
    }
}

/// Random points of the square of half-size `half` about `centre` in the plane
/// perpendicular to `axis` (its inner 80 %).
fn square_targets(axis: usize, centre: Vec3, half: f32, rng: &mut Pcg32) -> Vec<Vec3> {
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    (0..150)
        .map(|_| {
            let mut p = centre;
            p[i] += (rng.uniform() * 1.6 - 0.8) * half;
            p[j] += (rng.uniform() * 1.6 - 0.8) * half;
            p
        })
        .collect()
}

/// Large squares in the coordinate planes and in planes beside them, placed at the
/// origin and far along the plane, at every scale; viewed from both sides, steeply
/// and obliquely.
#[test]
fn rays_leaving_axis_aligned_triangles_never_hit_them() {
    let mut rng = Pcg32::new(1, 2);
    for axis in 0..3 {
        for s in SCALES {
            // (plane, centre along the plane, half-size): the last is a wall of a room
            // with a corner at the origin.
            for (plane, along, half) in [
                (0.0, 0.0, 10.0),
                (0.0, 370.0, 10.0),
                (0.37, 0.0, 10.0),
                (-13.0, 290.0, 10.0),
                (0.0, 280.0, 280.0),
            ] {
                let mut centre = Vec3::splat(along * s);
                centre[axis] = plane * s;
                let half = half * s;
                let world = world_of(vec![square(axis, centre, half)]);
                let targets = square_targets(axis, centre, half, &mut rng);
                let mut tally = Tally::default();
                for side in [1.0, -1.0] {
                    for tilt in [0.0, 3.0] {
                        let mut eye = centre + Vec3::splat(tilt * half * 0.1);
                        eye[axis] = centre[axis] + side * 0.4 * half;
                        check_flat(&world, eye, &targets, half, &mut tally);
                    }
                }
                tally.assert_clean(&format!(
                    "square ⟂ axis {axis}, scale {s}, plane {plane}, along {along}"
                ));
            }
        }
    }
}

/// Tilted disks and disks in a coordinate plane, at every scale and placement.
#[test]
fn rays_leaving_disks_never_hit_them() {
    let mut rng = Pcg32::new(3, 4);
    for s in SCALES {
        for (offset, degrees) in [(0.0, 0.0), (0.0, 37.0), (250.0, 0.0), (-90.0, 71.0)] {
            let centre = Vec3::new(1.0, -0.5, 0.25) * offset * s;
            let axis = Vec3::new(1.0, 0.5, -0.2).normalize();
            let xf = Transform::translate(centre)
                .compose(&Transform::rotate(degrees, axis).unwrap())
                .compose(&Transform::scale(Vec3::splat(s)).unwrap());
            let disk = Geometry::Disk {
                height: 0.0,
                radius: 10.0,
                inner_radius: 0.0,
                phi_max_deg: 360.0,
            };
            let world = world_of(vec![shape(disk, xf)]);
            let n = xf.normal(Vec3::Z).normalize();
            let targets: Vec<Vec3> = (0..150)
                .map(|_| xf.point((sampling::concentric_disk(rand2(&mut rng)) * 8.0).extend(0.0)))
                .collect();
            let mut tally = Tally::default();
            for side in [1.0, -1.0] {
                let eye = centre + side * 5.0 * s * n + xf.vector(Vec3::new(2.0, 1.0, 0.0));
                check_flat(&world, eye, &targets, 10.0 * s, &mut tally);
            }
            tally.assert_clean(&format!("disk scale {s}, offset {offset}, tilt {degrees}"));
        }
    }
}

/// Spheres of every scale at the origin and far from it: rays leaving outwards (random
/// and grazing) miss; rays entering travel at least half the chord 2 r cos θ before
/// they meet the sphere again; two points of the sphere see each other through it.
#[test]
fn rays_leaving_spheres_never_hit_them_near_their_origin() {
    let mut rng = Pcg32::new(5, 6);
    for s in SCALES {
        for offset in [0.0, 3.0, 400.0] {
            let centre = Vec3::new(0.7, -1.0, 0.4) * offset * s;
            let xf = Transform::translate(centre);
            let sphere = Geometry::Sphere {
                radius: s,
                z_min: -s,
                z_max: s,
                phi_max_deg: 360.0,
            };
            let world = world_of(vec![shape(sphere, xf)]);
            let mut tally = Tally::default();
            let mut hits: Vec<SurfaceHit> = Vec::new();
            for _ in 0..300 {
                let eye = centre + sampling::uniform_sphere(rand2(&mut rng)) * (3.0 * s);
                let aim = centre + sampling::uniform_sphere(rand2(&mut rng)) * (0.9 * s);
                if let Some(h) = world.intersect(&Ray::new(eye, aim - eye), f32::INFINITY) {
                    hits.push(h);
                }
            }
            for (k, hit) in hits.iter().enumerate() {
                tally.points += 1;
                let sp = hit.surface_point();
                let n = hit.ng;
                let mut outward: Vec<Vec3> = (0..RANDOM_DIRECTIONS)
                    .map(|_| {
                        let w = sampling::uniform_sphere(rand2(&mut rng));
                        if w.dot(n) < 0.0 { -w } else { w }
                    })
                    .collect();
                outward.extend(GRAZING.map(|tan| grazing(n, tan, &mut rng)));
                for w in outward {
                    tally.rays += 1;
                    if let Some(h) = world.intersect(&sp.spawn_ray(w), f32::INFINITY) {
                        tally.self_hits += 1;
                        tally.fail(format!("outward from {} w {w} hit at t {}", hit.p, h.t));
                    }
                }
                for tan in [-1.0, -0.3, -1e-1, -1e-2, -1e-3] {
                    let w = grazing(n, tan, &mut rng);
                    let cos = -w.dot(n);
                    tally.rays += 1;
                    let travelled = world
                        .intersect(&sp.spawn_ray(w), f32::INFINITY)
                        .map(|h| (h.p - hit.p).length());
                    if !travelled.is_some_and(|d| d > s * cos) {
                        tally.self_hits += 1;
                        tally.fail(format!(
                            "inward from {} cos {cos}: met again after {travelled:?} (chord {})",
                            hit.p,
                            2.0 * s * cos
                        ));
                    }
                }
                let other = &hits[(k * 7 + 3) % hits.len()];
                if (other.p - hit.p).length() > 1e-3 * s
                    && !world.visible(&sp, &other.surface_point())
                {
                    tally.blocked += 1;
                    tally.fail(format!(
                        "{} to {} through the sphere blocked",
                        hit.p, other.p
                    ));
                }
                let front = hit.p + (grazing(n, 1e-3, &mut rng) + 0.2 * n) * s;
                if !world.visible(&sp, &SurfacePoint::free(front)) {
                    tally.blocked += 1;
                    tally.fail(format!("{} to {front} outside blocked", hit.p));
                }
            }
            tally.assert_clean(&format!("sphere scale {s}, offset {offset}"));
        }
    }
}

/// pbrt-v4 accepts singular transforms: a warning with the location, a sphere under a
/// zero scale left out, a mesh under a flattening matrix kept (flattened), and an
/// error only where the inverse is needed (the camera).
#[test]
fn singular_transforms_are_accepted_with_a_warning_and_collapse_their_shapes() {
    let dir = std::path::Path::new(".");
    let text = r#"WorldBegin
AttributeBegin
  Scale 0 0 0
  Shape "sphere" "float radius" 5
AttributeEnd
AttributeBegin
  ConcatTransform [1 0 0 0  0 1 0 0  0 0 0 0  0 0 0 1]
  Shape "trianglemesh" "integer indices" [0 1 2]
    "point3 P" [-1 -1 3  1 -1 3  0 1 3]
AttributeEnd
"#;
    let desc = radiant_scene::parse_str(text, "t.pbrt", dir).unwrap_or_else(|e| panic!("{e}"));
    let singular: Vec<_> = desc
        .warnings
        .iter()
        .filter(|w| w.message.contains("singular"))
        .map(|w| w.to_string())
        .collect();
    assert_eq!(singular.len(), 2, "{singular:?}");
    assert!(singular[0].starts_with("t.pbrt:3:3:"), "{singular:?}");
    let (world, _) = World::build(&desc).unwrap_or_else(|e| panic!("{e}"));
    // The triangle, flattened onto z = 0, is hit there; the collapsed sphere nowhere.
    let down = Ray::new(Vec3::new(0.0, -0.2, 10.0), Vec3::new(0.0, 0.0, -1.0));
    let hit = world
        .intersect(&down, f32::INFINITY)
        .expect("the flattened triangle");
    assert!(hit.p.z.abs() < 1e-5, "{:?}", hit.p);
    let beside = Ray::new(Vec3::new(3.0, 0.0, 10.0), Vec3::new(0.0, 0.0, -1.0));
    assert!(world.intersect(&beside, f32::INFINITY).is_none());

    let camera = "Scale 1 0 1\nCamera \"perspective\"\nWorldBegin\n";
    let e = radiant_scene::parse_str(camera, "t.pbrt", dir)
        .expect_err("the camera needs the inverse")
        .to_string();
    assert!(
        e.starts_with("t.pbrt:2:1:") && e.contains("singular"),
        "{e}"
    );
}
