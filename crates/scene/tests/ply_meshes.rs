//! PLY and OBJ meshes written here in every encoding and read back.

use std::path::{Path, PathBuf};

use radiant_math::{Vec2, Vec3};
use radiant_scene::obj::read_obj;
use radiant_scene::ply::read_ply;
use radiant_scene::{Geometry, parse_str};

/// A square (vertices 0 1 2 3, one quad) with a triangle beside it (1 4 2).
const POSITIONS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [2.0, 0.5, 0.25],
];
const FACES: [&[i32]; 2] = [&[0, 1, 2, 3], &[1, 4, 2]];

#[derive(Clone, Copy)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiant-ply-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes the test mesh: float positions, double normals (0, 0, 1), float uvs (x, y)
/// under the names `u`/`v` or `s`/`t`, and faces as `list uchar int`.
fn write_ply(path: &Path, enc: Encoding, uv_names: (&str, &str), positions: &[[f32; 3]]) {
    let format = match enc {
        Encoding::Ascii => "ascii",
        Encoding::Little => "binary_little_endian",
        Encoding::Big => "binary_big_endian",
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment written by radiant's tests\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n\
         property double nx\nproperty double ny\nproperty double nz\n\
         property float {}\nproperty float {}\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        uv_names.0,
        uv_names.1,
        FACES.len()
    )
    .into_bytes();
    let f32b = |v: f32| match enc {
        Encoding::Big => v.to_be_bytes(),
        _ => v.to_le_bytes(),
    };
    let f64b = |v: f64| match enc {
        Encoding::Big => v.to_be_bytes(),
        _ => v.to_le_bytes(),
    };
    let i32b = |v: i32| match enc {
        Encoding::Big => v.to_be_bytes(),
        _ => v.to_le_bytes(),
    };
    for p in positions {
        match enc {
            Encoding::Ascii => {
                out.extend(format!("{} {} {} 0 0 1 {} {}\n", p[0], p[1], p[2], p[0], p[1]).bytes())
            }
            _ => {
                for c in p {
                    out.extend(f32b(*c));
                }
                for n in [0.0, 0.0, 1.0] {
                    out.extend(f64b(n));
                }
                out.extend(f32b(p[0]));
                out.extend(f32b(p[1]));
            }
        }
    }
    for f in FACES {
        match enc {
            Encoding::Ascii => {
                let list: Vec<String> = f.iter().map(i32::to_string).collect();
                out.extend(format!("{} {}\n", f.len(), list.join(" ")).bytes());
            }
            _ => {
                out.push(f.len() as u8);
                for &i in f {
                    out.extend(i32b(i));
                }
            }
        }
    }
    std::fs::write(path, out).unwrap();
}

#[test]
fn ply_in_every_encoding_reads_back() {
    let dir = temp_dir("encodings");
    for (enc, uv_names, name) in [
        (Encoding::Ascii, ("u", "v"), "ascii.ply"),
        (Encoding::Little, ("s", "t"), "little.ply"),
        (Encoding::Big, ("texture_u", "texture_v"), "big.ply"),
    ] {
        let path = dir.join(name);
        write_ply(&path, enc, uv_names, &POSITIONS);
        let mesh = read_ply(&path).unwrap_or_else(|e| panic!("{e}"));
        let expected: Vec<Vec3> = POSITIONS.iter().map(|p| Vec3::from(*p)).collect();
        assert_eq!(mesh.positions, expected, "{name}");
        assert_eq!(mesh.triangles, vec![1, 4, 2], "{name}");
        // The quad v0 v1 v2 v3 becomes the patch (p00, p10, p01, p11) = (v0, v1, v3, v2).
        assert_eq!(mesh.quads, vec![0, 1, 3, 2], "{name}");
        assert_eq!(mesh.normals, Some(vec![Vec3::Z; 5]), "{name}");
        let uvs: Vec<Vec2> = POSITIONS.iter().map(|p| Vec2::new(p[0], p[1])).collect();
        assert_eq!(mesh.uvs, Some(uvs), "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plymesh_shapes_split_into_triangles_and_bilinear_patches() {
    let dir = temp_dir("shape");
    write_ply(&dir.join("m.ply"), Encoding::Little, ("u", "v"), &POSITIONS);
    let scene = parse_str(
        "WorldBegin\nAreaLightSource \"diffuse\" \"float power\" 1\nShape \"plymesh\" \"string filename\" \"m.ply\"\n",
        "t.pbrt",
        &dir,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.shapes.len(), 2);
    assert!(
        matches!(&scene.shapes[0].geometry, Geometry::TriangleMesh { indices, .. } if indices == &[1, 4, 2])
    );
    assert!(
        matches!(&scene.shapes[1].geometry, Geometry::BilinearMesh { indices, .. } if indices == &[0, 1, 3, 2])
    );
    // Power is shared by the whole shape: the unit square plus the triangle
    // (1,0,0) (2,0.5,0.25) (1,1,0) of area |(1, 0.5, 0.25) × (0, 1, 0)| / 2 =
    // sqrt(1.0625) / 2, so Φ = π A L = 1 for white L.
    let area = 1.0 + 0.5 * 1.0625f32.sqrt();
    let l = scene.shapes[0].area_light.as_ref().unwrap().l;
    assert_eq!(Some(l), scene.shapes[1].area_light.as_ref().map(|a| a.l));
    assert!((std::f32::consts::PI * area * l.luminance() - 1.0).abs() < 1e-5);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_ply_data_is_an_error_naming_the_file_and_element() {
    let dir = temp_dir("bad");
    let mut nan = POSITIONS;
    nan[3][2] = f32::INFINITY;
    let path = dir.join("inf.ply");
    write_ply(&path, Encoding::Big, ("u", "v"), &nan);
    let e = read_ply(&path).unwrap_err().to_string();
    assert!(
        e.starts_with(&path.display().to_string()) && e.contains("vertex 3"),
        "{e}"
    );

    // Four vertices only: the triangle's index 4 is out of range.
    let path = dir.join("range.ply");
    write_ply(&path, Encoding::Ascii, ("u", "v"), &POSITIONS[..4]);
    let e = read_ply(&path).unwrap_err().to_string();
    assert!(e.contains("triangle 0 uses vertex 4"), "{e}");

    std::fs::write(
        dir.join("junk.ply"),
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
    )
    .unwrap();
    assert!(read_ply(&dir.join("junk.ply")).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An ASCII PLY file: `vertex_props` as the vertex element's properties, `rows` as its
/// data lines (three vertices), then `faces` as written after a face element header.
fn ascii_ply(vertex_props: &str, rows: [&str; 3], faces: &str) -> String {
    let props: String = vertex_props
        .split_whitespace()
        .map(|p| format!("property float {p}\n"))
        .collect();
    format!(
        "ply\nformat ascii 1.0\nelement vertex 3\n{props}{faces_header}end_header\n{}\n{}\n{}\n{faces}",
        rows[0],
        rows[1],
        rows[2],
        faces_header = if faces.is_empty() {
            ""
        } else {
            "element face 1\nproperty list uchar int vertex_indices\n"
        },
    )
}

#[test]
fn ply_without_faces_or_with_half_an_attribute_is_reported() {
    let dir = temp_dir("notes");
    let read = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        read_ply(&path).unwrap_or_else(|e| panic!("{e}"))
    };
    let points = read(
        "points.ply",
        &ascii_ply("x y z", ["0 0 0", "1 0 0", "0 1 0"], ""),
    );
    assert!(points.triangles.is_empty());
    assert_eq!(points.notes.len(), 1, "{:?}", points.notes);
    assert!(
        points.notes[0].contains("no 'face' element"),
        "{:?}",
        points.notes
    );

    let half = read(
        "half.ply",
        &ascii_ply(
            "x y z nx ny u",
            ["0 0 0 0 0 0", "1 0 0 0 0 1", "0 1 0 0 0 0"],
            "3 0 1 2\n",
        ),
    );
    assert_eq!(half.triangles, [0, 1, 2]);
    assert!(half.normals.is_none() && half.uvs.is_none());
    assert_eq!(half.notes.len(), 2, "{:?}", half.notes);
    assert!(
        half.notes[0].contains("only nx, ny; normals ignored"),
        "{:?}",
        half.notes
    );
    assert!(
        half.notes[1].contains("need u and v, but the file has only u"),
        "{:?}",
        half.notes
    );

    // Each note becomes a warning at the parameter that named the file.
    let scene = format!(
        "WorldBegin\nShape \"plymesh\" \"string filename\" \"{}\"\n",
        dir.join("points.ply").display()
    );
    let s = parse_str(&scene, "t.pbrt", &dir).unwrap_or_else(|e| panic!("{e}"));
    let w: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("t.pbrt:2:17: warning: Shape \"plymesh\": ")
            && w[0].contains("renders nothing"),
        "{w:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ply_data_the_header_does_not_describe_is_an_error() {
    let dir = temp_dir("extra");
    let err = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = read_ply(&path).unwrap_err().to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        e
    };
    let rows = ["0 0 0", "1 0 0 7", "0 1 0"];
    let e = err(
        "tokens.ply",
        ascii_ply("x y z", rows, "3 0 1 2\n").as_bytes(),
    );
    assert!(
        e.contains("'vertex' 1 has 4 values on its line, but its properties take 3"),
        "{e}"
    );
    let e = err(
        "face_tokens.ply",
        ascii_ply("x y z", ["0 0 0", "1 0 0", "0 1 0"], "3 0 1 2 9\n").as_bytes(),
    );
    assert!(e.contains("'face' 0 has 5 values"), "{e}");
    let ok = ascii_ply("x y z", ["0 0 0", "1 0 0", "0 1 0"], "3 0 1 2\n");
    let e = err("ascii_tail.ply", format!("{ok}\n0 0 1\n").as_bytes());
    assert!(e.contains("after the last element"), "{e}");
    // White space after an ASCII file's data is fine.
    std::fs::write(dir.join("blank_tail.ply"), format!("{ok}\n\n")).unwrap();
    assert!(read_ply(&dir.join("blank_tail.ply")).is_ok());

    let path = dir.join("bin.ply");
    write_ply(&path, Encoding::Little, ("u", "v"), &POSITIONS);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes.extend_from_slice(&[0, 0, 0, 0]);
    let e = err("bin_tail.ply", &bytes);
    assert!(e.contains("4 bytes of data after the last element"), "{e}");

    let misnamed = ascii_ply("x y z", ["0 0 0", "1 0 0", "0 1 0"], "3 0 1 2\n")
        .replace("vertex_indices", "vertex_idx");
    let e = err("misnamed.ply", misnamed.as_bytes());
    assert!(
        e.contains("no vertex index list") && e.contains("'vertex_idx'"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn obj_errors_name_the_line() {
    let dir = temp_dir("objline");
    let path = dir.join("bad.obj");
    std::fs::write(&path, "# a\nv 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n").unwrap();
    let e = read_obj(&path).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}: error: cannot read OBJ file: line 4: position parse error ('v 1 x 0')",
            path.display()
        )
    );
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 q\n").unwrap();
    let e = read_obj(&path).unwrap_err().to_string();
    assert!(e.contains("line 4: face parse error"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn obj_meshes_are_triangulated() {
    let dir = temp_dir("obj");
    let path = dir.join("m.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
         f 1/1/1 2/2/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    let mesh = read_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mesh.triangles.len(), 6);
    let area: f32 = mesh
        .triangles
        .chunks(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
            0.5 * (b - a).cross(c - a).z
        })
        .sum();
    assert!(
        (area - 1.0).abs() < 1e-6,
        "the fan keeps the winding: area {area}"
    );
    assert_eq!(
        mesh.normals.as_ref().map(Vec::len),
        Some(mesh.positions.len())
    );
    assert!(mesh.uvs.is_some());
    let scene = parse_str(
        "WorldBegin\nShape \"objmesh\" \"string filename\" \"m.obj\"\n",
        "t.pbrt",
        &dir,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.shapes.len(), 1);
    let e = parse_str(
        "WorldBegin\nShape \"objmesh\" \"string filename\" \"none.obj\"\n",
        "t.pbrt",
        &dir,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("t.pbrt:2:17: error:") && e.contains("none.obj"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
