//! The command line end to end: renders, bad input, determinism across thread counts,
//! and Ctrl-C writing the image rendered so far.

use std::process::{Command, Output};

use radiant::image::read_image;

mod common;
use common::*;

fn run(cmd: &mut Command) -> Output {
    cmd.output().expect("radiant runs")
}

#[test]
fn renders_the_default_scene_to_every_format() {
    let dir = temp_dir("formats");
    for ext in ["exr", "pfm", "png"] {
        let path = dir.join(format!("cb.{ext}"));
        let out = run(radiant()
            .args([
                "render",
                "--spp",
                "2",
                "--resolution",
                "24x16",
                "--quiet",
                "-o",
            ])
            .arg(&path));
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let img = read_image(&path).unwrap();
        assert_eq!((img.width, img.height), (24, 16));
        assert!(img.mean() > 0.0);
    }
}

/// Every malformed scene of the parser's corpus exits non-zero with `file:line:column`
/// and never panics.
#[test]
fn malformed_scenes_fail_cleanly_with_a_location() {
    let corpus = radiant_testkit::repo_path("tests/scenes/malformed");
    let mut n = 0;
    for entry in std::fs::read_dir(&corpus).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "pbrt") {
            continue;
        }
        n += 1;
        let out = run(radiant()
            .args(["render", "--quiet", "-o", "/dev/null.exr"])
            .arg(&path));
        let stderr = assert_clean_failure(&out, &path.display().to_string());
        let located = stderr.split_whitespace().any(|w| {
            let parts: Vec<&str> = w.trim_end_matches(':').rsplitn(3, ':').collect();
            parts.len() == 3 && parts[0].parse::<u32>().is_ok() && parts[1].parse::<u32>().is_ok()
        });
        assert!(
            located,
            "{}: no file:line:column in {stderr}",
            path.display()
        );
    }
    assert!(n >= 10, "corpus has {n} scenes");
}

#[test]
fn missing_scene_and_bad_arguments_fail_cleanly() {
    let out = run(radiant().args(["render", "no/such/scene.pbrt"]));
    let stderr = assert_clean_failure(&out, "missing file");
    assert!(stderr.contains("no/such/scene.pbrt"), "{stderr}");
    let out = run(radiant().args(["render", "not-a-builtin"]));
    assert_clean_failure(&out, "unknown scene name");
    let out = run(radiant().args(["render", "--spp", "2", "--resolution", "8x8", "-o", "x.bmp"]));
    assert_clean_failure(&out, "unknown extension");
    let out = run(radiant().args(["render", "--integrator", "spmp", "--spp", "1"]));
    let stderr = assert_clean_failure(&out, "unknown integrator");
    assert!(stderr.contains("spmp"), "{stderr}");
}

/// The same scene, seed and spp give the same pixels, bit for bit, at 1 and 2 threads.
/// (The EXR header's renderTimeSeconds is a measurement and differs; every pixel bit is
/// compared, and the rest of the header too.)
#[test]
fn exr_is_bit_identical_at_one_and_two_threads() {
    let dir = temp_dir("threads");
    let render = |threads: &str| {
        let path = dir.join(format!("t{threads}.exr"));
        let out = run(radiant()
            .args([
                "render",
                "cornell-caustics",
                "--spp",
                "4",
                "--resolution",
                "48x48",
                "--quiet",
            ])
            .args(["--threads", threads, "-o"])
            .arg(&path));
        assert!(out.status.success());
        path
    };
    let (a, b) = (render("1"), render("2"));
    let (ia, ib) = (read_image(&a).unwrap(), read_image(&b).unwrap());
    let bits = |i: &radiant::image::Image| -> Vec<u32> {
        i.pixels
            .iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect()
    };
    assert_eq!(bits(&ia), bits(&ib));
}

/// Ctrl-C (SIGINT) stops the render, writes the image so far and exits non-zero.
#[cfg(unix)]
#[test]
fn interrupt_writes_the_partial_image() {
    let dir = temp_dir("interrupt");
    let path = dir.join("partial.exr");
    let _ = std::fs::remove_file(&path);
    let child = radiant()
        .args([
            "render",
            "--spp",
            "100000",
            "--resolution",
            "64x64",
            "--quiet",
            "-o",
        ])
        .arg(&path)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let stderr = assert_clean_failure(&out, "interrupted render");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let img = read_image(&path).unwrap();
    assert!(img.mean() > 0.0, "partial image is empty");
}

/// `radiant radiosity --every K --sequence PATTERN` writes the classic progressive
/// sequence: one numbered image per K shots, approaching the final image; `--every`
/// alone is refused.
#[test]
fn radiosity_writes_the_progressive_sequence() {
    let dir = temp_dir("radiosity-sequence");
    let final_path = dir.join("final.pfm");
    let out = run(radiant()
        .args([
            "radiosity",
            "cornell-box",
            "--tolerance",
            "0.01",
            "--resolution",
            "16x16",
            "--spp",
            "4",
            "--every",
            "200",
            "--quiet",
            "--sequence",
        ])
        .arg(dir.join("frame-####.pfm"))
        .arg("-o")
        .arg(&final_path));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let frames: Vec<_> = (1..)
        .map(|k| dir.join(format!("frame-{k:04}.pfm")))
        .take_while(|p| p.exists())
        .map(|p| read_image(&p).unwrap())
        .collect();
    assert!(frames.len() >= 2, "{} frames", frames.len());
    let final_mean = read_image(&final_path).unwrap().mean();
    assert!(final_mean > 0.0);
    // Each frame shows B plus the ambient estimate of what is still unshot, so the
    // frames close in on the solution as the unshot power falls.
    let first = (frames[0].mean() / final_mean - 1.0).abs();
    let last = (frames[frames.len() - 1].mean() / final_mean - 1.0).abs();
    assert!(
        frames
            .iter()
            .all(|f| f.pixels.iter().all(|p| p.is_finite()))
    );
    assert!(last < first, "first frame off by {first}, last by {last}");

    let out = run(radiant().args(["radiosity", "cornell-box", "--every", "10", "--quiet"]));
    let stderr = assert_clean_failure(&out, "--every without --sequence");
    assert!(stderr.contains("--sequence"), "{stderr}");
}

/// `--adaptive` renders and says how it spread the samples; where it cannot work (SPPM's
/// iterations, units of a distributed render) it is refused before any work, with a
/// reason.
#[test]
fn adaptive_sampling_renders_and_is_refused_where_it_cannot_work() {
    let dir = temp_dir("adaptive");
    let path = dir.join("cb.exr");
    let out = run(radiant()
        .args([
            "render",
            "--spp",
            "64",
            "--resolution",
            "32x24",
            "--adaptive",
            "-o",
        ])
        .arg(&path));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("spp adaptive (16-"), "{stderr}");
    assert!(read_image(&path).unwrap().mean() > 0.0);

    let refused: [&[&str]; 2] = [&["--integrator", "sppm"], &["--part", "1/2"]];
    for extra in refused {
        let out = run(radiant()
            .current_dir(&dir)
            .args([
                "render",
                "--spp",
                "64",
                "--resolution",
                "32x24",
                "--adaptive",
            ])
            .args(extra)
            .args(["--quiet", "-o", "refused.exr"]));
        let stderr = assert_clean_failure(&out, &format!("--adaptive {extra:?}"));
        assert!(stderr.contains("adaptive"), "{extra:?}: {stderr}");
        assert!(!dir.join("refused.exr").exists(), "{extra:?}");
    }
}

/// A scene that splits its paths at the first vertex renders, and the summary says what
/// a sample is; a split of zero stops at the parameter with its file, line and column.
#[test]
fn split_renders_say_so_and_a_zero_split_is_located() {
    let dir = temp_dir("split");
    let scene =
        std::fs::read_to_string(radiant_testkit::repo_path("scenes/cornell-box.pbrt")).unwrap();
    let integrator = "Integrator \"path\" \"integer maxdepth\" [ 100 ]";
    assert!(scene.contains(integrator));
    for (k, name) in [(3, "split.pbrt"), (0, "zero.pbrt")] {
        let text = scene.replace(
            integrator,
            &format!("{integrator} \"integer primarysplit\" [ {k} ]"),
        );
        std::fs::write(dir.join(name), text).unwrap();
    }
    let out = run(radiant().current_dir(&dir).args([
        "render",
        "split.pbrt",
        "--spp",
        "4",
        "--resolution",
        "32x24",
        "-o",
        "split.exr",
    ]));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("4 spp x 3 paths split"), "{stderr}");
    assert!(read_image(dir.join("split.exr")).unwrap().mean() > 0.0);

    let out =
        run(radiant()
            .current_dir(&dir)
            .args(["render", "zero.pbrt", "--quiet", "-o", "zero.exr"]));
    let stderr = assert_clean_failure(&out, "primarysplit 0");
    let line = scene
        .lines()
        .position(|l| l.starts_with(integrator))
        .unwrap()
        + 1;
    let column = integrator.len() + 2;
    assert!(
        stderr.contains(&format!(
            "zero.pbrt:{line}:{column}: error: \"primarysplit\""
        )),
        "{stderr}"
    );
    assert!(!dir.join("zero.exr").exists());
}
