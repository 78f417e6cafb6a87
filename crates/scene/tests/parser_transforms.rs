//! Transform semantics against hand-computed matrices, named coordinate systems,
//! object instancing and includes.

use std::path::{Path, PathBuf};

use radiant_math::{Mat4, Vec3, Vec4};
use radiant_scene::{SceneDesc, parse_str};

fn parse(text: &str) -> SceneDesc {
    parse_str(text, "test.pbrt", Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// Transforms are composed in f32 from exactly representable inputs (or sin/cos of
/// 90°); 1e-5 covers the rounding of a few products.
fn assert_matrix(m: &Mat4, rows: [[f32; 4]; 4]) {
    let expected = Mat4::from_cols_array_2d(&rows).transpose();
    for (a, b) in m.to_cols_array().iter().zip(expected.to_cols_array()) {
        assert!((a - b).abs() < 1e-5, "got {m:?}\nexpected rows {rows:?}");
    }
}

fn shape_matrix(text: &str) -> Mat4 {
    let scene = parse(&format!("WorldBegin\n{text}\nShape \"sphere\"\n"));
    scene.shapes[0].render_from_object.m
}

#[test]
fn directives_post_multiply_the_ctm() {
    // Translate then Scale: M = T · S, so the scale applies to the object first.
    assert_matrix(
        &shape_matrix("Translate 1 2 3\nScale 2 3 4"),
        [
            [2.0, 0.0, 0.0, 1.0],
            [0.0, 3.0, 0.0, 2.0],
            [0.0, 0.0, 4.0, 3.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
    // Scale then Translate: M = S · T, the translation is scaled.
    assert_matrix(
        &shape_matrix("Scale 2 3 4\nTranslate 1 2 3"),
        [
            [2.0, 0.0, 0.0, 2.0],
            [0.0, 3.0, 0.0, 6.0],
            [0.0, 0.0, 4.0, 12.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
    // Rotate 90° about +z (right-handed): x → y, y → -x.
    assert_matrix(
        &shape_matrix("Rotate 90 0 0 1"),
        [
            [0.0, -1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
    // The axis need not be normalised.
    assert_matrix(
        &shape_matrix("Rotate -90 5 0 0"),
        [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
}

#[test]
fn transform_matrices_are_written_column_by_column() {
    // The last four numbers are the translation column.
    let m = shape_matrix("Translate 9 9 9\nTransform [ 2 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 ]");
    assert_matrix(
        &m,
        [
            [2.0, 0.0, 0.0, 5.0],
            [0.0, 1.0, 0.0, 6.0],
            [0.0, 0.0, 1.0, 7.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
    // ConcatTransform post-multiplies: Scale 2 · Translate(5, 6, 7).
    let m = shape_matrix("Scale 2 2 2\nConcatTransform [ 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 ]");
    assert_matrix(
        &m,
        [
            [2.0, 0.0, 0.0, 10.0],
            [0.0, 2.0, 0.0, 12.0],
            [0.0, 0.0, 2.0, 14.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
    // Identity resets.
    assert_matrix(
        &shape_matrix("Scale 2 2 2\nIdentity"),
        Mat4::IDENTITY.to_cols_array_2d(),
    );
}

#[test]
fn look_at_builds_pbrts_left_handed_camera() {
    // Looking along +x with +y up: camera z = world x, camera x = up × dir = -z,
    // camera y = y; the eye (1, 2, 3) goes to the origin.
    let scene = parse("LookAt 1 2 3  2 2 3  0 1 0\nCamera \"perspective\"\nWorldBegin\n");
    assert_matrix(
        &scene.camera.camera_from_world.m,
        [
            [0.0, 0.0, -1.0, 3.0],
            [0.0, 1.0, 0.0, -2.0],
            [1.0, 0.0, 0.0, -1.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
    // Scale -1 1 1 before LookAt mirrors camera x (radiant's right-handed camera).
    let scene =
        parse("Scale -1 1 1\nLookAt 1 2 3  2 2 3  0 1 0\nCamera \"perspective\"\nWorldBegin\n");
    assert_matrix(
        &scene.camera.camera_from_world.m,
        [
            [0.0, 0.0, 1.0, -3.0],
            [0.0, 1.0, 0.0, -2.0],
            [1.0, 0.0, 0.0, -1.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
    // WorldBegin resets the CTM: the world is not seen through the camera transform.
    assert_eq!(
        scene.camera.camera_from_world.m.w_axis,
        Vec4::new(-3.0, -2.0, -1.0, 1.0)
    );
}

#[test]
fn coordinate_systems_save_and_restore_the_ctm() {
    let scene = parse(
        "LookAt 1 2 3  2 2 3  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
         Translate 0 0 5\nCoordinateSystem \"lifted\"\nIdentity\n\
         AttributeBegin\n  CoordSysTransform \"camera\"\n  LightSource \"point\"\n\
           LightSource \"spot\" \"point3 to\" [ 0 0 1 ]\nAttributeEnd\n\
         CoordSysTransform \"lifted\"\nShape \"sphere\"\n",
    );
    // "camera" is world-from-camera: a light at the camera origin sits at the eye and
    // a spot aimed along camera +z points along the view direction (world +x).
    match &scene.lights[0] {
        radiant_scene::LightDesc::Point { position, .. } => {
            assert!((*position - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-5)
        }
        other => panic!("{other:?}"),
    }
    match &scene.lights[1] {
        radiant_scene::LightDesc::Spot { direction, .. } => {
            assert!((*direction - Vec3::X).length() < 1e-5)
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        scene.shapes[0].render_from_object.m.w_axis,
        Vec4::new(0.0, 0.0, 5.0, 1.0)
    );
}

#[test]
fn attribute_blocks_restore_the_graphics_state() {
    let scene = parse(
        "WorldBegin\nAttributeBegin\n  Translate 1 0 0\n  ReverseOrientation\n  Material \"conductor\"\n\
           Shape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n\
         TransformBegin\n  Translate 0 2 0\n  Material \"interface\"\nTransformEnd\nShape \"disk\"\n",
    );
    let [inner, outer, after] = [&scene.shapes[0], &scene.shapes[1], &scene.shapes[2]];
    assert!(inner.reverse_orientation && !outer.reverse_orientation);
    assert_eq!(inner.render_from_object.m.w_axis.x, 1.0);
    assert!(outer.render_from_object.is_identity());
    assert_ne!(inner.material, outer.material);
    // TransformEnd restores only the transform: the interface material stays current.
    assert!(after.render_from_object.is_identity());
    assert_eq!(
        scene.materials[after.material as usize],
        radiant_scene::MaterialDesc::Interface
    );
    assert_eq!(
        scene.warnings.len(),
        1,
        "deprecation note: {:?}",
        scene.warnings
    );
}

#[test]
fn object_instances_carry_their_transform() {
    let scene = parse(
        "WorldBegin\nObjectInstance \"later\"\n\
         ObjectBegin \"ball\"\n  Translate 1 0 0\n  AreaLightSource \"diffuse\"\n  Shape \"sphere\"\nObjectEnd\n\
         Translate 0 5 0\nObjectInstance \"ball\"\nObjectBegin \"later\"\nShape \"disk\"\nObjectEnd\n",
    );
    assert_eq!(scene.objects.len(), 2);
    assert!(scene.shapes.is_empty());
    let ball = &scene.objects[0];
    assert_eq!(ball.name, "ball");
    // The prototype keeps its definition-time CTM; the instance adds the CTM at use.
    assert_eq!(
        ball.shapes[0].render_from_object.m.w_axis,
        Vec4::new(1.0, 0.0, 0.0, 1.0)
    );
    // pbrt-v4 drops area lights inside object definitions, with a warning.
    assert!(ball.shapes[0].area_light.is_none());
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.message.contains("lose their emission"))
    );
    assert_eq!(scene.instances.len(), 2);
    assert_eq!(scene.instances[0].object, 1, "forward reference resolved");
    assert!(scene.instances[0].render_from_instance.is_identity());
    assert_eq!(scene.instances[1].object, 0);
    assert_eq!(
        scene.instances[1].render_from_instance.m.w_axis,
        Vec4::new(0.0, 5.0, 0.0, 1.0)
    );

    let e = parse_str(
        "WorldBegin\nObjectInstance \"nothing\"\n",
        "t.pbrt",
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("t.pbrt:2:1: error: ObjectInstance of unknown object"),
        "{e}"
    );
}

fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiant-parser-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("parts/deeper")).unwrap();
    dir
}

#[test]
fn includes_resolve_relative_to_the_including_file() {
    let dir = temp_dir("include");
    std::fs::write(
        dir.join("main.pbrt"),
        "WorldBegin\nInclude \"parts/a.pbrt\"\nShape \"disk\"\n",
    )
    .unwrap();
    // parts/a.pbrt includes deeper/b.pbrt relative to parts/.
    std::fs::write(
        dir.join("parts/a.pbrt"),
        "Translate 0 0 7\nImport \"deeper/b.pbrt\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("parts/deeper/b.pbrt"),
        "# b\nShape \"sphere\" \"float radius\" [ 2 ]\n",
    )
    .unwrap();
    let scene = radiant_scene::parse_file(&dir.join("main.pbrt")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.shapes.len(), 2);
    // Textual inclusion: the CTM set in a.pbrt still applies in main.pbrt afterwards.
    assert_eq!(scene.shapes[1].render_from_object.m.w_axis.z, 7.0);
    assert_eq!(scene.shapes[0].loc.line, 2);
    assert!(scene.shapes[0].loc.file.ends_with("b.pbrt"));

    // An error inside an included file names that file and line.
    std::fs::write(dir.join("parts/deeper/b.pbrt"), "\n\n   Bogus\n").unwrap();
    let e = radiant_scene::parse_file(&dir.join("main.pbrt"))
        .unwrap_err()
        .to_string();
    let b = dir.join("parts").join("deeper/b.pbrt");
    assert!(
        e.starts_with(&format!("{}:3:4: error: unknown directive", b.display())),
        "{e}"
    );

    // A file including itself stops at the nesting limit instead of overflowing.
    std::fs::write(dir.join("self.pbrt"), "Include \"self.pbrt\"\n").unwrap();
    let e = radiant_scene::parse_file(&dir.join("self.pbrt"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("nested deeper"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
