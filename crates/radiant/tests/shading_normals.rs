//! Bump and normal maps: the tilt of a known height field against its closed form,
//! a neutral normal map leaving the image unchanged to the bit, and a white furnace
//! with a bumpy sphere staying at or below 1.

use std::path::{Path, PathBuf};

use glam::Vec3;
use radiant::image::Image;
use radiant::render::geometry::Ray;
use radiant::render::world::World;
use radiant::scene::{SceneDesc, parse_str};

mod common;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "radiant-shading-normals-{}-{name}",
        std::process::id()
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn parse_in(text: &str, dir: &Path) -> SceneDesc {
    parse_str(text, "t.pbrt", dir).unwrap_or_else(|e| panic!("{e}"))
}

/// A 2 × 2 square in z = 0 facing +z, u along +x and v along +y over [0, 1]², so
/// ∂p/∂u = (2, 0, 0) and ∂p/∂v = (0, 2, 0); with `normals` it carries vertex normals
/// (all +z), which takes the interpolated-normal tangents.
fn square(material: &str, normals: bool) -> String {
    let n = if normals {
        r#""normal N" [0 0 1 0 0 1 0 0 1 0 0 1]"#
    } else {
        ""
    };
    format!(
        r#"WorldBegin
{material}
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
  "point2 uv" [0 0 1 0 1 1 0 1] {n}
"#
    )
}

fn hit_normal(desc: &SceneDesc, x: f32, y: f32) -> (Vec3, Vec3) {
    let (world, _) = World::build(desc).unwrap_or_else(|e| panic!("{e}"));
    let ray = Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0));
    let hit = world.intersect(&ray, f32::INFINITY).expect("the square");
    (hit.ns, hit.ng)
}

#[test]
fn bump_map_of_a_linear_ramp_tilts_the_normal_by_the_closed_form_angle() {
    let dir = temp_dir("ramp");
    // h = k u over a square of side 2: the height rises k / 2 per unit length along
    // +x, so the displaced surface's normal is (−k/2, 0, 1) normalised.
    for k in [0.1f32, 0.5, 2.0] {
        for normals in [false, true] {
            let material = format!(
                r#"Texture "h" "float" "bilerp" "float v00" 0 "float v01" 0 "float v10" {k} "float v11" {k}
Material "diffuse" "texture displacement" "h""#
            );
            let desc = parse_in(&square(&material, normals), &dir);
            for (x, y) in [(0.1, 0.2), (-0.7, 0.5), (0.6, -0.8)] {
                let (ns, ng) = hit_normal(&desc, x, y);
                assert_eq!(ng, Vec3::Z, "the geometric normal stays the shape's");
                let want = Vec3::new(-k / 2.0, 0.0, 1.0).normalize();
                let angle = ns.dot(want).clamp(-1.0, 1.0).acos();
                assert!(
                    angle < 1e-3,
                    "k {k} normals {normals}: ns {ns}, want {want} (off by {angle} rad)"
                );
            }
        }
    }
    // A constant displacement moves the surface but does not tilt it.
    let desc = parse_in(
        &square(r#"Material "diffuse" "float displacement" 0.3"#, false),
        &dir,
    );
    assert_eq!(hit_normal(&desc, 0.1, 0.2).0, Vec3::Z);
}

fn write_constant_map(path: &Path, rgb: [f32; 3]) {
    let mut img = Image::new(4, 4);
    for p in &mut img.pixels {
        *p = radiant::color::Rgb::new(rgb[0], rgb[1], rgb[2]);
    }
    radiant::image::pfm::write_pfm(path, &img).unwrap();
}

#[test]
fn a_normal_map_tilts_the_normal_in_the_tangent_frame() {
    let dir = temp_dir("tilted");
    // RGB (0.75, 0.5, 1) is the tangent-space normal (0.5, 0, 1): tilted towards
    // ∂p/∂u = +x.
    write_constant_map(&dir.join("tilt.pfm"), [0.75, 0.5, 1.0]);
    let desc = parse_in(
        &square(r#"Material "diffuse" "string normalmap" "tilt.pfm""#, false),
        &dir,
    );
    let (ns, _) = hit_normal(&desc, 0.3, -0.4);
    let want = Vec3::new(0.5, 0.0, 1.0).normalize();
    assert!((ns - want).length() < 1e-5, "ns {ns}, want {want}");
}

fn render(path: &Path, spp: u32) -> Image {
    common::render_file(path, spp)
}

const LIT_SCENE: &str = r#"LookAt 0 -4 3  0 0 0  0 0 1
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
Sampler "sobol"
Integrator "path" "integer maxdepth" 4
WorldBegin
LightSource "distant" "point3 from" [1 -1 3] "point3 to" [0 0 0] "rgb L" [2 2 2]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [4 4 4]
  Translate 0 0 3
  Shape "disk" "float radius" 0.5
AttributeEnd
"#;

#[test]
fn a_neutral_normal_map_leaves_the_image_unchanged_to_the_bit() {
    let dir = temp_dir("neutral");
    write_constant_map(&dir.join("flat.pfm"), [0.5, 0.5, 1.0]);
    let body = |material: &str| {
        format!(
            r#"{LIT_SCENE}
AttributeBegin
  {material}
  Shape "sphere" "float radius" 0.8
AttributeEnd
{material}
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [-3 -3 -0.8  3 -3 -0.8  3 3 -0.8  -3 3 -0.8]
  "point2 uv" [0 0 1 0 1 1 0 1]
"#
        )
    };
    let plain = dir.join("plain.pbrt");
    let mapped = dir.join("mapped.pbrt");
    std::fs::write(
        &plain,
        body(r#"Material "coateddiffuse" "float roughness" 0.2"#),
    )
    .unwrap();
    std::fs::write(
        &mapped,
        body(r#"Material "coateddiffuse" "float roughness" 0.2 "string normalmap" "flat.pfm""#),
    )
    .unwrap();
    let (a, b) = (render(&plain, 8), render(&mapped, 8));
    assert!(a.pixels.iter().any(|p| p.r > 0.0), "the scene is lit");
    let bits = |img: &Image| {
        img.pixels
            .iter()
            .flat_map(|p| [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()])
            .collect::<Vec<u32>>()
    };
    assert!(
        bits(&a) == bits(&b),
        "a (0.5, 0.5, 1) normal map changed the image"
    );
}

#[test]
fn white_furnace_with_a_bumpy_sphere_stays_at_or_below_one() {
    let dir = temp_dir("furnace");
    let path = dir.join("furnace.pbrt");
    // A strongly bumped white Lambertian sphere under a uniform sky of radiance 1: the
    // shading normals tilt far from the geometric ones, and no pixel may reflect more
    // than arrives.
    std::fs::write(
        &path,
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-1.25 1.25 -1.25 1.25]
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
PixelFilter "box" "float xradius" 0.5 "float yradius" 0.5
Sampler "independent"
Integrator "path" "integer maxdepth" 50
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Texture "bumps" "float" "wrinkled" "float roughness" 0.7
Texture "h" "float" "scale" "texture tex" "bumps" "float scale" 0.2
Material "diffuse" "rgb reflectance" [1 1 1] "texture displacement" "h"
Scale 4 4 4
Shape "sphere" "float radius" 0.25
"#,
    )
    .unwrap();
    let spp = 256;
    let img = render(&path, spp);
    // Per-pixel noise at this spp is well under 5 %; a furnace violation by bump
    // mapping (light leaking around the tilted normals) shows as whole regions above.
    let max = img.pixels.iter().map(|p| p.r).fold(0.0f32, f32::max);
    let mean = img.pixels.iter().map(|p| p.r as f64).sum::<f64>() / img.pixels.len() as f64;
    assert!(max <= 1.05, "brightest pixel {max}");
    assert!(mean <= 1.0 + 1e-3, "mean {mean}");
    // The bumps cost energy where shading and geometric hemispheres disagree: the
    // image is not trivially white.
    assert!(mean < 0.999, "mean {mean}: the bump map had no effect");
}

/// The bump map's finite differences span half the pixel footprint (pbrt-v4's
/// du = (|∂u/∂x| + |∂u/∂y|) / 2): next to a step in the height a camera ray with a
/// wide footprint sees the step and tilts, while a lookup without a footprint
/// (step 0.0005) does not; far from the step both stay flat.
#[test]
fn bump_differences_span_the_pixel_footprint() {
    use radiant::render::camera::RaySpread;
    let dir = temp_dir("footprint-step");
    // Checks of width 1/2 in u: the height steps from 0 to 0.05 at u = 1/2 (x = 0).
    let desc = parse_in(
        &square(
            "Texture \"steps\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 1 \
               \"float tex1\" 0 \"float tex2\" 0.05\n\
             Material \"diffuse\" \"texture displacement\" \"steps\"",
            false,
        ),
        &dir,
    );
    let (mut world, _) = World::build(&desc).unwrap_or_else(|e| panic!("{e}"));
    // 0.1 scene units per pixel: ∂u/∂x and ∂u/∂y of about 0.05 on this square.
    world.ray_spread = RaySpread {
        angle: 0.0,
        offset: 0.1,
    };
    let down = Vec3::new(0.0, 0.0, -1.0);
    let near_step = Ray::new(Vec3::new(-0.02, 0.3, 1.0), down);
    let point = world.intersect(&near_step, f32::INFINITY).unwrap();
    assert!(point.ns.z > 1.0 - 1e-6, "no footprint: {:?}", point.ns);
    let wide = world
        .intersect_with_footprint(&near_step, f32::INFINITY, 0.0)
        .unwrap();
    assert!(
        wide.ns.z < 0.99 && wide.ns.x < -0.1,
        "with a footprint the step tilts the normal away from +u: {:?}",
        wide.ns
    );
    let far = Ray::new(Vec3::new(-0.6, 0.3, 1.0), down);
    let flat = world
        .intersect_with_footprint(&far, f32::INFINITY, 0.0)
        .unwrap();
    assert!(flat.ns.z > 1.0 - 1e-6, "far from the step: {:?}", flat.ns);
    std::fs::remove_dir_all(&dir).ok();
}
