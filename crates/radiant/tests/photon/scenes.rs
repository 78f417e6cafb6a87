//! Scenes, crops and the reference shared by the photon tests.

use glam::Vec3;
use radiant::color::Rgb;
use radiant::image::{Crop, Image, read_image};
use radiant::render::Progress;
use radiant::render::integrator::photon::{PhotonMaps, PhotonSettings};
use radiant::render::world::World;
use radiant::scene::builtin::{LIGHT_LE, cornell_caustics};
use radiant::scene::params::ParamSet;
use radiant::scene::{LightDesc, SamplerKind, SceneDesc, ShapeDesc};
use radiant_testkit::fixtures;

use crate::common;

/// The caustic of the glass sphere in 256 × 256 pixel coordinates (x0, y0, x1, y1),
/// located from the reference: the bright ball-lens focus on the floor in front of and
/// right of the sphere spans pixels x 161..191, y 232..243; the crop adds a margin and
/// is aligned to multiples of 4 so that it survives 4 × 4 downsampling.
pub const CAUSTIC_CROP: (usize, usize, usize, usize) = (160, 232, 192, 244);

/// Floor in the front left of the image, away from the glass's caustic (its pixels see
/// the floor directly).
pub const FLOOR_CROP: (usize, usize, usize, usize) = (32, 232, 128, 252);

/// A crop given in 256 × 256 coordinates, at resolution `res`.
pub fn crop_at(c: (usize, usize, usize, usize), res: usize) -> Crop {
    let f = 256 / res;
    let (x0, y0, x1, y1) = c;
    Crop {
        x0: x0 / f,
        y0: y0 / f,
        x1: x1 / f,
        y1: y1 / f,
    }
}

/// Box-downsampled reference: a pixel of a low-resolution render estimates exactly the
/// mean of the reference pixels it covers (one-pixel box filter).
pub fn reference(res: usize) -> Image {
    let full = read_image(common::shared("refs/cornell-caustics-256-ref.exr")).expect("reference");
    let f = full.width / res;
    let mut out = Image::new(res, res);
    for y in 0..res {
        for x in 0..res {
            let mut s = Rgb::BLACK;
            for j in 0..f {
                for i in 0..f {
                    s += full.get(x * f + i, y * f + j);
                }
            }
            out.set(x, y, s * (1.0 / (f * f) as f32));
        }
    }
    out
}

/// cornell-caustics with a front wall at z = 0 (facing the room): no photon escapes.
pub fn closed_cornell_caustics() -> SceneDesc {
    let mut desc = cornell_caustics();
    // The white of the other walls.
    let white = &desc.shapes[0];
    let wall = ShapeDesc::quads(
        &[[
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(552.8, 0.0, 0.0),
            Vec3::new(556.0, 548.8, 0.0),
            Vec3::new(0.0, 548.8, 0.0),
        ]],
        white.material,
        white.loc.clone(),
    );
    desc.shapes.push(wall);
    desc
}

/// Replaces the area light by `light` (the luminaire stays, without emission).
pub fn relit(mut desc: SceneDesc, light: LightDesc) -> SceneDesc {
    for s in &mut desc.shapes {
        s.area_light = None;
    }
    desc.lights = vec![light];
    desc
}

pub fn point_light(desc: &SceneDesc) -> LightDesc {
    LightDesc::Point {
        position: Vec3::new(278.0, 540.0, 279.5),
        intensity: LIGHT_LE * 13650.0,
        loc: desc.camera.loc.clone(),
    }
}

pub fn spot_light(desc: &SceneDesc) -> LightDesc {
    LightDesc::Spot {
        position: Vec3::new(278.0, 540.0, 279.5),
        direction: -Vec3::Y,
        intensity: LIGHT_LE * 13650.0,
        cos_falloff_start: 40f32.to_radians().cos(),
        cos_total_width: 50f32.to_radians().cos(),
        loc: desc.camera.loc.clone(),
    }
}

/// Floor and spheres of cornell-caustics under the open sky: a distant light (sun) and
/// a constant environment.
pub fn open_sky() -> SceneDesc {
    let mut desc = cornell_caustics();
    let n = desc.shapes.len();
    // The floor, then the two spheres (the last two shapes).
    desc.shapes = vec![
        desc.shapes[0].clone(),
        desc.shapes[n - 2].clone(),
        desc.shapes[n - 1].clone(),
    ];
    for s in &mut desc.shapes {
        s.area_light = None;
    }
    let loc = desc.camera.loc.clone();
    desc.lights = vec![
        LightDesc::Distant {
            direction: Vec3::new(0.3, -1.0, 0.2),
            radiance: Rgb::new(3.0, 2.5, 2.0),
            loc: loc.clone(),
        },
        LightDesc::Infinite {
            radiance: Rgb::splat(0.05),
            image: None,
            loc,
        },
    ];
    desc
}

pub fn maps(world: &World, settings: PhotonSettings) -> PhotonMaps {
    PhotonMaps::build(
        world,
        &settings,
        SamplerKind::Sobol,
        7,
        &Progress::default(),
    )
}

/// `desc` with the integrator `name` and `params`, at `res` × `res` pixels (None:
/// the scene's resolution).
pub fn with_integrator(
    desc: SceneDesc,
    name: &str,
    params: ParamSet,
    res: Option<u32>,
) -> SceneDesc {
    let desc = fixtures::with_integrator(desc, name, params);
    match res {
        Some(res) => fixtures::with_resolution(desc, res, res),
        None => desc,
    }
}

/// Mean and standard deviation over the pixels of one channel.
pub fn mean_and_sd(img: &Image, c: usize) -> (f64, f64) {
    let v: Vec<f64> = img.pixels.iter().map(|p| p[c] as f64).collect();
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (
        m,
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt(),
    )
}
