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
    let display = solution.display_radiosity(&scene.patches);
    let radiosity = if std::env::var("AMBIENT").is_ok() { &display } else { &solution.radiosity };
    sensors(grid)
        .par_iter()
        .map(|(p, n, reference)| {
            // Sensors sit 0.01 mm off the surface along the normal, as in the data.
            let x = *p + 0.01 * *n;
            let e = irradiance_at(
                &scene.patches,
                radiosity,
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

fn solved_with(settings: &RadiositySettings) -> (RadiosityScene, FaceVisibility, Solution, Value) {
    let data = shared_json("cornell_irradiance_radiance.json");
    let desc = radiance_cornell(&data);
    let scene = RadiosityScene::from_desc(&desc, settings).unwrap();
    let sphere = SceneSphere {
        center: Vec3::new(278.0, 274.4, 279.5),
        radius: 500.0,
    };
    let out = radiant::radiosity::adaptive::solve_adaptive(&scene, &[], sphere, settings, FaceVisibility::new, |_| {
        ControlFlow::Continue(())
    })
    .unwrap();
    let scene = out.scene.unwrap_or(scene);
    let vis = FaceVisibility::new(&scene);
    (scene, vis, out.solution, data)
}

#[test]
#[ignore]
fn zz_diag_print_sensors() {
    let t = std::time::Instant::now();
    let env = |k: &str, d: f64| std::env::var(k).ok().and_then(|s| s.parse().ok()).unwrap_or(d);
    let settings = RadiositySettings {
        max_patch_area: Some(env("AREA", 600.0)),
        solver: SolverKind::Progressive,
        tolerance: env("TOL", 1e-3),
        refine: env("REFINE", 0.0) as u32,
        refine_threshold: env("THRESH", 0.1),
        contact_grading: env("CONTACT", 0.0) as u32,
        ..RadiositySettings::default()
    };
    let (scene, vis, solution, data) = solved_with(&settings);
    eprintln!("solve {:.2}s {} patches {} shots", t.elapsed().as_secs_f64(), scene.patches.len(), solution.iterations);
    let variant = &data["variants"]["brief"];
    for g in ["floor", "back_wall"] {
        let s = sensors(&variant[g]);
        let e = relative_errors(&scene, &solution, &vis, &variant[g]);
        for ((p, _, r), e) in s.iter().zip(&e) {
            let m = e.iter().map(|x| x.abs()).fold(0.0, f64::max);
            println!("OURS {g} {} {} {} {} {} {}", p.x, p.y, p.z, r[0] * (1.0 + e[0]), r[1] * (1.0 + e[1]), r[2] * (1.0 + e[2]));
            if m > 0.02 {
                eprintln!("{g} {:7.2} {:7.2} {:7.2}  ref {:.4} {:.4} {:.4}  err {:+.4} {:+.4} {:+.4}", p.x, p.y, p.z, r[0], r[1], r[2], e[0], e[1], e[2]);
            }
        }
    }
}

#[test]
#[ignore]
fn zz_diag_path_trace_all() {
    use radiant::render::integrator::{PathSettings, path};
    use radiant::render::sampler::PixelSample;
    use radiant::render::world::{World, NO_LIGHT};
    use radiant::render::geometry::Ray;
    use std::io::Write;
    let data = shared_json("cornell_irradiance_radiance.json");
    let desc = radiance_cornell(&data);
    let (world, _) = World::build(&desc).unwrap();
    let settings = PathSettings { max_depth: 100, rr_depth: 5 };
    let variant = &data["variants"]["brief"];
    let light_l = [18.387f64, 13.9873, 6.75357];
    let count: u32 = std::env::var("PT_COUNT").ok().and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let grid = 256usize;
    let mut out = std::fs::File::create("/tmp/pt_sensors.txt").unwrap();
    for g in ["floor", "back_wall"] {
        for (p, n, reference) in sensors(&variant[g]) {
            let x = p + 0.01 * n;
            // Direct: midpoint grid over the light (y = 548.7, normal -y).
            let (x0, x1, z0, z1) = (213.0f64, 343.0, 227.0, 332.0);
            let da = (x1 - x0) * (z1 - z0) / (grid * grid) as f64;
            let direct_geo: f64 = (0..grid * grid).into_par_iter().map(|k| {
                let (i, j) = (k % grid, k / grid);
                let y = DVec3::new(x0 + (i as f64 + 0.5) * (x1 - x0) / grid as f64, 548.7, z0 + (j as f64 + 0.5) * (z1 - z0) / grid as f64);
                let d = y - x;
                let d2 = d.length_squared();
                let c0 = n.dot(d) / d2.sqrt();
                let c1 = d.y / d2.sqrt();
                if c0 <= 0.0 || c1 <= 0.0 { return 0.0; }
                let ray = Ray::new(x.as_vec3(), (y - x).as_vec3());
                if world.occluded(&ray, 1.0 - 1e-4) { return 0.0; }
                c0 * c1 / d2 * da
            }).sum();
            let direct: [f64; 3] = std::array::from_fn(|b| light_l[b] * direct_geo);
            let frame = radiant::math::Frame::from_normal(n.as_vec3());
            let sums = (0..count)
                .into_par_iter()
                .map(|i| {
                    let mut s = PixelSample::for_stream(radiant::scene::SamplerKind::Sobol, 11, 1, i);
                    let d = frame.to_world(radiant::math::sampling::cosine_hemisphere(s.get_2d()));
                    let ray = Ray::new(x.as_vec3(), d);
                    if let Some(h) = world.intersect(&ray, f32::INFINITY) { if h.light != NO_LIGHT { return [0.0; 6]; } } else { return [0.0; 6]; }
                    let (l, _) = path::radiance(&world, &settings, ray, &mut s);
                    let v = [l.r as f64, l.g as f64, l.b as f64];
                    [v[0], v[1], v[2], v[0]*v[0], v[1]*v[1], v[2]*v[2]]
                })
                .reduce(|| [0.0; 6], |a, b| std::array::from_fn(|k| a[k] + b[k]));
            let c = count as f64;
            let mean: [f64; 3] = std::array::from_fn(|b| std::f64::consts::PI * sums[b] / c);
            let se: [f64; 3] = std::array::from_fn(|b| {
                let m = sums[b] / c;
                std::f64::consts::PI * ((sums[b + 3] / c - m * m).max(0.0) / c).sqrt()
            });
            writeln!(out, "{g} {} {} {} {} {} {} {} {} {} {} {} {} {} {} {}", p.x, p.y, p.z, reference[0], reference[1], reference[2], direct[0], direct[1], direct[2], mean[0], mean[1], mean[2], se[0], se[1], se[2]).unwrap();
            out.flush().unwrap();
        }
    }
}

#[test]
#[ignore]
fn zz_diag_radiance_direct() {
    use radiant::render::world::World;
    use radiant::render::geometry::Ray;
    let data = shared_json("cornell_irradiance_radiance.json");
    let desc = radiance_cornell(&data);
    let (world, _) = World::build(&desc).unwrap();
    let variant = &data["variants"]["brief"];
    let (x0, x1, z0, z1) = (213.0f64, 343.0, 227.0, 332.0);
    let direct = |x: DVec3, n: DVec3, nx: usize, nz: usize, y_light: f64| -> f64 {
        let da = (x1 - x0) * (z1 - z0) / (nx * nz) as f64;
        (0..nx * nz).into_par_iter().map(|k| {
            let (i, j) = (k % nx, k / nx);
            let y = DVec3::new(x0 + (i as f64 + 0.5) * (x1 - x0) / nx as f64, y_light, z0 + (j as f64 + 0.5) * (z1 - z0) / nz as f64);
            let d = y - x;
            let d2 = d.length_squared();
            let c0 = n.dot(d) / d2.sqrt();
            let c1 = d.y / d2.sqrt();
            if c0 <= 0.0 || c1 <= 0.0 { return 0.0; }
            let ray = Ray::new(x.as_vec3(), (y - x).as_vec3());
            if world.occluded(&ray, 1.0 - 1e-4) { return 0.0; }
            c0 * c1 / d2 * da
        }).sum()
    };
    for g in ["floor", "back_wall"] {
        for (p, n, _) in sensors(&variant[g]) {
            let x = p + 0.01 * n;
            let exact = direct(x, n, 512, 512, 548.7);
            let rad8 = direct(x, n, 8, 8, 548.7);
            let rad16 = direct(x, n, 16, 16, 548.7);
            println!("DIRECT {g} {} {} {} {} {} {}", p.x, p.y, p.z, exact, rad8, rad16);
        }
    }
}

#[test]
#[ignore]
fn zz_diag_radiance_emulation() {
    use radiant::math::hash::{Pcg32, hash_u64s};
    use radiant::render::geometry::Ray;
    use radiant::render::material::Material;
    use radiant::render::world::{NO_LIGHT, World};
    use std::io::Write;
    let data = shared_json("cornell_irradiance_radiance.json");
    let desc = radiance_cornell(&data);
    let (world, _) = World::build(&desc).unwrap();
    let variant = &data["variants"]["brief"];
    let light_l = [18.387f64, 13.9873, 6.75357];
    let (x0, x1, z0, z1, yl) = (213.0f64, 343.0, 227.0, 332.0, 548.7);
    let area = (x1 - x0) * (z1 - z0);
    let count: u32 = std::env::var("PT_COUNT").ok().and_then(|s| s.parse().ok()).unwrap_or(200_000);
    let point_mode = std::env::var("POINT").is_ok();
    let only: Option<Vec<usize>> = std::env::var("ONLY").ok().map(|s| s.split(',').map(|v| v.parse().unwrap()).collect());
    let albedo = |m: u32| -> [f64; 3] {
        match world.materials[m as usize] {
            Material::Diffuse { albedo } => [albedo.r as f64, albedo.g as f64, albedo.b as f64],
            _ => [0.0; 3],
        }
    };
    let direct_at = |p: DVec3, n: DVec3, rng: &mut Pcg32| -> f64 {
        let y = if point_mode {
            DVec3::new(0.5 * (x0 + x1), yl, 0.5 * (z0 + z1))
        } else {
            DVec3::new(x0 + (x1 - x0) * rng.uniform_f64(), yl, z0 + (z1 - z0) * rng.uniform_f64())
        };
        let d = y - p;
        let d2 = d.length_squared();
        let c0 = n.dot(d) / d2.sqrt();
        let c1 = d.y / d2.sqrt();
        if c0 <= 0.0 || c1 <= 0.0 {
            return 0.0;
        }
        let o = p + n * 1e-3;
        if world.occluded(&Ray::new(o.as_vec3(), (y - o).as_vec3()), 1.0 - 1e-4) {
            return 0.0;
        }
        c0 * c1 / d2 * area
    };
    let mut out = std::fs::File::create(if point_mode { "/tmp/emul_point.txt" } else { "/tmp/emul_area.txt" }).unwrap();
    let mut index = 0usize;
    for g in ["floor", "back_wall"] {
        for (p, n, _) in sensors(&variant[g]) {
            index += 1;
            if let Some(o) = &only { if !o.contains(&(index - 1)) { continue; } }
            let x = p + 0.01 * n;
            let sum = (0..count).into_par_iter().map(|i| {
                let mut rng = Pcg32::new(hash_u64s(&[index as u64, i as u64]), 0);
                let mut o = x;
                let mut nn = n;
                let mut beta = [1.0f64; 3];
                let mut acc = [0.0f64; 3];
                for depth in 0..200 {
                    let frame = radiant::math::Frame::from_normal(nn.as_vec3());
                    let u = glam::Vec2::new(rng.uniform_f64() as f32, rng.uniform_f64() as f32);
                    let d = frame.to_world(radiant::math::sampling::cosine_hemisphere(u));
                    let Some(h) = world.intersect(&Ray::new((o + nn * 1e-3).as_vec3(), d), f32::INFINITY) else { break };
                    if h.light != NO_LIGHT { break; }
                    let rho = albedo(h.material);
                    let mut ng = h.ng.as_dvec3();
                    if ng.dot(d.as_dvec3()) > 0.0 { ng = -ng; }
                    let hp = h.p.as_dvec3();
                    let ed = direct_at(hp, ng, &mut rng);
                    for b in 0..3 {
                        beta[b] *= rho[b];
                        acc[b] += beta[b] * ed * light_l[b];
                    }
                    if depth >= 5 {
                        let q = beta[0].max(beta[1]).max(beta[2]).min(0.95);
                        if rng.uniform_f64() > q { break; }
                        for b in beta.iter_mut() { *b /= q; }
                    }
                    o = hp;
                    nn = ng;
                }
                acc
            }).reduce(|| [0.0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
            // Irradiance: pi * mean radiance, radiance of each hit = rho/pi * E.
            let ind: [f64; 3] = std::array::from_fn(|b| sum[b] / count as f64);
            writeln!(out, "{g} {} {} {} {} {} {}", p.x, p.y, p.z, ind[0], ind[1], ind[2]).unwrap();
            out.flush().unwrap();
        }
    }
}

#[test]
#[ignore]
fn zz_diag_farfield_bias() {
    use radiant::radiosity::contour::{point_disk_approximation, point_polygon_factor};
    let data = shared_json("cornell_irradiance_radiance.json");
    let desc = radiance_cornell(&data);
    let settings = RadiositySettings { max_patch_area: Some(600.0), ..RadiositySettings::default() };
    let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
    let set = &scene.patches;
    let second = |x: DVec3, n: DVec3, c: DVec3, ny: DVec3, area: f64| -> f64 {
        let d0 = c - x;
        let h = -ny.dot(d0);
        let a = n.dot(d0);
        if h <= 0.0 || a <= 0.0 { return 0.0; }
        let r2 = d0.length_squared();
        let rho_v = d0 + h * ny; // in-plane part of d0 (d0 = rho_v - h ny)
        let b = n - n.dot(ny) * ny;
        let rho2 = rho_v.length_squared();
        let k0 = a / (r2 * r2);
        let lap = a * (16.0 * rho2 - 8.0 * h * h) / (r2 * r2 * r2 * r2) - 8.0 * b.dot(rho_v) / (r2 * r2 * r2);
        (area * h / std::f64::consts::PI) * (k0 + area / 24.0 * lap)
    };
    for ratio in [4.0, 16.0, 64.0, 256.0] {
        let sums = (0..set.len()).into_par_iter().map(|j| {
            let r = &set.patches[j];
            let mut s = [0.0f64; 10];
            for i in 0..set.len() {
                if i == j { continue; }
                let t = &set.patches[i];
                let d2 = (t.centroid - r.centroid).length_squared();
                if d2 <= ratio * t.area { continue; }
                let exact = point_polygon_factor(r.centroid, r.normal, set.polygon(i).as_slice(), t.normal);
                if exact <= 0.0 { continue; }
                let disk = point_disk_approximation(r.centroid, r.normal, t.centroid, t.normal, t.area);
                let d = t.centroid - r.centroid;
                let cr = r.normal.dot(d); let cs = -t.normal.dot(d);
                let point = if cr > 0.0 && cs > 0.0 { t.area * cr * cs / (std::f64::consts::PI * d2 * d2) } else { 0.0 };
                let sec = second(r.centroid, r.normal, t.centroid, t.normal, t.area);
                s[0] += exact; s[1] += disk; s[2] += point; s[3] += sec; s[4] += 1.0;
                s[5] += (disk - exact).abs(); s[6] += (point - exact).abs(); s[7] += (sec - exact).abs();
                if exact > 1e-5 { s[8] = s[8].max((point/exact - 1.0).abs()); s[9] = s[9].max((sec/exact-1.0).abs()); }
            }
            s
        }).reduce(|| [0.0; 10], |a, b| { let mut o: [f64; 10] = std::array::from_fn(|k| a[k] + b[k]); o[8] = a[8].max(b[8]); o[9] = a[9].max(b[9]); o });
        eprintln!("ratio {ratio}: pairs {} bias disk {:+.5} point {:+.5} second {:+.5} | mean abs disk {:.5} point {:.5} second {:.5} | max rel (F>1e-5) point {:.4} second {:.4}", sums[4], sums[1] / sums[0] - 1.0, sums[2] / sums[0] - 1.0, sums[3]/sums[0]-1.0, sums[5]/sums[0], sums[6]/sums[0], sums[7]/sums[0], sums[8], sums[9]);
    }
}

#[test]
#[ignore]
fn zz_diag_refine_where() {
    let env = |k: &str, d: f64| std::env::var(k).ok().and_then(|s| s.parse().ok()).unwrap_or(d);
    let settings = RadiositySettings {
        max_patch_area: Some(env("AREA", 600.0)),
        solver: SolverKind::Progressive,
        tolerance: env("TOL", 1e-3),
        refine: env("REFINE", 0.0) as u32,
        refine_threshold: env("THRESH", 0.25),
        contact_grading: env("CONTACT", 0.0) as u32,
        ..RadiositySettings::default()
    };
    let (scene, _, _, _) = solved_with(&settings);
    let names = ["floor", "back", "ceiling", "short top", "short s1", "short s2", "short s3", "short s4", "tall top", "tall s1", "tall s2", "tall s3", "tall s4", "red", "green", "light"];
    let mut count = vec![0usize; scene.faces.faces.len()];
    let mut area = vec![0.0f64; scene.faces.faces.len()];
    for i in 0..scene.front_count {
        count[scene.patch_face[i] as usize] += 1;
        area[scene.patch_face[i] as usize] += scene.patches.patches[i].area;
    }
    for f in 0..count.len() {
        eprintln!("face {f:2} {:10} patches {:6} area {:9.0} mean patch {:7.1}", names.get(f).unwrap_or(&"?"), count[f], area[f], area[f] / count[f] as f64);
    }
}
