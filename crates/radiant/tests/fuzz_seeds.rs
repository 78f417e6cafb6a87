//! The fuzz targets' seed corpus (fuzz/seeds/, see fuzz/README.md) replayed on stable
//! Rust in every test run: each seed goes through what its target exercises, and bad
//! inputs must come back as errors that name where they are, never as panics.

use std::path::{Path, PathBuf};

use radiant::Session;
use radiant::render::camera::realistic::{LensPrescription, LensSystem};
use radiant::render::{Overrides, Progress};

fn seeds(target: &str) -> Vec<PathBuf> {
    let dir = radiant_testkit::repo_path("fuzz/seeds").join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no seeds in {}", dir.display());
    files
}

fn name(path: &Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

/// Every scene seed parses or fails with a message naming a file (the seed itself with
/// line and column, or the file it includes); a scene that parses is built and rendered
/// at 8×8 pixels, 1 sample, as the `scene_render` target does.
#[test]
fn scene_seeds_parse_render_or_fail_located() {
    let (mut rendered, mut rejected) = (0, 0);
    for path in seeds("scene_parse") {
        let name = name(&path);
        let text = String::from_utf8_lossy(&std::fs::read(&path).unwrap()).into_owned();
        let base = path.parent().unwrap();
        match radiant::scene::parse_str(&text, &name, base) {
            Err(e) => {
                let message = e.to_string();
                let located = message.starts_with(&format!("{name}:"))
                    || message.contains(".pbrt")
                    || message.contains(".ply")
                    || message.contains(".dat")
                    || message.contains("/dev/");
                assert!(located, "{name}: error names no file: {message}");
                rejected += 1;
            }
            Ok(desc) => {
                let overrides = Overrides {
                    spp: Some(1),
                    seed: Some(1),
                    resolution: Some((8, 8)),
                    integrator: Some("path".into()),
                };
                if let Ok(session) = Session::new(&desc, &overrides) {
                    let out = session.render(&Progress::default());
                    assert_eq!((out.film.width, out.film.height), (8, 8), "{name}");
                    rendered += 1;
                }
            }
        }
    }
    assert!(rendered >= 5, "only {rendered} seeds rendered");
    assert!(rejected >= 10, "only {rejected} seeds rejected");
}

/// Lens seeds parse and build, or fail with an error naming the file and line.
#[test]
fn lens_seeds_build_or_fail_located() {
    for path in seeds("lens_file") {
        let name = name(&path);
        let text = std::fs::read_to_string(&path).unwrap();
        match LensPrescription::parse(&text, &name) {
            Ok(p) => {
                let _ = LensSystem::new(&p);
            }
            Err(e) => assert!(e.to_string().contains(&name), "{name}: {e}"),
        }
    }
}

/// Image seeds (PFM, EXR, PNG) decode, and the same bytes cut to one byte or to half
/// fail with an error; `bad-` seeds (what the fuzzer found) fail with an error.
#[test]
fn image_seeds_decode_and_truncations_fail() {
    let dir = radiant_testkit::output_dir("fuzz-seeds");
    for path in seeds("image_read") {
        let name = name(&path);
        let bytes = std::fs::read(&path).unwrap();
        let read = |p: &Path| match p.extension().and_then(|e| e.to_str()) {
            Some("exr") => radiant::image::exr::read_exr(p).map(|_| ()),
            Some("png") => radiant::image::png::read_png(p).map(|_| ()),
            _ => radiant::image::pfm::read_pfm(p).map(|_| ()),
        };
        if name.starts_with("bad-") {
            // Inputs the fuzzer found: each must be refused with an error naming the file.
            let e = read(&path).expect_err(&name).to_string();
            assert!(e.contains(&name), "{name}: {e}");
            continue;
        }
        read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        // (A PNG cut inside its final IEND chunk still holds the whole image.)
        for cut in [1, bytes.len() / 2] {
            let short = dir.join(format!("cut{cut}-{name}"));
            std::fs::write(&short, &bytes[..cut]).unwrap();
            assert!(read(&short).is_err(), "{name} cut to {cut} bytes decoded");
        }
    }
}

/// PLY and OBJ seeds read as meshes or fail with an error naming the file.
#[test]
fn mesh_seeds_read_or_fail_named() {
    let mut read = 0;
    let ply = seeds("ply_read").into_iter().map(|p| (p, true));
    let obj = seeds("obj_read").into_iter().map(|p| (p, false));
    for (path, is_ply) in ply.chain(obj) {
        let mesh = if is_ply {
            radiant::scene::ply::read_ply(&path)
        } else {
            radiant::scene::obj::read_obj(&path)
        };
        match mesh {
            Ok(mesh) => {
                assert!(
                    !(mesh.triangles.is_empty() && mesh.quads.is_empty()),
                    "{}",
                    name(&path)
                );
                read += 1;
            }
            Err(e) => assert!(e.to_string().contains(&name(&path)), "{e}"),
        }
    }
    assert!(read >= 5, "only {read} mesh seeds read");
}
