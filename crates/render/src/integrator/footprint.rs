//! The size of one pixel in the scene, for radius defaults that follow the image's
//! resolution (SPPM's initial radius, the photon dots of `photonviz`).

use glam::Vec2;

use crate::camera::Camera;
use crate::world::World;

/// Width of one pixel at the distance of the scene's centre, in scene units, and that
/// distance: the separation, at that distance, of the rays through the centres of the
/// image's central pixel and its right neighbour (works for perspective, orthographic
/// and lens cameras alike). A camera inside the scene near its centre (closer than half
/// the bounding radius) measures at the bounding radius instead. `None` when the camera
/// makes no ray there.
pub fn pixel_footprint(
    camera: &Camera,
    resolution: (u32, u32),
    world: &World,
) -> Option<(f32, f32)> {
    let (cx, cy) = ((resolution.0 / 2) as f32, (resolution.1 / 2) as f32);
    let u_lens = Vec2::splat(0.5);
    let a = camera
        .generate_ray(Vec2::new(cx + 0.5, cy + 0.5), u_lens)?
        .ray;
    let b = camera
        .generate_ray(Vec2::new(cx + 1.5, cy + 0.5), u_lens)?
        .ray;
    let scene = world.scene_sphere();
    let mut t = (scene.center - a.o).length();
    if t < 0.5 * scene.radius {
        t = scene.radius;
    }
    let pa = a.o + a.d.normalize() * t;
    let pb = b.o + b.d.normalize() * t;
    let w = (pb - pa).length();
    (w > 0.0 && w.is_finite()).then_some((w, t))
}
