//! From scene description to image and files: meshing, BVH visibility, delta lights,
//! solvers through the integrator settings, display, exports.

use std::ops::ControlFlow;

use radiant_math::{DVec3, Vec3};
use radiant_radiosity::Visibility;
use radiant_radiosity::mesh::meshed_scene::RadiosityScene;
use radiant_radiosity::settings::{FormFactorMethod, RadiositySettings, SolverKind};
use radiant_radiosity::solve::{Solution, solve};
use radiant_radiosity::visibility::bvh::{FaceVisibility, WorldVisibility};
use radiant_render::world::World;
use radiant_scene::builtin::cornell_box;
use radiant_scene::{FileLoc, Geometry, LightDesc, MaterialDesc, SceneDesc, ShapeDesc};

use crate::common::{max_relative_difference, solve_to_end};
use crate::mesh_checks::assert_conforming;

fn settings_with_area(area: f64) -> RadiositySettings {
    RadiositySettings {
        max_patch_area: Some(area),
        ..RadiositySettings::default()
    }
}

fn cornell(area: f64) -> (SceneDesc, RadiosityScene, World) {
    let desc = cornell_box();
    let scene = RadiosityScene::from_desc(&desc, &settings_with_area(area)).unwrap();
    let (world, _) = World::build(&desc).unwrap();
    (desc, scene, world)
}

#[test]
fn cornell_mesh_is_conforming_within_every_surface() {
    // No T-junctions (see `assert_conforming`).
    let (_, scene, _) = cornell(2000.0);
    let (boundary, mesh) = assert_conforming(&scene);
    assert!(boundary > 0);
    // The back-right-bottom corner (floor, back wall, green wall) has three display
    // vertices: the three surfaces meet there but are not blended.
    let corner = DVec3::new(0.0, 0.0, 559.2f32 as f64);
    let at_corner = mesh
        .positions
        .iter()
        .filter(|p| (**p - corner).length() < 1e-9)
        .count();
    assert_eq!(at_corner, 3);
}

#[test]
fn shaft_culled_face_visibility_agrees_with_the_world_bvh() {
    // The face BVH (walls culled, shot-by-shot candidate lists) and the render world's
    // BVH answer the same queries on the Cornell box (planar, so the geometry is the
    // same). They lift ray ends off surfaces by different amounts (1e-6 of the scene
    // against a few hundred ulps), so rays grazing the fold of the non-planar red wall
    // may go either way: measured 3 of 84,470 centroid pairs, allowed 0.2 %; the
    // radiosities then differ by 1.4e-5 of the largest, allowed 1e-3.
    let (_, scene, world) = cornell(4000.0);
    let faces = FaceVisibility::new(&scene);
    let render = WorldVisibility::new(&world, &scene.patches);
    assert!(faces.occluder_count() < 30, "walls should not be occluders");
    let set = &scene.patches;
    let mut disagree = 0;
    let mut pairs = 0;
    for i in (0..set.len()).step_by(3) {
        for j in 0..set.len() {
            let (a, b) = (set.patches[i].centroid, set.patches[j].centroid);
            // Pairs that face each other (the only ones the solver asks about).
            let grazing = 1e-6 * (b - a).length();
            if i == j
                || set.patches[i].normal.dot(b - a) <= grazing
                || set.patches[j].normal.dot(a - b) <= grazing
            {
                continue;
            }
            pairs += 1;
            disagree += usize::from(faces.visible(a, b, i, j) != render.visible(a, b, i, j));
        }
    }
    assert!(pairs > 50_000);
    assert!(disagree * 500 <= pairs, "{disagree} of {pairs}");
    let settings = RadiositySettings {
        tolerance: 1e-3,
        ..settings_with_area(4000.0)
    };
    let with_faces = solve_to_end(&scene, &world, &settings, &faces);
    let with_world = solve_to_end(&scene, &world, &settings, &render);
    let difference = max_relative_difference(&with_faces.radiosity, &with_world.radiosity);
    eprintln!("{disagree} of {pairs} pairs disagree; radiosities differ by {difference:e}");
    assert!(difference < 1e-3);
}

#[test]
fn shots_that_culling_would_slow_use_the_bvh_and_agree_with_the_world() {
    // Culling a shot tests every receiver tile against every occluder, and a tile
    // never spans two input faces: on a finely tessellated mesh that is quadratic in
    // its triangles (seconds per shot on Bitterli's material-testball, 130k patches).
    // A corrugated plate of 48 x 48 small quads (4,608 occluding triangles) hung in the
    // Cornell box is past that budget; its shots must then go through the face BVH and
    // agree with the render world's BVH as the culled ones do on the plain box.
    let (_, plain, plain_world) = cornell(4000.0);
    assert!(FaceVisibility::new(&plain).culls_shots());

    let mut desc = cornell_box();
    let material = desc.shapes[0].material;
    let n = 48;
    let (x0, z0, size) = (130.0f32, 130.0f32, 300.0f32);
    let cell = size / n as f32;
    let height = |i: usize, k: usize| 380.0 + if (i + k).is_multiple_of(2) { 0.0 } else { 4.0 };
    let mut quads = Vec::new();
    for i in 0..n {
        for k in 0..n {
            let (x, z) = (x0 + i as f32 * cell, z0 + k as f32 * cell);
            // Facing down, towards the floor: counter-clockwise seen from below.
            quads.push([
                Vec3::new(x, height(i, k), z),
                Vec3::new(x + cell, height(i + 1, k), z),
                Vec3::new(x + cell, height(i + 1, k + 1), z + cell),
                Vec3::new(x, height(i, k + 1), z + cell),
            ]);
        }
    }
    desc.shapes
        .push(ShapeDesc::quads(&quads, material, FileLoc::builtin("test")));
    let settings = RadiositySettings {
        tolerance: 1e-3,
        ..settings_with_area(4000.0)
    };
    let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
    let (world, _) = World::build(&desc).unwrap();
    let faces = FaceVisibility::new(&scene);
    assert!(faces.occluder_count() > 4_000);
    assert!(!faces.culls_shots());
    let render = WorldVisibility::new(&world, &scene.patches);
    let with_faces = solve_to_end(&scene, &world, &settings, &faces);
    let with_world = solve_to_end(&scene, &world, &settings, &render);
    assert!(with_faces.converged && with_world.converged);
    let difference = max_relative_difference(&with_faces.radiosity, &with_world.radiosity);
    eprintln!("radiosities differ by {difference:e}");
    assert!(difference < 1e-3);
    // The plate shades the floor under it.
    let plain_solution = solve_to_end(
        &plain,
        &plain_world,
        &settings,
        &FaceVisibility::new(&plain),
    );
    assert!(
        floor_under_the_plate(&scene, &with_faces)
            < 0.5 * floor_under_the_plate(&plain, &plain_solution)
    );
}

/// Mean radiosity (green) of the floor patches under the middle of the box.
fn floor_under_the_plate(scene: &RadiosityScene, solution: &Solution) -> f64 {
    let (mut sum, mut area) = (0.0, 0.0);
    for (p, b) in scene.patches.patches.iter().zip(&solution.radiosity) {
        let c = p.centroid;
        if c.y < 1.0 && (180.0..380.0).contains(&c.x) && (180.0..380.0).contains(&c.z) {
            sum += p.area * b[1];
            area += p.area;
        }
    }
    sum / area
}

#[test]
fn factor_methods_and_solvers_agree_on_the_cornell_box() {
    // Progressive ray casting (one point per receiver) to 1e-4, Gauss-Seidel on the
    // ray-cast matrix (2 x 2 points per receiver), and progressive hemi-cube shooting
    // (256 cells, occlusion by its depth buffer) solve the same box (550 patches of up
    // to 4,000 mm^2). They differ most on patches a shadow boundary crosses (floor
    // patches half under a block, ceiling patches half behind the light), which one
    // centre point sees as wholly lit or wholly dark and four points see in part.
    // Measured differences in reflected power 2.1 % (Gauss-Seidel) and 1.8 %
    // (hemi-cube); allowed 3 %.
    let (_, scene, world) = cornell(4000.0);
    let vis = FaceVisibility::new(&scene);
    let base = RadiositySettings {
        tolerance: 1e-4,
        ..settings_with_area(4000.0)
    };
    let progressive = solve_to_end(&scene, &world, &base, &vis);
    let seidel = solve_to_end(
        &scene,
        &world,
        &RadiositySettings {
            solver: SolverKind::GaussSeidel,
            tolerance: 1e-7,
            ..base.clone()
        },
        &vis,
    );
    let hemicube = solve_to_end(
        &scene,
        &world,
        &RadiositySettings {
            form_factor: FormFactorMethod::HemiCube,
            hemicube_resolution: 256,
            ..base.clone()
        },
        &vis,
    );
    // Difference in reflected power: sum A |B - B'| / sum A B'.
    let difference = |a: &Solution, b: &Solution| {
        let mut num = 0.0;
        let mut den = 0.0;
        for ((x, y), p) in a
            .radiosity
            .iter()
            .zip(&b.radiosity)
            .zip(&scene.patches.patches)
        {
            for k in 0..3 {
                num += p.area * (x[k] - y[k]).abs();
                den += p.area * y[k];
            }
        }
        num / den
    };
    let gs = difference(&seidel, &progressive);
    let hc = difference(&hemicube, &progressive);
    eprintln!("power-weighted difference: Gauss-Seidel {gs:.4}, hemi-cube {hc:.4}");
    assert!(gs < 0.03 && hc < 0.03);
    // Progressive bookkeeping closes to rounding; the matrix solution's balance is off
    // by the factors' reciprocity error (measured 0.2 %).
    let closes = |s: &Solution, tolerance: f64| {
        let gap = s.balance.imbalance();
        (0..3).all(|b| gap[b].abs() < tolerance * s.balance.emitted[b])
    };
    assert!(closes(&progressive, 1e-12));
    assert!(closes(&seidel, 0.01));
}

/// A square floor of half-side `a` at y = 0 (reflectance 0.5, facing up) under a point
/// light of intensity `i` at height `h` above its centre.
fn floor_under_point_light(a: f32, h: f32, i: f32) -> SceneDesc {
    let mut desc = cornell_box();
    desc.materials = vec![MaterialDesc::Diffuse {
        reflectance: radiant_math::color::Rgb::splat(0.5),
    }];
    desc.shapes = vec![ShapeDesc::quads(
        &[[
            Vec3::new(a, 0.0, -a),
            Vec3::new(-a, 0.0, -a),
            Vec3::new(-a, 0.0, a),
            Vec3::new(a, 0.0, a),
        ]],
        0,
        FileLoc::builtin("test"),
    )];
    desc.lights = vec![LightDesc::Point {
        position: Vec3::new(0.0, h, 0.0),
        intensity: radiant_math::color::Rgb::splat(i),
        loc: FileLoc::builtin("test"),
    }];
    desc
}

#[test]
fn point_light_is_the_first_shot() {
    // Power reaching the square is I times the solid angle it subtends from the light,
    // Omega = 4 asin(a^2 / (a^2 + h^2)). 3 x 3 Gauss points per patch on 20 x 20 patches
    // integrate I cos / r^2 to ~1e-6 here; allowed 1e-4. Nothing else is in the scene,
    // so everything the floor reflects escapes: absorbed = (1 - rho) I Omega, escaped
    // = 4 pi I - absorbed, to rounding.
    let (a, h, i) = (1.0f32, 1.5f32, 2.0f32);
    let desc = floor_under_point_light(a, h, i);
    let settings = RadiositySettings {
        subdivision: 20,
        ..settings_with_area(1.0)
    };
    let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
    let (world, _) = World::build(&desc).unwrap();
    let vis = FaceVisibility::new(&scene);
    let solution = solve_to_end(&scene, &world, &settings, &vis);
    let (a, h, i) = (a as f64, h as f64, i as f64);
    let omega = 4.0 * (a * a / (a * a + h * h)).asin();
    let arrived: f64 = scene
        .patches
        .patches
        .iter()
        .zip(&solution.irradiance)
        .map(|(p, e)| p.area * e[0])
        .sum();
    assert!(
        (arrived / (i * omega) - 1.0).abs() < 1e-4,
        "{arrived} vs {}",
        i * omega
    );
    let b = &solution.balance;
    let emitted = 4.0 * std::f64::consts::PI * i;
    assert!((b.emitted[0] / emitted - 1.0).abs() < 1e-6);
    assert!((b.absorbed[0] / (0.5 * arrived) - 1.0).abs() < 1e-9);
    assert!(b.imbalance()[0].abs() < 1e-9 * emitted);
    // The patch under the light gets about I / h^2 (its own average of I h / r^3).
    let centre = (0..scene.patches.len())
        .min_by(|&p, &q| {
            let d = |k: usize| scene.patches.patches[k].centroid.length();
            d(p).total_cmp(&d(q))
        })
        .unwrap();
    assert!((solution.irradiance[centre][0] / (i / (h * h)) - 1.0).abs() < 0.01);
}

#[test]
fn a_stopped_solve_reports_where_it_stopped() {
    let (_, scene, world) = cornell(4000.0);
    let vis = FaceVisibility::new(&scene);
    let mut calls = 0;
    let solution = solve(
        &scene,
        &world.lights,
        world.scene_sphere(),
        &settings_with_area(4000.0),
        &vis,
        |_| {
            calls += 1;
            if calls == 10 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    )
    .unwrap();
    assert!(solution.interrupted && !solution.converged);
    assert_eq!(solution.iterations, 10);
    // The books still balance with the light not yet shot counted as unshot.
    let gap = solution.balance.imbalance();
    assert!((0..3).all(|b| gap[b].abs() < 1e-12 * solution.balance.emitted[b]));
}

#[test]
fn curved_bilinear_patches_are_meshed_on_their_surface() {
    // The twisted patch y = 0.5 u v over the unit square (x = u, z = v), facing up,
    // under a square area light. Every patch corner lies on the bilinear surface, the
    // patches' area approaches the surface's (1.0790; flat triangles over cells of 1/8
    // of the side under-estimate it by ~1e-4, allowed 1e-3), and every patch sees
    // the light: shadow rays leave the curved surface without hitting it.
    use radiant_scene::AreaLightDesc;
    use radiant_scene::mesh::bilinear_patch_area;
    let mut desc = cornell_box();
    let corners = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.5, 1.0),
    ];
    let shape = |geometry, material, area_light| ShapeDesc {
        geometry,
        render_from_object: Default::default(),
        reverse_orientation: false,
        material,
        area_light,
        alpha: None,
        loc: FileLoc::builtin("test"),
    };
    desc.materials = vec![MaterialDesc::Diffuse {
        reflectance: radiant_math::color::Rgb::splat(0.5),
    }];
    desc.shapes = vec![
        shape(
            Geometry::BilinearMesh {
                positions: corners.to_vec(),
                // (p00, p10, p01, p11) with p00 -> p10 along x and p00 -> p01 along z:
                // dp/du x dp/dv points down, so list it the other way round.
                indices: vec![0, 2, 1, 3],
                normals: None,
                uvs: None,
            },
            0,
            None,
        ),
        ShapeDesc {
            area_light: Some(AreaLightDesc {
                l: radiant_math::color::Rgb::splat(1.0),
                two_sided: false,
                image: None,
            }),
            ..ShapeDesc::quads(
                &[[
                    Vec3::new(-1.0, 2.0, -1.0),
                    Vec3::new(2.0, 2.0, -1.0),
                    Vec3::new(2.0, 2.0, 2.0),
                    Vec3::new(-1.0, 2.0, 2.0),
                ]],
                0,
                FileLoc::builtin("test"),
            )
        },
    ];
    desc.lights.clear();
    let settings = RadiositySettings {
        subdivision: 8,
        ..settings_with_area(1.0)
    };
    let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
    assert!(scene.warnings.iter().any(|w| w.message.contains("curved")));
    let (world, _) = World::build(&desc).unwrap();
    let vis = FaceVisibility::new(&scene);
    let solution = solve_to_end(&scene, &world, &settings, &vis);
    let surface: Vec<usize> = (0..scene.patches.len())
        .filter(|&i| scene.patches.patches[i].emission == [0.0; 3])
        .collect();
    assert_eq!(surface.len(), 2 * 8 * 8);
    let area: f64 = surface.iter().map(|&i| scene.patches.patches[i].area).sum();
    let exact = bilinear_patch_area([corners[0], corners[1], corners[2], corners[3]]) as f64;
    assert!((area / exact - 1.0).abs() < 1e-3, "{area} vs {exact}");
    for &i in &surface {
        let p = &scene.patches.patches[i];
        assert!(p.normal.y > 0.5);
        for &c in &p.corners[..p.corner_count as usize] {
            let q = scene.patches.points[c as usize];
            assert!((q.y - 0.5 * q.x * q.z).abs() < 1e-12);
        }
        assert!(
            solution.irradiance[i][0] > 0.0,
            "patch {i} is in its own shadow"
        );
    }
}

/// Non-diffuse materials enter the solve with their diffuse albedo alone (a mix with
/// the amount-weighted albedo of its two materials), each with one warning that names
/// it, however many shapes use it; Lambertian materials with none.
#[test]
fn non_diffuse_materials_use_their_diffuse_albedo_with_one_warning_each() {
    let quad = |z: f32| {
        format!(
            "Shape \"trianglemesh\" \"point3 P\" [ 0 0 {z}  1 0 {z}  1 1 {z}  0 1 {z} ] \"integer indices\" [ 0 1 2  0 2 3 ]\n"
        )
    };
    let text = format!(
        "WorldBegin\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\n{}AttributeEnd\n\
         MakeNamedMaterial \"white\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0.8 0.8 0.8 ]\n\
         MakeNamedMaterial \"metal\" \"string type\" \"conductor\" \"float roughness\" 0.1\n\
         NamedMaterial \"white\"\n{}\
         Material \"diffusetransmission\" \"rgb reflectance\" [ 0.3 0.4 0.5 ]\n{}{}\
         NamedMaterial \"metal\"\n{}\
         Material \"mix\" \"string materials\" [ \"white\" \"metal\" ] \"float amount\" 0.25\n{}",
        quad(0.0),
        quad(1.0),
        quad(2.0),
        quad(3.0),
        quad(4.0),
        quad(5.0),
    );
    let desc = radiant_scene::parse_str(&text, "t.pbrt", std::path::Path::new(".")).unwrap();
    let scene = RadiosityScene::from_desc(&desc, &settings_with_area(1.0)).unwrap();
    let msgs: Vec<&str> = scene
        .warnings
        .iter()
        .map(|w| w.message.as_str())
        .filter(|m| m.contains("is not diffuse"))
        .collect();
    assert_eq!(msgs.len(), 3, "{msgs:#?}");
    for (msg, ty) in msgs.iter().zip(["diffusetransmission", "conductor", "mix"]) {
        assert!(msg.contains(&format!("(\"{ty}\")")), "{msg}");
    }
    let reflectance = |shape: u32| {
        let tag = scene.tags.iter().find(|t| t.shape == shape).unwrap();
        tag.reflectance.map(|r| r as f32)
    };
    let close = |a: [f32; 3], b: [f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-6);
    assert!(close(reflectance(1), [0.8; 3]));
    assert!(close(reflectance(2), [0.3, 0.4, 0.5]));
    assert!(close(reflectance(3), [0.3, 0.4, 0.5]));
    assert!(close(reflectance(4), [0.0; 3]));
    assert!(close(reflectance(5), [0.6; 3]), "{:?}", reflectance(5));
}

/// Textured inputs: each shape's tag holds its mean (an area light's image times
/// `scale`; with `power`, normalised by the image's mean luminance as the renderer
/// does; a textured mix amount by its mean over (u, v)), with one warning naming the
/// image, and each patch its own mean over the part of the surface it covers.
#[test]
fn image_emission_and_textured_mix_amounts_enter_by_their_means() {
    let dir = std::env::temp_dir().join(format!("radiant-radiosity-images-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pixels: Vec<radiant_math::color::Rgb> = (0..4)
        .map(|k| radiant_math::color::Rgb::new(k as f32, 1.0, 0.5))
        .collect();
    let img = radiant_image::Image {
        width: 2,
        height: 2,
        pixels,
    };
    radiant_image::pfm::write_pfm(dir.join("glow.pfm"), &img).unwrap();
    let quad = |z: f32| {
        format!(
            "Shape \"trianglemesh\" \"point3 P\" [ 0 0 {z}  1 0 {z}  1 1 {z}  0 1 {z} ] \
             \"point2 uv\" [ 0 0 1 0 1 1 0 1 ] \"integer indices\" [ 0 1 2  0 2 3 ]\n"
        )
    };
    let text = format!(
        "WorldBegin\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"string filename\" \"glow.pfm\" \"float scale\" 2\n{}AttributeEnd\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"string filename\" \"glow.pfm\" \"float power\" 3\n{}AttributeEnd\n\
         Texture \"amt\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 1 \
           \"float tex1\" 0 \"float tex2\" 1\n\
         MakeNamedMaterial \"white\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0.8 0.8 0.8 ]\n\
         MakeNamedMaterial \"black\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n\
         Material \"mix\" \"string materials\" [ \"white\" \"black\" ] \"texture amount\" \"amt\"\n{}",
        quad(0.0),
        quad(1.0),
        quad(2.0),
    );
    let desc = radiant_scene::parse_str(&text, "t.pbrt", &dir).unwrap();
    let scene = RadiosityScene::from_desc(&desc, &settings_with_area(0.01)).unwrap();
    let image_warnings = scene
        .warnings
        .iter()
        .filter(|w| w.message.contains("glow.pfm"))
        .count();
    assert_eq!(image_warnings, 1, "{:#?}", scene.warnings);
    let tag = |shape: u32| scene.tags.iter().find(|t| t.shape == shape).unwrap();
    let pi = std::f64::consts::PI;
    // Mean texel (1.5, 1, 0.5), times the scale, as exitance π L.
    let e0 = tag(0).emission;
    for (k, want) in [3.0, 2.0, 1.0].into_iter().enumerate() {
        assert!((e0[k] - pi * want).abs() < 1e-5, "{e0:?}");
    }
    // power 3 over a one-sided unit square: mean luminance π L̄ A = 3.
    let e1 = tag(1).emission;
    let lum = 0.2126 * e1[0] + 0.7152 * e1[1] + 0.0722 * e1[2];
    assert!((lum - 3.0).abs() < 1e-4, "{e1:?}");
    // Half black by the amount's mean: 0.4.
    let r = tag(2).reflectance;
    assert!((r[1] - 0.4).abs() < 1e-6, "{r:?}");
    // Per patch: white where u < 1/2 (x < 1/2), black beyond, the patches across the
    // edge in between; the image's left column (texels 0 and 2, red 0 and 2) emits
    // less red than its right (1 and 3).
    let (mut white, mut black) = (0, 0);
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for (i, p) in scene.patches.patches.iter().enumerate() {
        let shape = scene.tag(i).shape;
        let x = p.centroid.x;
        let polygon = scene.patches.polygon(i);
        let xs = polygon.as_slice().iter().map(|q| q.x);
        let (lo, hi) = (
            xs.clone().fold(f64::MAX, f64::min),
            xs.fold(f64::MIN, f64::max),
        );
        if shape == 2 && hi <= 0.5 + 1e-9 {
            assert!(
                (p.reflectance[1] - 0.8).abs() < 1e-6,
                "{i} at x {x}: {:?}",
                p.reflectance
            );
            white += 1;
        } else if shape == 2 && lo >= 0.5 - 1e-9 {
            assert!(
                p.reflectance[1].abs() < 1e-6,
                "{i} at x {x}: {:?}",
                p.reflectance
            );
            black += 1;
        } else if shape == 0 && hi <= 0.25 + 1e-9 {
            left.push(p.emission[0]);
        } else if shape == 0 && lo >= 0.75 - 1e-9 {
            right.push(p.emission[0]);
        }
    }
    assert!(white > 0 && black > 0 && !left.is_empty() && !right.is_empty());
    // Red over the columns, times the scale: 2 (texels 0, 2) and 4 (texels 1, 3).
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(
        (mean(&left) / pi - 2.0).abs() < 0.3,
        "left {}",
        mean(&left) / pi
    );
    assert!(
        (mean(&right) / pi - 4.0).abs() < 0.3,
        "right {}",
        mean(&right) / pi
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A shape cut out everywhere (constant alpha 0) is left out of the solve; one with a
/// partial cut-out is solved as opaque and reported.
#[test]
fn alpha_cut_outs_are_left_out_or_reported() {
    let quad = |z: f32, alpha: &str| {
        format!(
            "Shape \"trianglemesh\" \"point3 P\" [ 0 0 {z}  1 0 {z}  1 1 {z}  0 1 {z} ] \
             \"integer indices\" [ 0 1 2  0 2 3 ] {alpha}\n"
        )
    };
    let text = format!(
        "WorldBegin\n\
         Texture \"holes\" \"float\" \"checkerboard\" \"float tex1\" 0 \"float tex2\" 1\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\n{}AttributeEnd\n\
         {}{}{}",
        quad(0.0, ""),
        quad(1.0, "\"float alpha\" 0"),
        quad(2.0, "\"texture alpha\" \"holes\""),
        quad(3.0, "\"float alpha\" 0.5"),
    );
    let desc = radiant_scene::parse_str(&text, "t.pbrt", std::path::Path::new(".")).unwrap();
    let scene = RadiosityScene::from_desc(&desc, &settings_with_area(1.0)).unwrap();
    let shapes: Vec<u32> = scene.tags.iter().map(|t| t.shape).collect();
    assert!(!shapes.contains(&1), "{shapes:?}");
    assert!(shapes.contains(&0) && shapes.contains(&2) && shapes.contains(&3));
    let reported = scene
        .warnings
        .iter()
        .filter(|w| w.message.contains("alpha cut-out"))
        .count();
    assert_eq!(reported, 2, "{:#?}", scene.warnings);
}
