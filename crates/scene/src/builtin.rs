//! The canonical scenes, built in code exactly as `shared/scenes.md` defines them:
//! `cornell-box`, `cornell-caustics` and `furnace`. The same scenes exist as pbrt files
//! under `scenes/`; a test checks that both give the same description.
//!
//! Units are millimetres, +y is up and the camera looks along +z with world +x on the
//! image's left (a right-handed camera). pbrt's `LookAt` gives a left-handed camera, so
//! the camera transform is `Scale(-1, 1, 1) · LookAt`, as `Scale -1 1 1` in the files.

use glam::{Vec2, Vec3};

use super::desc::*;
use super::error::FileLoc;
use super::params::{ParamSet, ParamValue};
use radiant_math::Transform;
use radiant_math::color::Rgb;

/// Names accepted by [`builtin_scene`].
pub const BUILTIN_SCENES: [&str; 3] = ["cornell-box", "cornell-caustics", "furnace"];

/// Path length used for "unbounded" transport: with Russian roulette paths stop long
/// before; the truncation bias is below 0.885^100 ≈ 5e-6 of the image.
pub const UNBOUNDED_DEPTH: i32 = 100;

/// A canonical scene by name.
pub fn builtin_scene(name: &str) -> Option<SceneDesc> {
    match name {
        "cornell-box" => Some(cornell_box()),
        "cornell-caustics" => Some(cornell_caustics()),
        "furnace" => Some(furnace()),
        _ => None,
    }
}

pub const WHITE: Rgb = Rgb::new(0.885809, 0.698859, 0.666422);
pub const RED: Rgb = Rgb::new(0.570068, 0.0430135, 0.0443706);
pub const GREEN: Rgb = Rgb::new(0.105421, 0.37798, 0.076425);
pub const LIGHT_ALBEDO: Rgb = Rgb::splat(0.78);
pub const LIGHT_LE: Rgb = Rgb::new(18.387, 13.9873, 6.75357);

const M_WHITE: MaterialId = 0;
const M_RED: MaterialId = 1;
const M_GREEN: MaterialId = 2;
const M_LIGHT: MaterialId = 3;
const M_GLASS: MaterialId = 4;
const M_MIRROR: MaterialId = 5;

fn loc(scene: &str) -> FileLoc {
    FileLoc::builtin(scene)
}

fn p(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// A quad (v0, v1, v2, v3) as the triangles (v0,v1,v2), (v0,v2,v3).
fn quad(vs: [Vec3; 4], material: MaterialId, scene: &str) -> ShapeDesc {
    quads(&[vs], material, scene)
}

fn quads(list: &[[Vec3; 4]], material: MaterialId, scene: &str) -> ShapeDesc {
    ShapeDesc::quads(list, material, loc(scene))
}

fn sphere(center: Vec3, radius: f32, material: MaterialId, scene: &str) -> ShapeDesc {
    ShapeDesc {
        geometry: Geometry::Sphere {
            radius,
            z_min: -radius,
            z_max: radius,
            phi_max_deg: 360.0,
        },
        render_from_object: Transform::translate(center),
        reverse_orientation: false,
        material,
        area_light: None,
        alpha: None,
        loc: loc(scene),
    }
}

/// A pinhole camera at `eye` looking at `target` with world +x on the image's left
/// (`Scale -1 1 1` then pbrt's `LookAt`), as the canonical scenes use; `vfov_deg` is
/// the full field of view; `scene` names the built-in scene for locations.
pub fn right_handed_camera(
    eye: Vec3,
    target: Vec3,
    up: Vec3,
    vfov_deg: f32,
    scene: &str,
) -> CameraDesc {
    let look = Transform::look_at(eye, target, up).expect("valid canonical camera");
    let flip = Transform::scale(Vec3::new(-1.0, 1.0, 1.0)).expect("non-singular");
    CameraDesc {
        camera_from_world: flip.compose(&look),
        kind: CameraKind::Perspective {
            fov_deg: vfov_deg,
            lens_radius: 0.0,
            focal_distance: 1e6,
            screen_window: None,
        },
        exposure_time: 1.0,
        loc: loc(scene),
    }
}

fn canonical_settings(
    scene: &str,
    resolution: u32,
    spp: u32,
) -> (FilmDesc, SamplerDesc, FilterDesc, IntegratorDesc) {
    (
        FilmDesc {
            xresolution: resolution,
            yresolution: resolution,
            filename: Some(format!("{scene}.exr")),
            diagonal_mm: 35.0,
            iso: 100.0,
            gbuffer: None,
            max_component_value: f32::INFINITY,
            white_balance: None,
            loc: loc(scene),
        },
        SamplerDesc {
            kind: SamplerKind::Sobol,
            pixel_samples: spp,
            seed: 0,
            loc: loc(scene),
        },
        // A box of exactly one pixel, as the references use.
        FilterDesc {
            kind: FilterKind::Box,
            radius: Vec2::splat(0.5),
            loc: loc(scene),
        },
        IntegratorDesc {
            name: "path".into(),
            params: ParamSet::new().with("maxdepth", ParamValue::Int(vec![UNBOUNDED_DEPTH])),
            loc: loc(scene),
        },
    )
}

fn cornell_materials() -> Vec<MaterialDesc> {
    vec![
        MaterialDesc::Diffuse { reflectance: WHITE },
        MaterialDesc::Diffuse { reflectance: RED },
        MaterialDesc::Diffuse { reflectance: GREEN },
        MaterialDesc::Diffuse {
            reflectance: LIGHT_ALBEDO,
        },
        MaterialDesc::Dielectric { eta: 1.5 },
        MaterialDesc::Conductor(ConductorDesc::Reflectance(Rgb::WHITE)),
    ]
}

/// The room shared by both Cornell scenes: walls and the light.
fn cornell_room(scene: &str) -> Vec<ShapeDesc> {
    let mut light = quad(
        [
            p(343.0, 548.7, 227.0),
            p(343.0, 548.7, 332.0),
            p(213.0, 548.7, 332.0),
            p(213.0, 548.7, 227.0),
        ],
        M_LIGHT,
        scene,
    );
    light.area_light = Some(AreaLightDesc {
        l: LIGHT_LE,
        two_sided: false,
        image: None,
    });
    vec![
        // floor
        quad(
            [
                p(552.8, 0.0, 0.0),
                p(0.0, 0.0, 0.0),
                p(0.0, 0.0, 559.2),
                p(549.6, 0.0, 559.2),
            ],
            M_WHITE,
            scene,
        ),
        // ceiling
        quad(
            [
                p(556.0, 548.8, 0.0),
                p(556.0, 548.8, 559.2),
                p(0.0, 548.8, 559.2),
                p(0.0, 548.8, 0.0),
            ],
            M_WHITE,
            scene,
        ),
        // back wall
        quad(
            [
                p(549.6, 0.0, 559.2),
                p(0.0, 0.0, 559.2),
                p(0.0, 548.8, 559.2),
                p(556.0, 548.8, 559.2),
            ],
            M_WHITE,
            scene,
        ),
        // right wall (x = 0, image right)
        quad(
            [
                p(0.0, 0.0, 559.2),
                p(0.0, 0.0, 0.0),
                p(0.0, 548.8, 0.0),
                p(0.0, 548.8, 559.2),
            ],
            M_GREEN,
            scene,
        ),
        // left wall (x ~ 556, image left); measured data, not planar
        quad(
            [
                p(552.8, 0.0, 0.0),
                p(549.6, 0.0, 559.2),
                p(556.0, 548.8, 559.2),
                p(556.0, 548.8, 0.0),
            ],
            M_RED,
            scene,
        ),
        light,
    ]
}

fn cornell_camera(scene: &str) -> CameraDesc {
    right_handed_camera(
        p(278.0, 273.0, -800.0),
        p(278.0, 273.0, 0.0),
        Vec3::Y,
        39.3077,
        scene,
    )
}

/// `cornell-box`: Cornell University's measured box with its two blocks.
pub fn cornell_box() -> SceneDesc {
    let name = "cornell-box";
    let mut shapes = cornell_room(name);
    shapes.push(quads(
        &[
            [
                p(130.0, 165.0, 65.0),
                p(82.0, 165.0, 225.0),
                p(240.0, 165.0, 272.0),
                p(290.0, 165.0, 114.0),
            ],
            [
                p(290.0, 0.0, 114.0),
                p(290.0, 165.0, 114.0),
                p(240.0, 165.0, 272.0),
                p(240.0, 0.0, 272.0),
            ],
            [
                p(130.0, 0.0, 65.0),
                p(130.0, 165.0, 65.0),
                p(290.0, 165.0, 114.0),
                p(290.0, 0.0, 114.0),
            ],
            [
                p(82.0, 0.0, 225.0),
                p(82.0, 165.0, 225.0),
                p(130.0, 165.0, 65.0),
                p(130.0, 0.0, 65.0),
            ],
            [
                p(240.0, 0.0, 272.0),
                p(240.0, 165.0, 272.0),
                p(82.0, 165.0, 225.0),
                p(82.0, 0.0, 225.0),
            ],
        ],
        M_WHITE,
        name,
    ));
    shapes.push(quads(
        &[
            [
                p(423.0, 330.0, 247.0),
                p(265.0, 330.0, 296.0),
                p(314.0, 330.0, 456.0),
                p(472.0, 330.0, 406.0),
            ],
            [
                p(423.0, 0.0, 247.0),
                p(423.0, 330.0, 247.0),
                p(472.0, 330.0, 406.0),
                p(472.0, 0.0, 406.0),
            ],
            [
                p(472.0, 0.0, 406.0),
                p(472.0, 330.0, 406.0),
                p(314.0, 330.0, 456.0),
                p(314.0, 0.0, 456.0),
            ],
            [
                p(314.0, 0.0, 456.0),
                p(314.0, 330.0, 456.0),
                p(265.0, 330.0, 296.0),
                p(265.0, 0.0, 296.0),
            ],
            [
                p(265.0, 0.0, 296.0),
                p(265.0, 330.0, 296.0),
                p(423.0, 330.0, 247.0),
                p(423.0, 0.0, 247.0),
            ],
        ],
        M_WHITE,
        name,
    ));
    assemble(
        name,
        cornell_camera(name),
        cornell_materials(),
        shapes,
        256,
        128,
    )
}

/// `cornell-caustics`: the room with a mirror sphere and a glass sphere (Jensen's scene).
pub fn cornell_caustics() -> SceneDesc {
    let name = "cornell-caustics";
    let mut shapes = cornell_room(name);
    shapes.push(sphere(p(400.0, 100.0, 380.0), 100.0, M_MIRROR, name));
    shapes.push(sphere(p(175.0, 90.0, 110.0), 90.0, M_GLASS, name));
    assemble(
        name,
        cornell_camera(name),
        cornell_materials(),
        shapes,
        256,
        128,
    )
}

/// `furnace`: a closed emitting and reflecting sphere seen from its centre; every pixel
/// converges to Le / (1 - albedo) = 2.
pub fn furnace() -> SceneDesc {
    let name = "furnace";
    let mut s = sphere(Vec3::ZERO, 100.0, 0, name);
    // The sphere's normal points outwards; emit (one-sided) towards the inside.
    s.reverse_orientation = true;
    s.area_light = Some(AreaLightDesc {
        l: Rgb::WHITE,
        two_sided: false,
        image: None,
    });
    let camera = right_handed_camera(Vec3::ZERO, Vec3::Z, Vec3::Y, 60.0, name);
    let materials = vec![MaterialDesc::Diffuse {
        reflectance: Rgb::splat(0.5),
    }];
    assemble(name, camera, materials, vec![s], 64, 64)
}

fn assemble(
    name: &str,
    camera: CameraDesc,
    materials: Vec<MaterialDesc>,
    shapes: Vec<ShapeDesc>,
    resolution: u32,
    spp: u32,
) -> SceneDesc {
    let (film, sampler, filter, integrator) = canonical_settings(name, resolution, spp);
    SceneDesc {
        camera,
        film,
        sampler,
        filter,
        integrator,
        materials,
        shading_normals: Vec::new(),
        textures: Vec::new(),
        shapes,
        objects: Vec::new(),
        instances: Vec::new(),
        lights: Vec::new(),
        warnings: Vec::new(),
        source: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle_normals(s: &ShapeDesc) -> Vec<Vec3> {
        match &s.geometry {
            Geometry::TriangleMesh {
                positions, indices, ..
            } => indices
                .chunks(3)
                .map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
                    (b - a).cross(c - a).normalize()
                })
                .collect(),
            _ => vec![],
        }
    }

    #[test]
    fn cornell_light_faces_down_and_has_the_stated_area() {
        let scene = cornell_box();
        let light = scene
            .shapes
            .iter()
            .find(|s| s.area_light.is_some())
            .unwrap();
        for n in triangle_normals(light) {
            assert!((n - Vec3::NEG_Y).length() < 1e-6);
        }
        if let Geometry::TriangleMesh {
            positions, indices, ..
        } = &light.geometry
        {
            let area: f32 = indices
                .chunks(3)
                .map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum();
            assert!((area - 13650.0).abs() < 1e-2);
        }
    }

    #[test]
    fn room_normals_point_into_the_room() {
        let scene = cornell_box();
        let centre = Vec3::new(278.0, 274.4, 279.6);
        for s in &scene.shapes[..5] {
            if let Geometry::TriangleMesh {
                positions, indices, ..
            } = &s.geometry
            {
                for (t, n) in indices.chunks(3).zip(triangle_normals(s)) {
                    let a = positions[t[0] as usize];
                    assert!((centre - a).dot(n) > 0.0);
                }
            }
        }
    }

    #[test]
    fn camera_puts_world_plus_x_on_the_image_left() {
        let scene = cornell_box();
        // Camera +x is raster right (pbrt); the red wall at x ~ 556 must land at camera -x.
        let v = scene
            .camera
            .camera_from_world
            .point(Vec3::new(550.0, 273.0, 300.0));
        assert!(v.x < 0.0 && v.z > 0.0);
    }
}
