//! The malformed-scene corpus: every file under `tests/scenes/malformed/` must fail with
//! an error at the exact `file:line:column` of its fault, and never panic.

use std::path::PathBuf;

use radiant_scene::parse_file;

fn corpus(name: &str) -> PathBuf {
    radiant_testkit::repo_path("tests/scenes/malformed").join(name)
}

/// (scene file, file the error must name (relative to the corpus), line, column,
/// words the message must contain).
const CASES: &[(&str, &str, u32, u32, &[&str])] = &[
    (
        "texture_undefined.pbrt",
        "texture_undefined.pbrt",
        2,
        20,
        &["\"reflectance\"", "undefined spectrum texture \"nowhere\""],
    ),
    (
        "texture_wrong_type.pbrt",
        "texture_wrong_type.pbrt",
        3,
        20,
        &["needs a spectrum texture", "\"bumps\" is a float texture"],
    ),
    (
        "texture_missing_image.pbrt",
        "texture_missing_image.pbrt",
        3,
        3,
        &["no-such-image.png", "not found"],
    ),
    (
        "texture_bad_filter.pbrt",
        "texture_bad_filter.pbrt",
        3,
        3,
        &["unknown image filter \"gaussian\""],
    ),
    (
        "texture_unknown_class.pbrt",
        "texture_unknown_class.pbrt",
        2,
        1,
        &["unknown texture class \"plaid\""],
    ),
    (
        "texture_undefined_roughness.pbrt",
        "texture_undefined_roughness.pbrt",
        3,
        46,
        &["\"uroughness\"", "undefined float texture \"u\""],
    ),
    (
        "unknown_directive.pbrt",
        "unknown_directive.pbrt",
        4,
        3,
        &["unknown directive 'Shaep'"],
    ),
    (
        "bad_number.pbrt",
        "bad_number.pbrt",
        2,
        33,
        &["bad number '1.2.3'"],
    ),
    (
        "unterminated_string.pbrt",
        "unterminated_string.pbrt",
        2,
        15,
        &["unterminated string"],
    ),
    (
        "missing_plymesh.pbrt",
        "missing_plymesh.pbrt",
        3,
        21,
        &["does-not-exist.ply", "cannot open"],
    ),
    (
        "missing_include.pbrt",
        "missing_include.pbrt",
        3,
        1,
        &["no-such-file.pbrt", "cannot read included file"],
    ),
    (
        "wrong_param_type.pbrt",
        "wrong_param_type.pbrt",
        2,
        22,
        &["\"fov\"", "expected \"float\""],
    ),
    (
        "unknown_named_material.pbrt",
        "unknown_named_material.pbrt",
        3,
        1,
        &["unknown named material \"whit\""],
    ),
    (
        "index_count.pbrt",
        "index_count.pbrt",
        4,
        5,
        &["indices", "multiple of 3"],
    ),
    (
        "nan_vertex.pbrt",
        "nan_vertex.pbrt",
        4,
        5,
        &["\"P\"", "vertex 1", "not finite"],
    ),
    (
        "attribute_end.pbrt",
        "attribute_end.pbrt",
        4,
        3,
        &["AttributeEnd without a matching AttributeBegin"],
    ),
    (
        "nan_in_ply.pbrt",
        "nan_in_ply.pbrt",
        2,
        17,
        &["nan.ply", "vertex 2", "non-finite"],
    ),
    (
        "error_in_include.pbrt",
        "inc/broken.pbrt",
        2,
        16,
        &["\"radius\" must be positive"],
    ),
    (
        "index_out_of_range.pbrt",
        "index_out_of_range.pbrt",
        3,
        22,
        &["index 3", "3 vertices"],
    ),
    (
        "unclosed_attribute.pbrt",
        "unclosed_attribute.pbrt",
        2,
        1,
        &["AttributeBegin without a matching end"],
    ),
    (
        "shape_before_world.pbrt",
        "shape_before_world.pbrt",
        2,
        1,
        &["only allowed after WorldBegin"],
    ),
    (
        "integer_expected.pbrt",
        "integer_expected.pbrt",
        1,
        36,
        &["parameter \"integer xresolution\": 64.5 is not an integer"],
    ),
    (
        "envmap_with_l.pbrt",
        "envmap_with_l.pbrt",
        2,
        62,
        &["either \"L\" or \"filename\""],
    ),
    (
        "normal_count.pbrt",
        "normal_count.pbrt",
        3,
        5,
        &["2 normals for 3 vertices"],
    ),
    (
        "area_light_image_and_l.pbrt",
        "area_light_image_and_l.pbrt",
        2,
        56,
        &["either \"L\" or \"filename\""],
    ),
    (
        "mix_amount_wrong_texture_type.pbrt",
        "mix_amount_wrong_texture_type.pbrt",
        5,
        47,
        &[
            "\"amount\"",
            "needs a float texture",
            "\"tint\" is a spectrum texture",
        ],
    ),
    (
        "coat_thickness_texture_undefined.pbrt",
        "coat_thickness_texture_undefined.pbrt",
        2,
        26,
        &["\"thickness\"", "undefined float texture \"nowhere\""],
    ),
    (
        "conductor_eta_wrong_texture_type.pbrt",
        "conductor_eta_wrong_texture_type.pbrt",
        3,
        28,
        &["needs a spectrum texture", "\"w\" is a float texture"],
    ),
];

#[test]
fn every_malformed_scene_fails_at_its_fault() {
    for (scene, blamed, line, column, words) in CASES {
        let result = std::panic::catch_unwind(|| parse_file(&corpus(scene)));
        let Ok(result) = result else {
            panic!("{scene}: the parser panicked");
        };
        let message = match result {
            Ok(_) => panic!("{scene}: parsed without error"),
            Err(e) => e.to_string(),
        };
        let expected_loc = format!("{}:{line}:{column}: error:", corpus(blamed).display());
        assert!(
            message.starts_with(&expected_loc),
            "{scene}: expected the error at {expected_loc}, got: {message}"
        );
        for w in *words {
            assert!(
                message.contains(w),
                "{scene}: message lacks \"{w}\": {message}"
            );
        }
    }
}

#[test]
fn the_corpus_has_no_untested_file() {
    let dir = corpus("");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".pbrt"))
        .collect();
    files.sort();
    let mut tested: Vec<String> = CASES.iter().map(|c| c.0.to_string()).collect();
    tested.sort();
    assert_eq!(files, tested);
}

#[test]
fn an_unreadable_scene_names_its_path() {
    let path = corpus("no-such-scene.pbrt");
    let e = parse_file(&path).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{}: error: cannot read scene", path.display())),
        "{e}"
    );
}
