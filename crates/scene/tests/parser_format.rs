//! Parts of pbrt-v4's format beyond the directives: gzip-compressed includes and PLY
//! meshes, Loop subdivision surfaces, and meshes with broken normals.

use std::io::Write;
use std::path::{Path, PathBuf};

use flate2::{Compression, write::GzEncoder};
use radiant_math::Vec3;
use radiant_scene::{Geometry, SceneDesc, parse_file, parse_str};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("radiant-format-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = GzEncoder::new(Vec::new(), Compression::default());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
}

fn parse(text: &str, base: &Path) -> SceneDesc {
    parse_str(text, "t.pbrt", base).unwrap_or_else(|e| panic!("{e}"))
}

/// Positions, indices and normals of one triangle mesh.
type Mesh = (Vec<Vec3>, Vec<u32>, Option<Vec<Vec3>>);

fn triangles(desc: &SceneDesc) -> Vec<Mesh> {
    desc.shapes
        .iter()
        .filter_map(|s| match &s.geometry {
            Geometry::TriangleMesh {
                positions,
                indices,
                normals,
                ..
            } => Some((positions.clone(), indices.clone(), normals.clone())),
            _ => None,
        })
        .collect()
}

const MESH: &str = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \
                    \"integer indices\" [0 1 2 2 1 3]\n";

const PLY: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                   property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                   end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

#[test]
fn gzip_includes_and_ply_meshes_read_like_plain_ones() {
    let d = dir("gz");
    std::fs::write(d.join("part.pbrt.gz"), gzip(MESH.as_bytes())).unwrap();
    std::fs::write(d.join("m.ply.gz"), gzip(PLY.as_bytes())).unwrap();
    std::fs::write(d.join("m.ply"), PLY).unwrap();
    let packed = parse(
        "WorldBegin\nInclude \"part.pbrt.gz\"\nShape \"plymesh\" \"string filename\" \"m.ply.gz\"\n",
        &d,
    );
    let plain = parse(
        &format!("WorldBegin\n{MESH}Shape \"plymesh\" \"string filename\" \"m.ply\"\n"),
        &d,
    );
    assert_eq!(triangles(&packed), triangles(&plain));
    assert_eq!(triangles(&packed).len(), 2);
    // A whole scene file compressed reads too.
    std::fs::write(
        d.join("scene.pbrt.gz"),
        gzip(format!("WorldBegin\n{MESH}").as_bytes()),
    )
    .unwrap();
    let whole = parse_file(&d.join("scene.pbrt.gz")).unwrap();
    assert_eq!(triangles(&whole)[0], triangles(&plain)[0]);
    // A damaged stream is a located error naming the file.
    let mut cut = gzip(MESH.as_bytes());
    cut.truncate(cut.len() / 2);
    std::fs::write(d.join("cut.pbrt.gz"), cut).unwrap();
    let e = parse_str("WorldBegin\nInclude \"cut.pbrt.gz\"\n", "t.pbrt", &d)
        .unwrap_err()
        .to_string();
    assert!(e.contains("cut.pbrt.gz"), "{e}");
}

const OCTAHEDRON: &str = "\"point3 P\" [1 0 0 -1 0 0 0 1 0 0 -1 0 0 0 1 0 0 -1] \
    \"integer indices\" [0 2 4 2 1 4 1 3 4 3 0 4 2 0 5 1 2 5 3 1 5 0 3 5]";

#[test]
fn loop_subdivision_surfaces_become_smooth_meshes() {
    let d = dir("loop");
    let s = parse(
        &format!("WorldBegin\nShape \"loopsubdiv\" \"integer levels\" 2 {OCTAHEDRON}\n"),
        &d,
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let meshes = triangles(&s);
    let (p, ix, n) = &meshes[0];
    assert_eq!(ix.len() / 3, 8 * 16);
    let n = n.as_ref().expect("normals from the limit surface");
    assert_eq!(n.len(), p.len());
    for (q, n) in p.iter().zip(n) {
        assert!(q.length() < 1.0 && n.dot(q.normalize()) > 0.8);
    }
    // The default is 3 levels.
    let s = parse(
        &format!("WorldBegin\nShape \"loopsubdiv\" {OCTAHEDRON}\n"),
        &d,
    );
    assert_eq!(triangles(&s)[0].1.len() / 3, 8 * 64);
    for (levels, expect) in [
        ("-1", "t.pbrt:2:20: error: \"levels\" must be at least 0"),
        ("30", "t.pbrt:2:20: error: \"levels\" 30 would make"),
    ] {
        let e = parse_str(
            &format!("WorldBegin\nShape \"loopsubdiv\" \"integer levels\" {levels} {OCTAHEDRON}\n"),
            "t.pbrt",
            &d,
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with(expect), "{e}");
    }
}

#[test]
fn non_finite_and_zero_normals_become_geometric_with_one_warning() {
    let d = dir("normals");
    let s = parse(
        "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \
         \"integer indices\" [0 1 2 2 1 3] \"normal N\" [nan 0 1 0 0 0 0 0 1 0 0 1]\n",
        &d,
    );
    let (_, _, n) = &triangles(&s)[0];
    let n = n.as_ref().unwrap();
    assert_eq!(n[0], Vec3::Z);
    assert_eq!(n[1], Vec3::Z);
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    let w = s.warnings[0].to_string();
    assert!(
        w.starts_with("t.pbrt:2:") && w.contains("2 of 4 normals are not finite or zero"),
        "{w}"
    );
}
