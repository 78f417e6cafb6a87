//! Real scene files: the canonical scenes under `scenes/` must equal the scenes built in
//! code, and Bitterli's Cornell box (pbrt-v4 syntax) must parse without warnings.

use radiant_math::color::Rgb;
use radiant_math::{Mat4, Vec3};
use radiant_scene::builtin::builtin_scene;
use radiant_scene::{Geometry, SceneDesc, ShapeDesc, parse_file};

/// Geometry and transforms are written with 6 significant digits; 1e-4 (relative to
/// the mm-scale coordinates, absolute below 1) is far above the f32 round-off of
/// parsing and composing, and far below any real difference.
const TOL: f32 = 1e-4;

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= TOL * a.abs().max(b.abs()).max(1.0)
}

fn close_v(a: &[Vec3], b: &[Vec3]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| (0..3).all(|k| close(p[k], q[k])))
}

fn close_m(a: &Mat4, b: &Mat4) -> bool {
    a.to_cols_array()
        .iter()
        .zip(b.to_cols_array())
        .all(|(x, y)| close(*x, y))
}

fn same_geometry(a: &Geometry, b: &Geometry) -> bool {
    match (a, b) {
        (
            Geometry::TriangleMesh {
                positions: pa,
                indices: ia,
                normals: na,
                uvs: ua,
            },
            Geometry::TriangleMesh {
                positions: pb,
                indices: ib,
                normals: nb,
                uvs: ub,
            },
        ) => close_v(pa, pb) && ia == ib && na == nb && ua == ub,
        (
            Geometry::Sphere {
                radius: ra,
                z_min: za,
                z_max: zb,
                phi_max_deg: fa,
            },
            Geometry::Sphere {
                radius: rb,
                z_min: zc,
                z_max: zd,
                phi_max_deg: fb,
            },
        ) => close(*ra, *rb) && close(*za, *zc) && close(*zb, *zd) && close(*fa, *fb),
        _ => false,
    }
}

fn same_shape(a: &ShapeDesc, b: &ShapeDesc) -> bool {
    same_geometry(&a.geometry, &b.geometry)
        && close_m(&a.render_from_object.m, &b.render_from_object.m)
        && a.reverse_orientation == b.reverse_orientation
        && a.material == b.material
        && a.area_light == b.area_light
}

fn assert_same_scene(name: &str, file: &SceneDesc, code: &SceneDesc) {
    assert!(file.warnings.is_empty(), "{name}: {:?}", file.warnings);
    assert_eq!(file.materials, code.materials, "{name}: materials");
    assert_eq!(file.shapes.len(), code.shapes.len(), "{name}: shape count");
    for (i, (a, b)) in file.shapes.iter().zip(&code.shapes).enumerate() {
        assert!(same_shape(a, b), "{name}: shape {i} differs:\n{a:?}\n{b:?}");
    }
    assert_eq!(file.lights, code.lights, "{name}: lights");
    assert!(file.objects.is_empty() && file.instances.is_empty());
    assert!(
        close_m(
            &file.camera.camera_from_world.m,
            &code.camera.camera_from_world.m
        ),
        "{name}: camera"
    );
    assert_eq!(file.camera.kind, code.camera.kind, "{name}: camera kind");
    let strip = |s: &SceneDesc| {
        let (mut f, mut sa, mut fi) = (s.film.clone(), s.sampler.clone(), s.filter.clone());
        let here = radiant_scene::FileLoc::builtin("test");
        (f.loc, sa.loc, fi.loc) = (here.clone(), here.clone(), here);
        (f, sa, fi)
    };
    assert_eq!(strip(file), strip(code), "{name}: film, sampler, filter");
    assert_eq!(file.integrator.name, code.integrator.name);
    assert_eq!(
        file.integrator.params.int("maxdepth", -1).unwrap(),
        code.integrator.params.int("maxdepth", -2).unwrap()
    );
}

#[test]
fn canonical_scene_files_equal_the_scenes_in_code() {
    let dir = radiant_testkit::repo_path("scenes");
    for name in radiant_scene::builtin::BUILTIN_SCENES {
        let path = dir.join(format!("{name}.pbrt"));
        let file = parse_file(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(file.source.as_deref(), Some(path.as_path()));
        assert_same_scene(name, &file, &builtin_scene(name).unwrap());
    }
}

fn bitterli() -> SceneDesc {
    let path =
        radiant_testkit::shared_root().join("data/scenes/bitterli/cornell-box/scene-v4.pbrt");
    parse_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn bitterli_cornell_box_parses_cleanly() {
    let scene = bitterli();
    // Every parameter (uv, N, P, indices, L, reflectance…) is used; Accelerator is
    // accepted silently.
    assert!(scene.warnings.is_empty(), "{:#?}", scene.warnings);
    assert_eq!(scene.shapes.len(), 8);
    assert_eq!(scene.materials.len(), 8);
    assert_eq!((scene.film.xresolution, scene.film.yresolution), (64, 64));
    assert_eq!(scene.integrator.name, "path");
    assert_eq!(scene.integrator.params.int("maxdepth", 5).unwrap(), 4);
    assert_eq!(scene.sampler.pixel_samples, 1);
    assert_eq!(scene.filter.radius.x, 1.5);
    for s in &scene.shapes {
        let Geometry::TriangleMesh {
            normals,
            uvs,
            positions,
            ..
        } = &s.geometry
        else {
            panic!("Bitterli's box is all triangle meshes");
        };
        assert_eq!(normals.as_ref().map(Vec::len), Some(positions.len()));
        assert_eq!(uvs.as_ref().map(Vec::len), Some(positions.len()));
    }
    // The camera: Transform [1 0 0 0 0 1 0 0 0 0 -1 0 0 -1 6.8 1] (columns) puts the
    // eye at world (0, 1, 6.8).
    let eye = scene.camera.camera_from_world.inverse().point(Vec3::ZERO);
    assert!((eye - Vec3::new(0.0, 1.0, 6.8)).length() < 1e-5, "{eye}");
}

/// pbrt-v4 turns a triangle's geometric normal to the side of its shading normal N
/// when N is given, and a diffuse area light emits on the side of the geometric
/// normal. Bitterli's light must therefore emit downwards, into the box: its N, its
/// winding normal (v1 - v0) × (v2 - v0) and the direction to the floor all agree.
#[test]
fn bitterli_light_emits_into_the_box() {
    let scene = bitterli();
    let lights: Vec<&ShapeDesc> = scene
        .shapes
        .iter()
        .filter(|s| s.area_light.is_some())
        .collect();
    assert_eq!(lights.len(), 1);
    let light = lights[0];
    let al = light.area_light.as_ref().unwrap();
    assert_eq!(al.l, Rgb::new(17.0, 12.0, 4.0));
    assert!(!al.two_sided && !light.reverse_orientation);
    let Geometry::TriangleMesh {
        positions,
        indices,
        normals: Some(normals),
        ..
    } = &light.geometry
    else {
        panic!("light is a mesh with normals");
    };
    for t in indices.chunks(3) {
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
        let winding = (b - a).cross(c - a).normalize();
        let shading = (0..3)
            .map(|k| normals[t[k] as usize])
            .sum::<Vec3>()
            .normalize();
        assert!(winding.dot(shading) > 0.999);
        assert!(shading.dot(Vec3::NEG_Y) > 0.999);
        // The floor (y = 0) lies on the emitting side.
        assert!((Vec3::ZERO - a).dot(shading) > 0.0);
    }
}
