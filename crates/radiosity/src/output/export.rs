//! Writing a solution out: the lit mesh with linear float vertex colours as glTF 2.0
//! (`.gltf` with a `.bin` beside it, or one `.glb`) or PLY (binary little-endian, or
//! ASCII), and a CSV table of every patch.
//!
//! Vertex colours are radiance `B / pi` (Lambertian exitance to radiance, the values
//! the rendered image shows), linear, in the scene's units; positions stay in scene
//! units (glTF assumes metres: scale on import if needed). The glTF material is
//! `KHR_materials_unlit` with a white base colour, so viewers show the colours as they
//! are instead of lighting them again.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

use radiant_image::atomic::{AtomicFile, atomic_write_bytes};
use thiserror::Error;

use super::display::DisplayMesh;
use crate::mesh::meshed_scene::RadiosityScene;
use crate::solve::Solution;

#[derive(Debug, Error)]
pub enum ExportError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: unknown mesh format (use .gltf, .glb or .ply)", path.display())]
    UnknownFormat { path: PathBuf },
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> ExportError + '_ {
    move |source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The display mesh with one colour per vertex; faces are the patches (3 or 4
/// corners, counter-clockwise seen from the lit side).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LitMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub colors: Vec<[f32; 3]>,
    pub faces: Vec<Vec<u32>>,
}

impl LitMesh {
    /// Radiance colours `vertex_radiosity / pi` on the display mesh of `scene`.
    pub fn new(
        scene: &RadiosityScene,
        mesh: &DisplayMesh,
        vertex_radiosity: &[[f32; 3]],
    ) -> LitMesh {
        let inv_pi = std::f32::consts::FRAC_1_PI;
        LitMesh {
            positions: mesh
                .positions
                .iter()
                .map(|p| p.as_vec3().to_array())
                .collect(),
            normals: mesh
                .normals
                .iter()
                .map(|n| n.as_vec3().to_array())
                .collect(),
            colors: vertex_radiosity
                .iter()
                .map(|c| c.map(|v| v * inv_pi))
                .collect(),
            faces: scene
                .patches
                .patches
                .iter()
                .zip(&mesh.corner_vertex)
                .map(|(p, c)| c[..p.corner_count as usize].to_vec())
                .collect(),
        }
    }

    /// Triangles (quads split along corner 0 - 2).
    pub fn triangles(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.faces.len() * 6);
        for f in &self.faces {
            for k in 1..f.len() - 1 {
                out.extend_from_slice(&[f[0], f[k], f[k + 1]]);
            }
        }
        out
    }
}

/// Writes the lit mesh in the format named by the extension: `.gltf`, `.glb`, `.ply`.
pub fn write_lit_mesh(path: &Path, mesh: &LitMesh) -> Result<(), ExportError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("gltf") => write_gltf(path, mesh, false),
        Some("glb") => write_gltf(path, mesh, true),
        Some("ply") => write_ply(path, mesh, false),
        _ => Err(ExportError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

fn push_f32s(bytes: &mut Vec<u8>, values: &[[f32; 3]]) {
    for v in values {
        for c in v {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
}

/// glTF 2.0: positions, normals, `COLOR_0` (float RGB) and `u32` indices in one buffer.
/// `binary`: a single `.glb`; otherwise `.gltf` JSON and `<stem>.bin` beside it.
pub fn write_gltf(path: &Path, mesh: &LitMesh, binary: bool) -> Result<(), ExportError> {
    let indices = mesh.triangles();
    let v = mesh.positions.len();
    let mut buffer = Vec::with_capacity(36 * v + 4 * indices.len());
    push_f32s(&mut buffer, &mesh.positions);
    push_f32s(&mut buffer, &mesh.normals);
    push_f32s(&mut buffer, &mesh.colors);
    for i in &indices {
        buffer.extend_from_slice(&i.to_le_bytes());
    }
    let (lower, upper) = mesh.positions.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            )
        },
    );
    let (lower, upper) = if v == 0 {
        ([0.0; 3], [0.0; 3])
    } else {
        (lower, upper)
    };
    let bin_name = format!(
        "{}.bin",
        path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh")
    );
    let uri = if binary {
        String::new()
    } else {
        format!("\"uri\":\"{}\",", json_escape(&bin_name))
    };
    let vec3 = 12 * v;
    let mut json = String::new();
    let _ = write!(
        json,
        concat!(
            "{{\"asset\":{{\"version\":\"2.0\",\"generator\":\"radiant radiosity\"}},",
            "\"extensionsUsed\":[\"KHR_materials_unlit\"],",
            "\"scene\":0,\"scenes\":[{{\"nodes\":[0]}}],\"nodes\":[{{\"mesh\":0,\"name\":\"radiosity\"}}],",
            "\"materials\":[{{\"name\":\"lit\",\"pbrMetallicRoughness\":{{\"baseColorFactor\":[1,1,1,1],",
            "\"metallicFactor\":0,\"roughnessFactor\":1}},\"extensions\":{{\"KHR_materials_unlit\":{{}}}}}}],",
            "\"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":0,\"NORMAL\":1,\"COLOR_0\":2}},",
            "\"indices\":3,\"material\":0,\"mode\":4}}]}}],",
            "\"buffers\":[{{{}\"byteLength\":{}}}],",
            "\"bufferViews\":[",
            "{{\"buffer\":0,\"byteOffset\":0,\"byteLength\":{},\"byteStride\":12,\"target\":34962}},",
            "{{\"buffer\":0,\"byteOffset\":{},\"byteLength\":{},\"byteStride\":12,\"target\":34962}},",
            "{{\"buffer\":0,\"byteOffset\":{},\"byteLength\":{},\"byteStride\":12,\"target\":34962}},",
            "{{\"buffer\":0,\"byteOffset\":{},\"byteLength\":{},\"target\":34963}}],",
            "\"accessors\":[",
            "{{\"bufferView\":0,\"componentType\":5126,\"count\":{},\"type\":\"VEC3\",\"min\":[{},{},{}],\"max\":[{},{},{}]}},",
            "{{\"bufferView\":1,\"componentType\":5126,\"count\":{},\"type\":\"VEC3\"}},",
            "{{\"bufferView\":2,\"componentType\":5126,\"count\":{},\"type\":\"VEC3\"}},",
            "{{\"bufferView\":3,\"componentType\":5125,\"count\":{},\"type\":\"SCALAR\"}}]}}"
        ),
        uri,
        buffer.len(),
        vec3,
        vec3,
        vec3,
        2 * vec3,
        vec3,
        3 * vec3,
        4 * indices.len(),
        v,
        lower[0],
        lower[1],
        lower[2],
        upper[0],
        upper[1],
        upper[2],
        v,
        v,
        indices.len(),
    );
    if binary {
        // GLB: 12-byte header, a JSON chunk padded with spaces and a BIN chunk padded
        // with zeros, both to 4 bytes.
        let mut json_bytes = json.into_bytes();
        while !json_bytes.len().is_multiple_of(4) {
            json_bytes.push(b' ');
        }
        while !buffer.len().is_multiple_of(4) {
            buffer.push(0);
        }
        let total = 12 + 8 + json_bytes.len() + 8 + buffer.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json_bytes);
        out.extend_from_slice(&(buffer.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&buffer);
        atomic_write_bytes(path, &out).map_err(io_error(path))
    } else {
        // Both files complete on disk before either replaces its predecessor, so a failed
        // write leaves the previous pair as it was.
        let bin_path = path.with_file_name(&bin_name);
        let mut bin = AtomicFile::create(&bin_path).map_err(io_error(&bin_path))?;
        bin.writer()
            .write_all(&buffer)
            .map_err(io_error(&bin_path))?;
        let mut gltf = AtomicFile::create(path).map_err(io_error(path))?;
        gltf.writer()
            .write_all(json.as_bytes())
            .map_err(io_error(path))?;
        gltf.writer().flush().map_err(io_error(path))?;
        bin.commit().map_err(io_error(&bin_path))?;
        gltf.commit().map_err(io_error(path))
    }
}

fn json_escape(s: &str) -> String {
    s.chars()
        .flat_map(|c| match c {
            '"' => vec!['\\', '"'],
            '\\' => vec!['\\', '\\'],
            c if (c as u32) < 0x20 => format!("\\u{:04x}", c as u32).chars().collect(),
            c => vec![c],
        })
        .collect()
}

/// PLY with float `x y z nx ny nz red green blue` per vertex and the patches as faces
/// (`vertex_indices`, 3 or 4 each); binary little-endian unless `ascii`.
pub fn write_ply(path: &Path, mesh: &LitMesh, ascii: bool) -> Result<(), ExportError> {
    let mut out = Vec::new();
    let format = if ascii {
        "ascii"
    } else {
        "binary_little_endian"
    };
    let header = format!(
        "ply\nformat {format} 1.0\ncomment radiant radiosity: vertex colours are linear radiance B/pi\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property float red\nproperty float green\nproperty float blue\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.faces.len()
    );
    out.extend_from_slice(header.as_bytes());
    for ((p, n), c) in mesh.positions.iter().zip(&mesh.normals).zip(&mesh.colors) {
        let row = [p[0], p[1], p[2], n[0], n[1], n[2], c[0], c[1], c[2]];
        if ascii {
            let line: Vec<String> = row.iter().map(|v| v.to_string()).collect();
            out.extend_from_slice(line.join(" ").as_bytes());
            out.push(b'\n');
        } else {
            for v in row {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    for f in &mesh.faces {
        if ascii {
            let line: Vec<String> = std::iter::once(f.len().to_string())
                .chain(f.iter().map(|i| i.to_string()))
                .collect();
            out.extend_from_slice(line.join(" ").as_bytes());
            out.push(b'\n');
        } else {
            out.push(f.len() as u8);
            for &i in f {
                out.extend_from_slice(&(i as i32).to_le_bytes());
            }
        }
    }
    atomic_write_bytes(path, &out).map_err(io_error(path))
}

/// One row per patch: index, area, centroid, normal, reflectance, emission `E`,
/// radiosity `B` and irradiance `H` per band (`E`, `B`, `H` in the scene's units of
/// power per area).
pub fn write_patch_csv(
    path: &Path,
    scene: &RadiosityScene,
    solution: &Solution,
) -> Result<(), ExportError> {
    let mut file = AtomicFile::create(path).map_err(io_error(path))?;
    let w = file.writer();
    let write = |w: &mut std::io::BufWriter<std::fs::File>, s: &str| {
        w.write_all(s.as_bytes()).map_err(io_error(path))
    };
    write(
        w,
        "patch,area,cx,cy,cz,nx,ny,nz,rho_r,rho_g,rho_b,E_r,E_g,E_b,B_r,B_g,B_b,H_r,H_g,H_b\n",
    )?;
    let mut line = String::new();
    for (i, p) in scene.patches.patches.iter().enumerate() {
        line.clear();
        let _ = write!(
            line,
            "{i},{},{},{},{},{},{},{}",
            p.area, p.centroid.x, p.centroid.y, p.centroid.z, p.normal.x, p.normal.y, p.normal.z
        );
        for values in [
            p.reflectance,
            p.emission,
            solution.radiosity[i],
            solution.irradiance[i],
        ] {
            for v in values {
                let _ = write!(line, ",{v}");
            }
        }
        line.push('\n');
        write(w, &line)?;
    }
    file.commit().map_err(io_error(path))
}
