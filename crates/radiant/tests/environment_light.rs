//! Image-based lighting end to end, from pbrt files that name images written here:
//! a convex Lambertian sphere under a constant-valued environment image (radiance
//! albedo · L on the sphere, L around it, for every integrator: path, photon mapping,
//! SPPM and radiosity), and a sphere of reflectance 1 under a sky with a sun, whose radiance at
//! each point is E(n) / π from the closed-form irradiance.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use radiant::Session;
use radiant::color::Rgb;
use radiant::image::{Image, ImageMeta, write_image};
use radiant::render::{Overrides, Progress};
use radiant::scene::parse_file;
use radiant_math::equal_area::square_to_sphere;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiant-envlight-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn render_file(scene: &Path, integrator: &str, spp: u32) -> Image {
    let desc = parse_file(scene).expect("scene parses");
    let session = Session::new(
        &desc,
        &Overrides {
            spp: Some(spp),
            integrator: Some(integrator.into()),
            ..Default::default()
        },
    )
    .expect("scene builds");
    session.render(&Progress::default()).film.image()
}

/// An orthographic view down -z of the unit sphere at the origin, `res`² pixels over
/// [-1.25, 1.25]², world +y up in the image, and `light` before `WorldBegin`'s world.
fn sphere_scene(res: u32, reflectance: f32, light: &str) -> String {
    format!(
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-1.25 1.25 -1.25 1.25]
Film "rgb" "integer xresolution" {res} "integer yresolution" {res}
PixelFilter "box" "float xradius" 0.5 "float yradius" 0.5
Sampler "independent"
WorldBegin
{light}
Material "diffuse" "rgb reflectance" [{reflectance} {reflectance} {reflectance}]
Shape "sphere" "float radius" 1
"#
    )
}

/// The world point seen through pixel (x, y) on the plane z = 0 (image x along world
/// -x or +x: the scenes here are symmetric in x).
fn pixel_point(x: f32, y: f32, res: u32) -> Vec2 {
    let s = 2.5 / res as f32;
    Vec2::new(-1.25 + s * x, 1.25 - s * y)
}

#[test]
fn convex_lambertian_under_a_constant_image_reflects_albedo_times_l() {
    let dir = temp_dir("furnace");
    let mut sky = Image::new(8, 8);
    for p in &mut sky.pixels {
        *p = Rgb::new(1.5, 1.0, 0.5);
    }
    write_image(dir.join("constant.exr"), &sky, &ImageMeta::default(), 0.0).unwrap();
    let res = 32;
    let scene = dir.join("furnace.pbrt");
    std::fs::write(
        &scene,
        sphere_scene(
            res,
            0.5,
            r#"LightSource "infinite" "string filename" "constant.exr" "float scale" 2"#,
        ),
    )
    .unwrap();
    let l = [3.0f64, 2.0, 1.0];
    // Radiosity's patches each get the irradiance of 144 environment samples: the
    // 2 % allow for that noise, which the pixels share (Gouraud interpolation), so
    // their spread understates it.
    for (integrator, spp, tolerance) in [
        ("path", 16, 0.0),
        ("sppm", 8, 0.0),
        ("photonmap", 4, 0.0),
        ("radiosity", 1, 0.02),
    ] {
        let img = render_file(&scene, integrator, spp);
        // Pixels wholly on the sphere or wholly beside it (by the corners' distance).
        let (mut on, mut off) = (Vec::new(), Vec::new());
        for y in 0..res {
            for x in 0..res {
                let r: Vec<f32> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .iter()
                    .map(|(dx, dy)| pixel_point(x as f32 + dx, y as f32 + dy, res).length())
                    .collect();
                let p = img.get(x as usize, y as usize);
                if r.iter().all(|&r| r < 1.0) {
                    on.push(p);
                } else if r.iter().all(|&r| r > 1.0) {
                    off.push(p);
                }
            }
        }
        assert!(on.len() > 300 && off.len() > 200);
        for c in 0..3 {
            // The background is the image's radiance exactly (nearest lookup of a
            // constant image).
            for p in &off {
                assert!(
                    (p[c] as f64 - l[c]).abs() < 1e-5,
                    "{integrator}: background {p:?}"
                );
            }
            let v: Vec<f64> = on.iter().map(|p| p[c] as f64).collect();
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let se = sd / n.sqrt();
            let exact = 0.5 * l[c];
            println!("{integrator} channel {c}: {mean:.5} ± {se:.5} vs {exact}");
            assert!(
                (mean - exact).abs() < 4.0 * se + tolerance * exact + 1e-6,
                "{integrator} channel {c}: mean {mean}, se {se}, exact {exact}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

const SKY: f32 = 0.5;
const GROUND: f32 = 0.1;
const SUN: f32 = 1500.0;
const SUN_HALF_ANGLE: f32 = 0.08;

/// The sun in the light's frame (+z up); in the y-z plane, so that the scene is
/// symmetric in x.
fn sun_light() -> Vec3 {
    Vec3::new(0.0, -0.55, 0.8).normalize()
}

fn sky(w: Vec3) -> f32 {
    if w.dot(sun_light()) >= SUN_HALF_ANGLE.cos() {
        SUN
    } else if w.z > 0.0 {
        SKY
    } else {
        GROUND
    }
}

/// Closed-form irradiance for a light-frame normal `n` (see
/// crates/render/tests/environment.rs); `None` when the sun straddles its horizon.
fn irradiance(n: Vec3) -> Option<f64> {
    let pi = std::f64::consts::PI;
    let s = sun_light();
    let cos_ns = n.dot(s) as f64;
    let sin_a = (SUN_HALF_ANGLE as f64).sin();
    if cos_ns.abs() < sin_a + 0.01 {
        return None;
    }
    let base =
        pi * SKY as f64 * (1.0 + n.z as f64) / 2.0 + pi * GROUND as f64 * (1.0 - n.z as f64) / 2.0;
    Some(base + (SUN - SKY) as f64 * pi * sin_a * sin_a * cos_ns.max(0.0))
}

#[test]
fn white_sphere_under_a_sky_shows_the_closed_form_irradiance() {
    let dir = temp_dir("sky");
    let size = 128;
    let mut img = Image::new(size, size);
    let k = 6;
    for y in 0..size {
        for x in 0..size {
            let mut s = 0.0;
            for a in 0..k {
                for b in 0..k {
                    let st = Vec2::new(
                        (x as f32 + (a as f32 + 0.5) / k as f32) / size as f32,
                        (y as f32 + (b as f32 + 0.5) / k as f32) / size as f32,
                    );
                    s += sky(square_to_sphere(st));
                }
            }
            img.set(x, y, Rgb::splat(s / (k * k) as f32));
        }
    }
    write_image(dir.join("sky.pfm"), &img, &ImageMeta::default(), 0.0).unwrap();
    let res = 40;
    let scene = dir.join("sky.pbrt");
    // Rotate -90 about x takes the light's +z (up) to world +y and its -y to world +z:
    // the sun is up and in front, towards the camera.
    std::fs::write(
        &scene,
        sphere_scene(
            res,
            1.0,
            r#"AttributeBegin
Rotate -90 1 0 0
LightSource "infinite" "string filename" "sky.pfm"
AttributeEnd"#,
        ),
    )
    .unwrap();
    let render = render_file(&scene, "path", 64);
    // Expected pixel value: the mean of E(n)/π over 4 x 4 points of the pixel, with
    // the world normal (x, y, z) in the light's frame (x, -z, y).
    let mut tiles: std::collections::BTreeMap<(u32, u32), Vec<(f64, f64)>> = Default::default();
    for y in 0..res {
        for x in 0..res {
            let mut expected = 0.0;
            let mut ok = true;
            for a in 0..4 {
                for b in 0..4 {
                    let q = pixel_point(
                        x as f32 + (a as f32 + 0.5) / 4.0,
                        y as f32 + (b as f32 + 0.5) / 4.0,
                        res,
                    );
                    let r2 = q.length_squared();
                    if r2 > 0.95 {
                        ok = false;
                        continue;
                    }
                    let n = Vec3::new(q.x, q.y, (1.0 - r2).sqrt());
                    match irradiance(Vec3::new(n.x, -n.z, n.y)) {
                        Some(e) => expected += e / std::f64::consts::PI / 16.0,
                        None => ok = false,
                    }
                }
            }
            if ok {
                let got = render.get(x as usize, y as usize).g as f64;
                tiles
                    .entry((x / 5, y / 5))
                    .or_default()
                    .push((got, expected));
            }
        }
    }
    let mut checked = 0;
    for (tile, v) in &tiles {
        if v.len() < 10 {
            continue;
        }
        checked += 1;
        let n = v.len() as f64;
        let res_mean = v.iter().map(|(g, e)| g - e).sum::<f64>() / n;
        let sd = (v
            .iter()
            .map(|(g, e)| (g - e - res_mean).powi(2))
            .sum::<f64>()
            / (n - 1.0))
            .sqrt();
        let expected = v.iter().map(|(_, e)| e).sum::<f64>() / n;
        println!(
            "tile {tile:?}: {n} pixels, mean {expected:.4}, residual {res_mean:+.4} (se {:.4})",
            sd / n.sqrt()
        );
        assert!(
            res_mean.abs() < 5.0 * sd / n.sqrt() + 0.01 * expected,
            "tile {tile:?}: mean residual {res_mean} (sd {sd}, {n} pixels), expected mean {expected}"
        );
    }
    println!("{checked} tiles within 5 standard errors + 1 % of E(n)/π");
    assert!(checked >= 20, "{checked} tiles checked");
    std::fs::remove_dir_all(&dir).ok();
}
