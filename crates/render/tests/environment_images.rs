//! Environment images are read when the world is built: their pixels and scale reach
//! the light, `illuminance` sets the scale, and a missing or non-square image is an
//! error at the `filename` parameter.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use radiant_math::PI;
use radiant_math::color::Rgb;
use radiant_math::equal_area::square_to_sphere;
use radiant_render::light::Light;
use radiant_render::world::World;
use radiant_scene::{parse_file, parse_str};

fn corpus(name: &str) -> PathBuf {
    radiant_testkit::repo_path("tests/scenes/malformed/world").join(name)
}

/// A 4 × 4 PFM whose pixel k (row-major from the top) is (k+1)·(1, 2, ½).
fn write_sky(dir: &Path) -> Vec<Rgb> {
    let mut bytes = b"PF\n4 4\n-1.0\n".to_vec();
    let mut pixels = vec![Rgb::BLACK; 16];
    for y in (0..4).rev() {
        for x in 0..4 {
            let v = (y * 4 + x + 1) as f32;
            pixels[y * 4 + x] = Rgb::new(v, 2.0 * v, 0.5 * v);
            for c in [v, 2.0 * v, 0.5 * v] {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join("sky.pfm"), bytes).unwrap();
    pixels
}

fn infinite_scale(world: &World, k: usize) -> Rgb {
    match &world.lights[k] {
        Light::Infinite { radiance, map, .. } => {
            assert_eq!(map.as_ref().expect("an image").size(), 4);
            *radiance
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn images_reach_the_light_with_scale_and_illuminance() {
    let dir = std::env::temp_dir().join(format!("radiant-envimage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pixels = write_sky(&dir);
    let scene = parse_str(
        "WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.pfm\" \"float scale\" 3\n\
         LightSource \"infinite\" \"string filename\" \"sky.pfm\" \"float illuminance\" 7\n",
        "t.pbrt",
        &dir,
    )
    .unwrap();
    let (world, _) = World::build(&scene).unwrap();
    assert_eq!(infinite_scale(&world, 0), Rgb::splat(3.0));
    // The pixel straight up (the square's centre) reads back with the scale.
    let up = match &world.lights[0] {
        Light::Infinite { map: Some(m), .. } => m.radiance(Vec3::Z),
        _ => unreachable!(),
    };
    let centre = [5, 6, 9, 10].map(|k| pixels[k] * 3.0);
    assert!(centre.contains(&up), "{up:?}");
    // illuminance: Σ over pixels above the horizon of Y cos θ · 4π / 16 = 7.
    let scale = infinite_scale(&world, 1);
    let mut e = 0.0;
    for (k, p) in pixels.iter().enumerate() {
        let w = square_to_sphere(Vec2::new(
            ((k % 4) as f32 + 0.5) / 4.0,
            ((k / 4) as f32 + 0.5) / 4.0,
        ));
        if w.z > 0.0 {
            e += (*p * scale).luminance() * w.z * 4.0 * PI / 16.0;
        }
    }
    assert!((e - 7.0).abs() < 1e-4, "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn missing_and_non_square_images_fail_at_the_filename() {
    for (scene, line, column, words) in [
        (
            "missing_envmap.pbrt",
            3,
            26,
            &["cannot read environment image", "no-such-sky.exr"][..],
        ),
        (
            "nonsquare_envmap.pbrt",
            3,
            5,
            &["nonsquare-sky.pfm", "4x2", "square", "imgtool makeequiarea"][..],
        ),
    ] {
        let desc = parse_file(&corpus(scene)).unwrap_or_else(|e| panic!("{scene}: {e}"));
        let message = World::build(&desc).map(|_| ()).unwrap_err().to_string();
        let expected = format!("{}:{line}:{column}: error:", corpus(scene).display());
        assert!(message.starts_with(&expected), "{scene}: {message}");
        for w in words {
            assert!(message.contains(w), "{scene}: lacks \"{w}\": {message}");
        }
    }
}
