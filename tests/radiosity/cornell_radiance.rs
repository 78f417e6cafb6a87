//! The diffuse Cornell box of `cornell_irradiance_radiance.json` (variant "brief": the
//! idealised 556 x 548.8 x 559 mm box open at z = 0, the measured blocks, a
//! non-reflecting light at y = 548.7): irradiance at Radiance's floor and back-wall
//! sensors from the meshed, solved scene.

use std::ops::ControlFlow;

use radiant::color::Rgb;
use radiant::math::{DVec3, Vec3};
use radiant::radiosity::irradiance::{GatherSettings, irradiance_at};
use radiant::radiosity::scene::RadiosityScene;
use radiant::radiosity::settings::{RadiositySettings, SolverKind};
use radiant::radiosity::solve::{Solution, solve};
use radiant::radiosity::world_visibility::FaceVisibility;
use radiant::render::light::SceneSphere;
use radiant::scene::builtin::cornell_box;
use radiant::scene::{AreaLightDesc, FileLoc, Geometry, MaterialDesc, SceneDesc, ShapeDesc};
use rayon::prelude::*;
use serde_json::Value;

use crate::common::{shared_json, vec3};

fn rgb(v: &Value) -> Rgb {
    Rgb::new(
        v[0].as_f64().unwrap() as f32,
        v[1].as_f64().unwrap() as f32,
        v[2].as_f64().unwrap() as f32,
    )
}

fn quads(list: &[[Vec3; 4]], material: u32, light: Option<Rgb>) -> ShapeDesc {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for q in list {
        let base = positions.len() as u32;
        positions.extend_from_slice(q);
        indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    ShapeDesc {
        geometry: Geometry::TriangleMesh {
            positions,
            indices,
            normals: None,
            uvs: None,
        },
        render_from_object: Default::default(),
        reverse_orientation: false,
        material,
        area_light: light.map(|l| AreaLightDesc {
            l,
            two_sided: false,
        }),
        loc: FileLoc::builtin("cornell_irradiance_radiance"),
    }
}

/// A block: the top quad at `height` (counter-clockwise from above) and four sides
/// facing out, no bottom.
fn block(top: &[Vec3; 4], height: f32) -> Vec<[Vec3; 4]> {
    let up = |p: Vec3| Vec3::new(p.x, height, p.z);
    let mut faces = vec![top.map(up)];
    for k in 0..4 {
        let (p, q) = (top[(k + 1) % 4], top[k]);
        faces.push([p, up(p), up(q), q]);
    }
    faces
}

/// The scene of the data file, in code: materials white, red, green, light.
pub fn radiance_cornell(data: &Value) -> SceneDesc {
    let scene = &data["scene"];
    let albedo = &scene["albedo_rgb"];
    let [w, h, d] = [0, 1, 2].map(|k| scene["box_mm"][k].as_f64().unwrap() as f32);
    let p = Vec3::new;
    let xz = |v: &Value| -> [Vec3; 4] {
        std::array::from_fn(|k| {
            p(
                v[k][0].as_f64().unwrap() as f32,
                0.0,
                v[k][1].as_f64().unwrap() as f32,
            )
        })
    };
    let light = &scene["light_rect"];
    let (x0, x1) = (
        light["x"][0].as_f64().unwrap() as f32,
        light["x"][1].as_f64().unwrap() as f32,
    );
    let (z0, z1) = (
        light["z"][0].as_f64().unwrap() as f32,
        light["z"][1].as_f64().unwrap() as f32,
    );
    let y_light = 548.7;
    let mut desc = cornell_box();
    desc.materials = vec![
        MaterialDesc::Diffuse {
            reflectance: rgb(&albedo["white"]),
        },
        MaterialDesc::Diffuse {
            reflectance: rgb(&albedo["red"]),
        },
        MaterialDesc::Diffuse {
            reflectance: rgb(&albedo["green"]),
        },
        MaterialDesc::Diffuse {
            reflectance: Rgb::BLACK,
        },
    ];
    // Floor, back wall, ceiling (wound so that the normals point into the room).
    let mut white = vec![
        [
            p(w, 0.0, 0.0),
            p(0.0, 0.0, 0.0),
            p(0.0, 0.0, d),
            p(w, 0.0, d),
        ],
        [p(w, 0.0, d), p(0.0, 0.0, d), p(0.0, h, d), p(w, h, d)],
    ];
    white.push([p(w, h, 0.0), p(w, h, d), p(0.0, h, d), p(0.0, h, 0.0)]);
    white.extend(block(&xz(&scene["short_block_top_xz_y165"]), 165.0));
    white.extend(block(&xz(&scene["tall_block_top_xz_y330"]), 330.0));
    desc.shapes = vec![
        quads(&white, 0, None),
        quads(
            &[[p(w, 0.0, 0.0), p(w, 0.0, d), p(w, h, d), p(w, h, 0.0)]],
            1,
            None,
        ),
        quads(
            &[[
                p(0.0, 0.0, d),
                p(0.0, 0.0, 0.0),
                p(0.0, h, 0.0),
                p(0.0, h, d),
            ]],
            2,
            None,
        ),
        quads(
            &[[
                p(x1, y_light, z0),
                p(x1, y_light, z1),
                p(x0, y_light, z1),
                p(x0, y_light, z0),
            ]],
            3,
            Some(rgb(&scene["light_radiance_rgb"])),
        ),
    ];
    desc.lights.clear();
    desc
}

/// (sensor point, normal, Radiance's E) of one grid, skipping points under the blocks.
fn sensors(grid: &Value) -> Vec<(DVec3, DVec3, [f64; 3])> {
    grid.as_array()
        .unwrap()
        .iter()
        .filter(|s| !s["E"].is_null())
        .map(|s| {
            let e = &s["E"];
            (
                vec3(&s["p"]),
                vec3(&s["n"]),
                [0, 1, 2].map(|k| e[k].as_f64().unwrap()),
            )
        })
        .collect()
}

/// Relative error per sensor and band of the irradiance computed from `solution` at
/// Radiance's sensor points of `grid`.
fn relative_errors(
    scene: &RadiosityScene,
    solution: &Solution,
    vis: &FaceVisibility,
    grid: &Value,
) -> Vec<[f64; 3]> {
    sensors(grid)
        .par_iter()
        .map(|(p, n, reference)| {
            // Sensors sit 0.01 mm off the surface along the normal, as in the data.
            let x = *p + 0.01 * *n;
            let e = irradiance_at(
                &scene.patches,
                &solution.radiosity,
                x,
                *n,
                vis,
                GatherSettings::default(),
            );
            std::array::from_fn(|b| e[b] / reference[b] - 1.0)
        })
        .collect()
}

/// Mean, 90th percentile and maximum of the absolute relative errors.
fn stats(errors: &[[f64; 3]]) -> (f64, f64, f64) {
    let mut all: Vec<f64> = errors.iter().flatten().map(|e| e.abs()).collect();
    all.sort_by(f64::total_cmp);
    let mean = all.iter().sum::<f64>() / all.len() as f64;
    (mean, all[all.len() * 9 / 10], all[all.len() - 1])
}

/// The solved scene at the test's resolution: 600 mm^2 patches (3,361 patches),
/// progressive refinement with one-point ray-cast factors to 0.1 % unshot power.
fn solved() -> (RadiosityScene, FaceVisibility, Solution, Value) {
    let data = shared_json("cornell_irradiance_radiance.json");
    let desc = radiance_cornell(&data);
    let settings = RadiositySettings {
        max_patch_area: Some(600.0),
        solver: SolverKind::Progressive,
        tolerance: 1e-3,
        ..RadiositySettings::default()
    };
    let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
    let vis = FaceVisibility::new(&scene);
    let sphere = SceneSphere {
        center: Vec3::new(278.0, 274.4, 279.5),
        radius: 500.0,
    };
    let solution = solve(&scene, &[], sphere, &settings, &vis, |_| {
        ControlFlow::Continue(())
    })
    .unwrap();
    (scene, vis, solution, data)
}

#[test]
fn irradiance_matches_radiance_on_floor_and_back_wall() {
    // Variant "brief" (the only one in the file). Irradiance at each sensor is
    // evaluated from the solved radiosities with the exact contour factor of every
    // patch and shadow rays (16 x 16 per light patch, 2 x 2 per other triangle), so the
    // direct light is exact up to its penumbra sampling and only the indirect part
    // carries discretisation error.
    let (scene, vis, solution, data) = solved();
    assert!(solution.converged);
    let variant = &data["variants"]["brief"];
    let (floor_mean, floor_p90, floor_max) =
        stats(&relative_errors(&scene, &solution, &vis, &variant["floor"]));
    let (back_mean, back_p90, back_max) = stats(&relative_errors(
        &scene,
        &solution,
        &vis,
        &variant["back_wall"],
    ));
    eprintln!(
        "{} patches: floor mean {floor_mean:.4} p90 {floor_p90:.4} max {floor_max:.4}; back wall mean {back_mean:.4} p90 {back_p90:.4} max {back_max:.4}",
        scene.patches.len()
    );
    // Means over 294 (floor) and 363 (back wall) sensor-band values: measured 0.87 %
    // and 0.67 %; Radiance's own standard errors are 0.1-0.3 %.
    assert!(floor_mean < 0.01 && back_mean < 0.01);
    // Nine values in ten within 3 % (measured 2.1 % and 1.2 %).
    assert!(floor_p90 < 0.03 && back_p90 < 0.03);
    // The largest errors, measured 17.3 % (floor) and 6.0 % (back wall), have two
    // causes. (1) The floor sensor 3 mm in front of the short block's face, in its
    // shadow, where the constant radiosity of the block's lowest patches overstates
    // the darker strip at its base (+8 to +17 % in green and blue, where the values
    // are 0.004-0.014 W/m^2, depending on where patch edges fall). (2) Around x = 228-278 mm west of and behind the tall
    // block (floor and back-wall base) Radiance is 2.5-5.7 % brighter than both this
    // solution and radiant's path tracer with 3 million paths per sensor
    // (`radiance_discrepancy_is_shared_by_the_path_tracer`), which agree there to 1 %.
    assert!(floor_max < 0.2 && back_max < 0.07);
}

/// Radiant's path tracer at the sensors where this solution departs most from
/// Radiance: it departs from Radiance too, and agrees with the radiosity solution.
/// Slow (3 million paths per sensor, 20 s on 2 cores): run with `--ignored`.
#[test]
#[ignore]
fn radiance_discrepancy_is_shared_by_the_path_tracer() {
    use radiant::render::integrator::{PathSettings, path};
    use radiant::render::sampler::PixelSample;
    use radiant::render::world::World;
    let (scene, vis, solution, data) = solved();
    let desc = radiance_cornell(&data);
    let (world, _) = World::build(&desc).unwrap();
    let settings = PathSettings {
        max_depth: 100,
        rr_depth: 5,
    };
    let variant = &data["variants"]["brief"];
    let wanted = [
        [278.0, 24.945, 559.0],
        [227.45, 24.945, 559.0],
        [278.0, 0.0, 279.5],
        [278.0, 0.0, 533.59],
    ];
    let mut all = sensors(&variant["floor"]);
    all.extend(sensors(&variant["back_wall"]));
    for (p, n, reference) in all.into_iter().filter(|(p, _, _)| {
        wanted
            .iter()
            .any(|w| (DVec3::from_array(*w) - *p).length() < 0.1)
    }) {
        let x = p + 0.01 * n;
        let frame = radiant::math::Frame::from_normal(n.as_vec3());
        let count = 3_000_000u32;
        let sum = (0..count)
            .into_par_iter()
            .map(|i| {
                let mut s = PixelSample::for_stream(radiant::scene::SamplerKind::Sobol, 7, 1, i);
                let d = frame.to_world(radiant::math::sampling::cosine_hemisphere(s.get_2d()));
                let (l, _) = path::radiance(
                    &world,
                    &settings,
                    radiant::render::geometry::Ray::new(x.as_vec3(), d),
                    &mut s,
                );
                [l.r as f64, l.g as f64, l.b as f64]
            })
            .reduce(|| [0.0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        let traced = sum.map(|v| std::f64::consts::PI * v / count as f64);
        let ours = irradiance_at(
            &scene.patches,
            &solution.radiosity,
            x,
            n,
            &vis,
            GatherSettings::default(),
        );
        for b in 0..3 {
            eprintln!(
                "{p:?} band {b}: Radiance {:.5} path {:.5} radiosity {:.5}",
                reference[b], traced[b], ours[b]
            );
            // Path tracing noise here is 0.1-0.2 %; the radiosity's own error below 1 %.
            assert!((ours[b] / traced[b] - 1.0).abs() < 0.015);
            // Measured: 1.4 to 5.7 % below Radiance.
            assert!(traced[b] / reference[b] - 1.0 < -0.01);
        }
    }
}
