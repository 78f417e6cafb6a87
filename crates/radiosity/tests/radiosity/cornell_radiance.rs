//! The diffuse Cornell box of `cornell_irradiance_radiance.json` (variant "brief": the
//! idealised 556 x 548.8 x 559 mm box open at z = 0, the measured blocks, a
//! non-reflecting light at y = 548.7): irradiance at Radiance's floor and back-wall
//! sensors from the meshed, solved scene.

use std::ops::ControlFlow;

use radiant_math::color::Rgb;
use radiant_math::{DVec3, Vec3};
use radiant_radiosity::mesh::meshed_scene::RadiosityScene;
use radiant_radiosity::output::point_irradiance::{GatherSettings, irradiance_at};
use radiant_radiosity::settings::{RadiositySettings, SolverKind};
use radiant_radiosity::solve::Solution;
use radiant_radiosity::solve::adaptive::solve_adaptive;
use radiant_radiosity::visibility::bvh::FaceVisibility;
use radiant_render::light::SceneSphere;
use radiant_scene::builtin::cornell_box;
use radiant_scene::{AreaLightDesc, FileLoc, MaterialDesc, SceneDesc, ShapeDesc};
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
    ShapeDesc {
        area_light: light.map(|l| AreaLightDesc {
            l,
            two_sided: false,
            image: None,
        }),
        ..ShapeDesc::quads(
            list,
            material,
            FileLoc::builtin("cornell_irradiance_radiance"),
        )
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

/// The solved scene with what the sensors need: the radiosities as displayed
/// (`B + rho * ambient`, Cohen et al. 1988's estimate of the light not yet shot, as the
/// renderer shows them) and a visibility oracle for shadow rays.
struct Solved {
    scene: RadiosityScene,
    vis: FaceVisibility,
    solution: Solution,
    display: Vec<[f64; 3]>,
    data: Value,
}

impl Solved {
    /// Irradiance at `x` (normal `n`): the exact contour factor of every patch times its
    /// displayed radiosity, with shadow rays.
    fn irradiance(&self, x: DVec3, n: DVec3) -> [f64; 3] {
        irradiance_at(
            &self.scene.patches,
            &self.display,
            x,
            n,
            &self.vis,
            GatherSettings::default(),
        )
    }
}

/// The floor's and then the back wall's sensors of `grids` (the data's variant "brief",
/// or [`converged_radiance`]).
fn both_grids(grids: &Value) -> Vec<(DVec3, DVec3, [f64; 3])> {
    let mut all = sensors(&grids["floor"]);
    all.extend(sensors(&grids["back_wall"]));
    all
}

/// Relative error per sensor and band of the irradiance of the solved scene at
/// Radiance's sensor points of `grid`.
fn relative_errors(solved: &Solved, grid: &Value) -> Vec<[f64; 3]> {
    sensors(grid)
        .par_iter()
        .map(|(p, n, reference)| {
            // Sensors sit 0.01 mm off the surface along the normal, as in the data.
            let e = solved.irradiance(*p + 0.01 * *n, *n);
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

/// The solved scene at the test's resolution: 600 mm^2 patches graded twice towards
/// the blocks' contact lines (3,361 patches become 5,609), progressive refinement with
/// one-point ray-cast factors to 0.1 % unshot power.
fn solved() -> Solved {
    let data = shared_json("cornell_irradiance_radiance.json");
    let desc = radiance_cornell(&data);
    let settings = RadiositySettings {
        max_patch_area: Some(600.0),
        solver: SolverKind::Progressive,
        tolerance: 1e-3,
        contact_grading: 2,
        ..RadiositySettings::default()
    };
    let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
    let sphere = SceneSphere {
        center: Vec3::new(278.0, 274.4, 279.5),
        radius: 500.0,
    };
    let out = solve_adaptive(&scene, &[], sphere, &settings, FaceVisibility::new, |_| {
        ControlFlow::Continue(())
    })
    .unwrap();
    let scene = out.scene.unwrap_or(scene);
    let vis = FaceVisibility::new(&scene);
    let display = out.solution.display_radiosity(&scene.patches);
    Solved {
        scene,
        vis,
        solution: out.solution,
        display,
        data,
    }
}

/// Radiance's irradiance at the same sensors averaged over 4,096 unbiased evaluations
/// each (`tools/radiance/cornell_sensors.py`: the data file's rtrace command with the
/// light jittered, `-dj 1`), committed as tests/data/radiance-cornell-converged.json.
fn converged_radiance() -> Value {
    let path = radiant_testkit::repo_path("tests/data/radiance-cornell-converged.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn irradiance_matches_radiance_on_floor_and_back_wall() {
    // Irradiance at each sensor is evaluated from the displayed radiosities with the
    // exact contour factor of every patch and shadow rays (16 x 16 per light patch,
    // 2 x 2 per other triangle), so the direct light is exact up to its penumbra
    // sampling and only the indirect part carries discretisation error.
    let solved = solved();
    assert!(solved.solution.converged);
    let shared = &solved.data["variants"]["brief"];
    let converged = converged_radiance();
    for grid in ["floor", "back_wall"] {
        // The re-run is of the same sensors.
        let (ours, theirs) = (sensors(&converged[grid]), sensors(&shared[grid]));
        assert_eq!(ours.len(), theirs.len());
        assert!(
            ours.iter()
                .zip(&theirs)
                .all(|(a, b)| (a.0 - b.0).length() < 1e-9)
        );
    }
    let report = |name: &str, grid: &Value| {
        let (mean, p90, max) = stats(&relative_errors(&solved, grid));
        eprintln!("{name}: mean {mean:.4} p90 {p90:.4} max {max:.4}");
        (mean, p90, max)
    };
    let n = solved.scene.patches.len();
    eprintln!("{n} patches");
    // Against Radiance converged (standard errors of its means at most 0.59 %, median
    // 0.05 %): measured floor mean 0.25 %, max 1.96 %; back wall mean 0.25 %, max 1.01 %.
    for grid in ["floor", "back_wall"] {
        let (mean, _, max) = report(&format!("{grid} vs Radiance converged"), &converged[grid]);
        assert!(mean < 0.01 && max < 0.03, "{grid}: mean {mean}, max {max}");
    }
    // Against the data file's single run: means measured 0.79 % and 0.60 %; nine values
    // in ten within 2.1 % and 1.1 %; the largest, 5.5 % and 5.9 %, where that run
    // departs from Radiance converged by as much (5.6 % and 6.0 % at most): it samples
    // the light at fixed points (`radiance_departs_where_its_light_sampling_is_coarse`),
    // and 16 such runs averaged still depart by 4.7 % and 5.9 %. Without the contact
    // grading the floor sensor 3 mm in front of the short block was 17 % off: the
    // constant radiosity of the block's lowest patches overstated the dark strip at its
    // base.
    for grid in ["floor", "back_wall"] {
        let (mean, p90, max) = report(&format!("{grid} vs the data's run"), &shared[grid]);
        assert!(
            mean < 0.01 && p90 < 0.03 && max < 0.065,
            "{grid}: {mean} {p90} {max}"
        );
    }
}

/// Radiant's path tracer at the sensors where this solution departs most from the data
/// file's Radiance run: it departs from that run too, and agrees with the radiosity
/// solution and with Radiance converged. Slow (3 million paths per sensor, 20 s on 2 cores): run with `--ignored`.
#[test]
#[ignore]
fn radiance_discrepancy_is_shared_by_the_path_tracer() {
    use radiant_render::integrator::{PathSettings, path};
    use radiant_render::sampler::PixelSample;
    use radiant_render::world::World;
    let solved = solved();
    let data = &solved.data;
    let desc = radiance_cornell(data);
    let (world, _) = World::build(&desc).unwrap();
    let settings = PathSettings {
        max_depth: 100,
        rr_depth: 5,
        ..Default::default()
    };
    let converged = both_grids(&converged_radiance());
    let wanted = [
        [278.0, 24.945, 559.0],
        [227.45, 24.945, 559.0],
        [278.0, 0.0, 279.5],
        [278.0, 0.0, 533.59],
        [379.09, 0.0, 533.59],
    ];
    for (p, n, reference) in
        both_grids(&data["variants"]["brief"])
            .into_iter()
            .filter(|(p, _, _)| {
                wanted
                    .iter()
                    .any(|w| (DVec3::from_array(*w) - *p).length() < 0.1)
            })
    {
        let x = p + 0.01 * n;
        let frame = radiant_math::Frame::from_normal(n.as_vec3());
        let count = 3_000_000u32;
        let sum = (0..count)
            .into_par_iter()
            .map(|i| {
                let mut s = PixelSample::for_stream(radiant_scene::SamplerKind::Sobol, 7, 1, i);
                let d = frame.to_world(radiant_math::sampling::cosine_hemisphere(s.get_2d()));
                let (l, _) = path::radiance(
                    &world,
                    &settings,
                    radiant_render::geometry::Ray::new(x.as_vec3(), d),
                    &mut s,
                );
                [l.r as f64, l.g as f64, l.b as f64]
            })
            .reduce(|| [0.0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        let traced = sum.map(|v| std::f64::consts::PI * v / count as f64);
        let ours = solved.irradiance(x, n);
        let (_, _, settled) = converged
            .iter()
            .find(|(q, _, _)| (*q - p).length() < 1e-9)
            .unwrap();
        for b in 0..3 {
            eprintln!(
                "{p:?} band {b}: Radiance's run {:.5} Radiance converged {:.5} path {:.5} radiosity {:.5}",
                reference[b], settled[b], traced[b], ours[b]
            );
            // Radiance converged carries up to 0.6 % of noise, the path tracer 0.1-0.2 %;
            // measured within 0.15 % at all fifteen values.
            assert!((traced[b] / settled[b] - 1.0).abs() < 0.015);
            // Path tracing noise here is 0.1-0.2 %; the radiosity's own error below 1 %.
            assert!((ours[b] / traced[b] - 1.0).abs() < 0.015);
            // Measured: 1.4 to 5.7 % below the data's run in the light, 3 to 5 % above
            // it in the short block's penumbra at (379, 0, 534).
            assert!((traced[b] / reference[b] - 1.0).abs() > 0.01);
        }
    }
}

/// Brute-force irradiance at every sensor, two ways. Exact: the light integrated on a
/// 128 x 128 midpoint grid with shadow rays at the sensor, plus indirect light from
/// cosine-sampled random walks that sample the light's area at every bounce. Coarse:
/// the same with the light sampled at 8 x 8 fixed points at the sensor and at its
/// centre at the bounces, which is how the data file's run samples it: with `-dj 0`
/// Radiance samples each partition of a source at its centre, and it splits a source
/// into at most 64 partitions (MAXSPART in its source.h) however small `-ds` (0.01
/// there) asks, while at later bounces the small ray weight leaves the light whole.
/// The radiosity solution and Radiance converged (jittered light, see
/// [`converged_radiance`]) agree with the exact values; the data's run agrees with the
/// coarse ones, and departs from the exact ones where the light is partly hidden.
/// Slow (2 x 200,000 walks per sensor, about 1 minute on 2 cores): run with
/// `--ignored`.
#[test]
#[ignore]
fn radiance_departs_where_its_light_sampling_is_coarse() {
    use radiant_math::hash::{Pcg32, hash_u64s};
    use radiant_render::geometry::Ray;
    use radiant_render::material::Material;
    use radiant_render::world::{MaterialEntry, NO_LIGHT, World};
    let solved = solved();
    let data = &solved.data;
    let desc = radiance_cornell(data);
    let (world, _) = World::build(&desc).unwrap();
    let light = &data["scene"]["light_rect"];
    let (x0, x1) = (
        light["x"][0].as_f64().unwrap(),
        light["x"][1].as_f64().unwrap(),
    );
    let (z0, z1) = (
        light["z"][0].as_f64().unwrap(),
        light["z"][1].as_f64().unwrap(),
    );
    let light_y = 548.7;
    let radiance = [0, 1, 2].map(|k| data["scene"]["light_radiance_rgb"][k].as_f64().unwrap());
    let area = (x1 - x0) * (z1 - z0);
    let albedo = |m: u32| match world.materials[m as usize] {
        MaterialEntry::Bsdf(Material::Diffuse { albedo }) => {
            [albedo.r, albedo.g, albedo.b].map(f64::from)
        }
        _ => [0.0; 3],
    };
    // Geometric factor from x (normal n) to the light point y, times the light's area.
    let to_light = |x: DVec3, n: DVec3, y: DVec3| -> f64 {
        let d = y - x;
        let d2 = d.length_squared();
        let (cos_x, cos_y) = (n.dot(d) / d2.sqrt(), d.y / d2.sqrt());
        if cos_x <= 0.0 || cos_y <= 0.0 {
            return 0.0;
        }
        let o = x + 1e-3 * n;
        if world.occluded(&Ray::new(o.as_vec3(), (y - o).as_vec3()), 1.0 - 1e-4) {
            return 0.0;
        }
        cos_x * cos_y / d2 * area
    };
    let grid_point = |i: usize, j: usize, cells: usize| {
        DVec3::new(
            x0 + (i as f64 + 0.5) * (x1 - x0) / cells as f64,
            light_y,
            z0 + (j as f64 + 0.5) * (z1 - z0) / cells as f64,
        )
    };
    let grid_direct = |x: DVec3, n: DVec3, cells: usize| -> f64 {
        (0..cells * cells)
            .into_par_iter()
            .map(|k| to_light(x, n, grid_point(k % cells, k / cells, cells)))
            .sum::<f64>()
            / (cells * cells) as f64
    };
    // Indirect irradiance at x by random walks; `coarse` samples the light's centre.
    let walks = 200_000u64;
    let indirect = |sensor: u64, x: DVec3, n: DVec3, coarse: bool| -> [f64; 3] {
        let sum = (0..walks)
            .into_par_iter()
            .map(|w| {
                let mut rng = Pcg32::new(hash_u64s(&[sensor, w, coarse as u64]), 0);
                let (mut o, mut normal) = (x, n);
                let mut weight = [1.0f64; 3];
                let mut acc = [0.0f64; 3];
                for depth in 0..200 {
                    let frame = radiant_math::Frame::from_normal(normal.as_vec3());
                    // The first direction from a Hammersley set, which takes out most of
                    // the variance; the rest of the walk is random.
                    let u = if depth == 0 {
                        glam::Vec2::new(
                            ((w as f64 + 0.5) / walks as f64) as f32,
                            (w as u32).reverse_bits() as f32 / 4_294_967_296.0,
                        )
                    } else {
                        glam::Vec2::new(rng.uniform_f64() as f32, rng.uniform_f64() as f32)
                    };
                    let d = frame.to_world(radiant_math::sampling::cosine_hemisphere(u));
                    let ray = Ray::new((o + 1e-3 * normal).as_vec3(), d);
                    let Some(hit) = world.intersect(&ray, f32::INFINITY) else {
                        break;
                    };
                    if hit.light != NO_LIGHT {
                        break; // the light is counted by its sampling at each vertex
                    }
                    let mut ng = hit.ng.as_dvec3();
                    if ng.dot(d.as_dvec3()) > 0.0 {
                        ng = -ng;
                    }
                    let p = hit.p.as_dvec3();
                    let y = if coarse {
                        grid_point(0, 0, 1)
                    } else {
                        DVec3::new(
                            x0 + (x1 - x0) * rng.uniform_f64(),
                            light_y,
                            z0 + (z1 - z0) * rng.uniform_f64(),
                        )
                    };
                    let g = to_light(p, ng, y);
                    let rho = albedo(hit.material);
                    for b in 0..3 {
                        weight[b] *= rho[b];
                        acc[b] += weight[b] * g * radiance[b];
                    }
                    if depth >= 5 {
                        let q = weight[0].max(weight[1]).max(weight[2]).min(0.95);
                        if rng.uniform_f64() > q {
                            break;
                        }
                        weight = weight.map(|v| v / q);
                    }
                    o = p;
                    normal = ng;
                }
                acc
            })
            .reduce(|| [0.0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        sum.map(|v| v / walks as f64)
    };
    let mut ours_exact: Vec<[f64; 3]> = Vec::new();
    let mut exact_radiance: Vec<[f64; 3]> = Vec::new();
    let mut coarse_radiance: Vec<[f64; 3]> = Vec::new();
    let mut exact_converged: Vec<[f64; 3]> = Vec::new();
    let converged = both_grids(&converged_radiance());
    for (s, (p, n, reference)) in both_grids(&data["variants"]["brief"]).iter().enumerate() {
        let x = *p + 0.01 * *n;
        let exact_direct = grid_direct(x, *n, 128);
        let coarse_direct = grid_direct(x, *n, 8);
        let exact_indirect = indirect(s as u64, x, *n, false);
        let coarse_indirect = indirect(s as u64, x, *n, true);
        let ours = solved.irradiance(x, *n);
        let exact: [f64; 3] =
            std::array::from_fn(|b| exact_direct * radiance[b] + exact_indirect[b]);
        let coarse: [f64; 3] =
            std::array::from_fn(|b| coarse_direct * radiance[b] + coarse_indirect[b]);
        ours_exact.push(std::array::from_fn(|b| ours[b] / exact[b] - 1.0));
        exact_radiance.push(std::array::from_fn(|b| exact[b] / reference[b] - 1.0));
        coarse_radiance.push(std::array::from_fn(|b| coarse[b] / reference[b] - 1.0));
        exact_converged.push(std::array::from_fn(|b| exact[b] / converged[s].2[b] - 1.0));
    }
    // (mean, 90th percentile, max) of the absolute relative differences.
    let (oe, ee, ce, ec) = (
        stats(&ours_exact),
        stats(&exact_radiance),
        stats(&coarse_radiance),
        stats(&exact_converged),
    );
    eprintln!(
        "|relative difference| mean, max over {} sensor-bands: radiosity vs exact {:.4} {:.4}; \
         exact vs the data's run {:.4} {:.4}; coarse vs the data's run {:.4} {:.4}; \
         exact vs Radiance converged {:.4} {:.4}",
        3 * ours_exact.len(),
        oe.0,
        oe.2,
        ee.0,
        ee.2,
        ce.0,
        ce.2,
        ec.0,
        ec.2
    );
    // Measured (mean, max): radiosity vs exact 0.27 %, 2.2 %; exact vs the data's run
    // 0.67 %, 6.4 %; coarse vs the data's run 0.20 %, 2.2 %; exact vs Radiance
    // converged 0.14 %, 2.6 %. The walks' noise is 0.1-0.5 % per sensor.
    assert!(oe.0 < 0.005 && oe.2 < 0.03);
    assert!(ce.0 < 0.01 && ce.2 < 0.03);
    assert!(ce.0 < 0.5 * ee.0 && ee.2 > 0.04);
    assert!(ec.0 < 0.005 && ec.2 < 0.03);
}
