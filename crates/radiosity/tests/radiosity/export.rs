//! The lit mesh and patch table written by `radiant radiosity --export/--patches`,
//! read back with independent readers (ply-rs-bw, serde_json).

use std::path::PathBuf;

use radiant_radiosity::mesh::meshed_scene::RadiosityScene;
use radiant_radiosity::output::export::{LitMesh, write_gltf, write_patch_csv, write_ply};
use radiant_radiosity::output::shading::Shading;
use radiant_radiosity::settings::RadiositySettings;
use radiant_radiosity::solve::Solution;
use radiant_radiosity::visibility::bvh::FaceVisibility;
use radiant_render::world::World;
use radiant_scene::builtin::cornell_box;

use crate::common::solve_to_end;

/// A scratch folder unique to this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiant-radiosity-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn lit_cornell() -> (RadiosityScene, Solution, LitMesh) {
    let desc = cornell_box();
    let settings = RadiositySettings {
        max_patch_area: Some(20_000.0),
        ..RadiositySettings::default()
    };
    let scene = RadiosityScene::from_desc(&desc, &settings).unwrap();
    let (world, _) = World::build(&desc).unwrap();
    let vis = FaceVisibility::new(&scene);
    let solution = solve_to_end(&scene, &world, &settings, &vis);
    let display = solution.display_radiosity(&scene.patches);
    let shading = Shading::new(&scene, &world, &display, &solution.irradiance, 0);
    let mesh = LitMesh::new(&scene, shading.mesh(), shading.vertex_radiosity());
    (scene, solution, mesh)
}

#[test]
fn ply_reads_back_in_both_encodings() {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let (_, _, mesh) = lit_cornell();
    assert!(
        mesh.colors
            .iter()
            .flatten()
            .all(|c| c.is_finite() && *c >= 0.0)
    );
    for ascii in [false, true] {
        let path = scratch(if ascii { "lit-ascii.ply" } else { "lit.ply" });
        write_ply(&path, &mesh, ascii).unwrap();
        let mut file = std::fs::File::open(&path).unwrap();
        let ply = Parser::<DefaultElement>::new().read_ply(&mut file).unwrap();
        let vertices = &ply.payload["vertex"];
        let faces = &ply.payload["face"];
        assert_eq!(vertices.len(), mesh.positions.len());
        assert_eq!(faces.len(), mesh.faces.len());
        let float = |e: &DefaultElement, name: &str| match e[name] {
            Property::Float(v) => v,
            ref other => panic!("{name}: {other:?}"),
        };
        // Binary is exact; ASCII prints the shortest decimal that reads back exactly.
        for (k, v) in vertices.iter().enumerate().step_by(17) {
            assert_eq!(
                [float(v, "x"), float(v, "y"), float(v, "z")],
                mesh.positions[k]
            );
            assert_eq!(
                [float(v, "red"), float(v, "green"), float(v, "blue")],
                mesh.colors[k]
            );
        }
        match &faces[3]["vertex_indices"] {
            Property::ListInt(list) => {
                assert_eq!(
                    list.iter().map(|&i| i as u32).collect::<Vec<_>>(),
                    mesh.faces[3]
                )
            }
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn gltf_and_glb_hold_positions_normals_and_float_colours() {
    let (_, _, mesh) = lit_cornell();
    let path = scratch("lit.gltf");
    write_gltf(&path, &mesh, false).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let bin = std::fs::read(path.with_file_name("lit.bin")).unwrap();
    assert_eq!(json["asset"]["version"], "2.0");
    assert_eq!(
        json["buffers"][0]["byteLength"].as_u64().unwrap() as usize,
        bin.len()
    );
    let attributes = &json["meshes"][0]["primitives"][0]["attributes"];
    let accessor = |name: &str| &json["accessors"][attributes[name].as_u64().unwrap() as usize];
    let colour = accessor("COLOR_0");
    assert_eq!(colour["componentType"], 5126); // FLOAT
    assert_eq!(colour["type"], "VEC3");
    assert_eq!(
        colour["count"].as_u64().unwrap() as usize,
        mesh.positions.len()
    );
    // Read vertex 5's colour through the accessor's buffer view.
    let view = &json["bufferViews"][colour["bufferView"].as_u64().unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap() as usize + 5 * 12;
    let read = |at: usize| f32::from_le_bytes(bin[at..at + 4].try_into().unwrap());
    assert_eq!(
        [read(offset), read(offset + 4), read(offset + 8)],
        mesh.colors[5]
    );
    // Bounds of POSITION as the format requires.
    let position = accessor("POSITION");
    let max_y = mesh.positions.iter().map(|p| p[1]).fold(f32::MIN, f32::max);
    assert_eq!(position["max"][1].as_f64().unwrap() as f32, max_y);
    // Indices: every face as triangles.
    let indices = &json["accessors"][json["meshes"][0]["primitives"][0]["indices"]
        .as_u64()
        .unwrap() as usize];
    let triangles: usize = mesh.faces.iter().map(|f| f.len() - 2).sum();
    assert_eq!(indices["count"].as_u64().unwrap() as usize, 3 * triangles);

    // GLB: header, a JSON chunk and a BIN chunk holding the same buffer.
    let glb_path = scratch("lit.glb");
    write_gltf(&glb_path, &mesh, true).unwrap();
    let glb = std::fs::read(&glb_path).unwrap();
    let word = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&glb[0..4], b"glTF");
    assert_eq!(word(4), 2);
    assert_eq!(word(8), glb.len());
    let json_length = word(12);
    assert_eq!(&glb[16..20], b"JSON");
    let glb_json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_length]).unwrap();
    assert!(glb_json["buffers"][0].get("uri").is_none());
    let bin_at = 20 + json_length;
    assert_eq!(&glb[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(&glb[bin_at + 8..bin_at + 8 + bin.len()], &bin[..]);
}

#[test]
fn patch_table_has_a_row_per_patch_with_its_balance() {
    // Each row's B = E + rho H (the radiosity equation, per band), to the CSV's
    // shortest round-trip decimals.
    let (scene, solution, _) = lit_cornell();
    let path = scratch("patches.csv");
    write_patch_csv(&path, &scene, &solution).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 20);
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), scene.patches.len());
    for row in &rows {
        for band in ["r", "g", "b"] {
            let get = |q: &str| row[column(&format!("{q}_{band}"))];
            let expected = get("E") + get("rho") * get("H");
            assert!(
                (get("B") - expected).abs() <= 1e-9 * expected.max(1.0),
                "{row:?}"
            );
        }
    }
}
