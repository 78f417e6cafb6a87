//! Scene-reading throughput: a canonical scene, a large text triangle mesh and a large
//! binary PLY. Run with `cargo bench --bench scene_parse`.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use radiant::scene::{parse_file, parse_str};

fn main() {
    divan::main();
}

/// A `grid × grid` quad grid as one trianglemesh (2 grid² triangles), as text.
fn grid_scene(grid: usize) -> String {
    let mut s = String::from("WorldBegin\nShape \"trianglemesh\"\n\"point3 P\" [\n");
    for j in 0..=grid {
        for i in 0..=grid {
            s.push_str(&format!(
                "{:.6} {:.6} {:.6}\n",
                i as f32 / grid as f32,
                j as f32 / grid as f32,
                0.25
            ));
        }
    }
    s.push_str("]\n\"integer indices\" [\n");
    let row = grid + 1;
    for j in 0..grid {
        for i in 0..grid {
            let v = j * row + i;
            s.push_str(&format!(
                "{} {} {} {} {} {}\n",
                v,
                v + 1,
                v + row + 1,
                v,
                v + row + 1,
                v + row
            ));
        }
    }
    s.push_str("]\n");
    s
}

fn big_text() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| grid_scene(300))
}

/// The same grid as a binary little-endian PLY of quads.
fn big_ply() -> &'static Path {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let grid = 300usize;
        let row = grid + 1;
        let mut out = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
             property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
            row * row,
            grid * grid
        )
        .into_bytes();
        for j in 0..=grid {
            for i in 0..=grid {
                for c in [i as f32 / grid as f32, j as f32 / grid as f32, 0.25] {
                    out.extend(c.to_le_bytes());
                }
            }
        }
        for j in 0..grid {
            for i in 0..grid {
                let v = (j * row + i) as i32;
                out.push(4);
                for k in [v, v + 1, v + row as i32 + 1, v + row as i32] {
                    out.extend(k.to_le_bytes());
                }
            }
        }
        let path = std::env::temp_dir().join(format!("radiant-bench-{}.ply", std::process::id()));
        std::fs::write(&path, out).expect("temp file");
        path
    })
}

#[divan::bench]
fn cornell_box_file() {
    let path = radiant_testkit::repo_path("scenes/cornell-box.pbrt");
    divan::black_box(parse_file(&path).expect("valid scene"));
}

/// 90 601 vertices, 180 000 triangles, 5.6 MB of text.
#[divan::bench(sample_count = 10)]
fn trianglemesh_180k_triangles() {
    divan::black_box(parse_str(big_text(), "grid.pbrt", Path::new(".")).expect("valid scene"));
}

/// 90 601 vertices, 90 000 quads, 2.6 MB.
#[divan::bench(sample_count = 10)]
fn plymesh_90k_quads() {
    divan::black_box(radiant::scene::ply::read_ply(big_ply()).expect("valid PLY"));
}
