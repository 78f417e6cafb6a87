//! Checkpoint and resume: a render stopped after some passes (or by SIGTERM) and
//! resumed from its checkpoint ends with the image of the same render done in one go,
//! bit for bit, at another thread count; checkpoints of another run, truncated or
//! corrupt ones are refused with a message saying why.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use radiant::image::read_image;

mod common;
use common::*;

fn run(args: &[&str], extra: &[&Path]) -> Output {
    Command::new(BIN).args(args).args(extra).output().unwrap()
}

/// The image's pixels as f32 bit patterns (headers left out).
fn pixel_bits(path: &Path) -> Vec<u32> {
    let img = read_image(path).unwrap();
    img.pixels
        .iter()
        .flat_map(|p| [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()])
        .collect()
}

fn assert_same_pixels(a: &Path, b: &Path, what: &str) {
    let (pa, pb) = (pixel_bits(a), pixel_bits(b));
    assert_eq!(pa.len(), pb.len(), "{what}");
    let differ = pa.iter().zip(&pb).filter(|(x, y)| x != y).count();
    assert_eq!(
        differ,
        0,
        "{what}: {differ} of {} channels differ",
        pa.len()
    );
    // A black image would match trivially.
    assert!(pa.iter().any(|&v| f32::from_bits(v) > 0.0), "{what}: black");
}

/// Renders straight at 1 thread; stops after `stop` passes (SPPM: iterations) at 1
/// thread with a checkpoint; resumes at 2 threads; compares the pixels.
fn stop_and_resume(dir: &Path, name: &str, args: &[&str], stop: u32) {
    stop_and_resume_as(dir, name, args, stop, "pfm");
}

/// [`stop_and_resume`] with images of extension `ext`; returns the straight and the
/// resumed image and what the resumed run printed.
fn stop_and_resume_as(
    dir: &Path,
    name: &str,
    args: &[&str],
    stop: u32,
    ext: &str,
) -> (PathBuf, PathBuf, String) {
    let straight = dir.join(format!("{name}-straight.{ext}"));
    let partial = dir.join(format!("{name}-partial.{ext}"));
    let resumed = dir.join(format!("{name}-resumed.{ext}"));
    let ckpt = dir.join(format!("{name}.ckpt"));
    fn with<'a>(args: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        args.iter().chain(extra).copied().collect()
    }
    let out = run(&with(args, &["--threads", "1", "-o"]), &[&straight]);
    assert_ok(&out, name);
    let stop = stop.to_string();
    let out = run(
        &with(args, &["--threads", "1", "--stop-after", &stop, "-o"]),
        &[&partial, Path::new("--checkpoint"), &ckpt],
    );
    let stderr = assert_clean_failure(&out, name);
    assert!(
        stderr.contains(&ckpt.display().to_string()),
        "{name}: {stderr}"
    );
    // The partial image (radiosity writes none before the solve is done) really is
    // partial.
    if partial.exists() {
        assert_ne!(pixel_bits(&partial), pixel_bits(&straight), "{name}");
    }
    let out = run(
        &with(args, &["--threads", "2", "-o"]),
        &[&resumed, Path::new("--resume"), &ckpt],
    );
    assert_ok(&out, name);
    assert_same_pixels(&straight, &resumed, name);
    (straight, resumed, stderr_of(&out))
}

#[test]
fn path_sppm_and_photonmap_resume_bit_identically() {
    let dir = temp_dir("render");
    let small = ["--resolution", "24x24", "--quiet"];
    let cases: [(&str, &[&str], u32); 3] = [
        ("path", &["render", "cornell-box", "--spp", "24"], 4),
        (
            "sppm",
            &[
                "render",
                "cornell-caustics",
                "--integrator",
                "sppm",
                "--spp",
                "6",
            ],
            2,
        ),
        (
            "photonmap",
            &[
                "render",
                "cornell-caustics",
                "--integrator",
                "photonmap",
                "--spp",
                "8",
            ],
            2,
        ),
    ];
    for (name, args, stop) in cases {
        let args: Vec<&str> = args.iter().chain(&small).copied().collect();
        stop_and_resume(&dir, name, &args, stop);
    }
}

/// An adaptive render keeps its pilot's moments and rays, then its targets, in its
/// checkpoints: stopped in the pilot (4 of its 16 samples per pixel) or after the first
/// adaptive round, it resumes to the image of the render done in one go. The variance
/// channels, which come from the same moments, survive the resume too.
#[test]
fn adaptive_renders_resume_bit_identically_in_the_pilot_and_after_it() {
    let dir = temp_dir("adaptive");
    let args = [
        "render",
        "cornell-box",
        "--spp",
        "64",
        "--adaptive",
        "--resolution",
        "24x20",
        "--quiet",
    ];
    stop_and_resume(&dir, "adaptive-pilot", &args, 4);
    stop_and_resume(&dir, "adaptive-rounds", &args, 20);

    // With variance channels: an EXR resumed from the pilot matches in every channel.
    let with_variance = [&args[..], &["--aov", "variance"]].concat();
    let (straight, resumed, stderr) =
        stop_and_resume_as(&dir, "variance", &with_variance, 8, "exr");
    assert!(!stderr.contains("no variance"), "{stderr}");
    let channels = |p: &Path| -> Vec<(String, Vec<u32>)> {
        let exr = exr::prelude::read_all_flat_layers_from_file(p).unwrap();
        exr.layer_data[0]
            .channel_data
            .list
            .iter()
            .map(|c| {
                let bits = c.sample_data.values_as_f32().map(f32::to_bits).collect();
                (c.name.to_string(), bits)
            })
            .collect()
    };
    let (a, b) = (channels(&straight), channels(&resumed));
    assert!(
        a.iter().any(|(n, _)| n.contains("Variance")),
        "{:?}",
        a.iter().map(|c| &c.0).collect::<Vec<_>>()
    );
    assert_eq!(a, b, "variance render resumed");

    // Uniform and adaptive checkpoints are not each other's.
    let uniform = dir.join("uniform.ckpt");
    let plain: Vec<&str> = args
        .iter()
        .copied()
        .filter(|a| *a != "--adaptive")
        .collect();
    let out = run(
        &[&plain[..], &["--stop-after", "4", "-o"]].concat(),
        &[&dir.join("u.pfm"), Path::new("--checkpoint"), &uniform],
    );
    assert_clean_failure(&out, "uniform stopped");
    let out = run(
        &[&args[..], &["-o"]].concat(),
        &[&dir.join("u2.pfm"), Path::new("--resume"), &uniform],
    );
    let e = assert_clean_failure(&out, "uniform checkpoint resumed adaptively");
    assert!(
        e.contains("uniform sampling in the checkpoint, adaptive now"),
        "{e}"
    );
}

#[test]
fn progressive_radiosity_resumes_bit_identically() {
    let dir = temp_dir("radiosity");
    let args = [
        "radiosity",
        "cornell-box",
        "--max-patch-area",
        "5000",
        "--resolution",
        "16x16",
        "--spp",
        "2",
        "--quiet",
    ];
    stop_and_resume(&dir, "radiosity", &args, 200);
    // The power booked per shot is restored too: the energy balance is the same.
    let straight = run(
        &[&args[..], &["-o"]].concat(),
        &[&dir.join("straight-again.pfm")],
    );
    let resumed = run(
        &[&args[..], &["-o"]].concat(),
        &[
            &dir.join("resumed-again.pfm"),
            Path::new("--resume"),
            &dir.join("radiosity.ckpt"),
        ],
    );
    assert_ok(&resumed, "radiosity");
    assert_eq!(straight.stdout, resumed.stdout);
    assert!(String::from_utf8_lossy(&straight.stdout).contains("energy balance"));

    let out = run(
        &[&args[..], &["--refine", "1", "--checkpoint"]].concat(),
        &[&dir.join("r.ckpt")],
    );
    let stderr = assert_clean_failure(&out, "radiosity --refine");
    assert!(stderr.contains("--refine"), "{stderr}");
    let out = run(
        &[&args[..], &["--solver", "jacobi", "--checkpoint"]].concat(),
        &[&dir.join("r.ckpt")],
    );
    let stderr = assert_clean_failure(&out, "radiosity --solver jacobi");
    assert!(stderr.contains("progressive"), "{stderr}");
}

/// SIGTERM in the middle of a pass: rows of the pass already done keep their samples,
/// and the resumed render takes, per pixel, the samples it lacks.
#[test]
fn a_render_resumed_after_sigterm_equals_one_done_in_one_go() {
    let dir = temp_dir("sigterm");
    let args = [
        "render",
        "cornell-box",
        "--spp",
        "8192",
        "--resolution",
        "16x16",
        "--quiet",
    ];
    let ckpt = dir.join("term.ckpt");
    let child = Command::new(BIN)
        .args(args)
        .args(["--threads", "2", "-o"])
        .arg(dir.join("partial.exr"))
        .arg("--checkpoint")
        .arg(&ckpt)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let stderr = stderr_of(&out);
    // Under heavy load the render may not have got far, but it cannot have finished.
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("checkpoint:"), "{stderr}");
    let resumed = dir.join("resumed.pfm");
    let out = run(
        &[&args[..], &["--threads", "1", "-o"]].concat(),
        &[&resumed, Path::new("--resume"), &ckpt],
    );
    assert_ok(&out, "resume after SIGTERM");
    let straight = dir.join("straight.pfm");
    let out = run(&[&args[..], &["-o"]].concat(), &[&straight]);
    assert_ok(&out, "straight");
    assert_same_pixels(&straight, &resumed, "resumed after SIGTERM");
}

#[test]
fn other_runs_truncated_and_corrupt_checkpoints_are_refused() {
    let dir = temp_dir("refused");
    let ckpt = dir.join("c.ckpt");
    let image = dir.join("out.pfm");
    let base = ["render", "--spp", "8", "--resolution", "12x12", "--quiet"];
    // Checkpoints every few milliseconds, and at the end.
    let out = run(
        &[&base[..], &["--checkpoint-every", "0.001", "-o"]].concat(),
        &[&image, Path::new("--checkpoint"), &ckpt],
    );
    assert_ok(&out, "checkpointed render");
    let straight = pixel_bits(&image);
    // A finished render's checkpoint resumes to the same image at once.
    let again = dir.join("again.pfm");
    let out = run(
        &[&base[..], &["-o"]].concat(),
        &[&again, Path::new("--resume"), &ckpt],
    );
    assert_ok(&out, "resume of a finished render");
    assert_eq!(pixel_bits(&again), straight);

    let resume = |extra: &[&str], file: &Path| {
        run(
            &[&base[..], extra, &["-o"]].concat(),
            &[&dir.join("x.pfm"), Path::new("--resume"), file],
        )
    };
    let e = assert_clean_failure(&resume(&["--seed", "5"], &ckpt), "other seed");
    assert!(e.contains("seed 0 in the checkpoint, 5 now"), "{e}");
    let e = assert_clean_failure(&resume(&["cornell-caustics"], &ckpt), "other scene");
    assert!(e.contains("the scene differs"), "{e}");
    let out = run(
        &[
            "render",
            "--spp",
            "8",
            "--resolution",
            "12x10",
            "--quiet",
            "-o",
        ],
        &[&dir.join("x.pfm"), Path::new("--resume"), &ckpt],
    );
    let e = assert_clean_failure(&out, "other size");
    assert!(
        e.contains("resolution 12x12 in the checkpoint, 12x10 now"),
        "{e}"
    );
    let e = assert_clean_failure(&resume(&["--integrator", "sppm"], &ckpt), "other method");
    assert!(e.contains("integrator \"path\" in the checkpoint"), "{e}");

    let bytes = std::fs::read(&ckpt).unwrap();
    let truncated = dir.join("truncated.ckpt");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let e = assert_clean_failure(&resume(&[], &truncated), "truncated");
    assert!(e.contains("truncated"), "{e}");
    let corrupt = dir.join("corrupt.ckpt");
    let mut flipped = bytes.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 1;
    std::fs::write(&corrupt, &flipped).unwrap();
    let e = assert_clean_failure(&resume(&[], &corrupt), "corrupt");
    assert!(e.contains("checksum"), "{e}");
    let e = assert_clean_failure(&resume(&[], &image), "an image");
    assert!(e.contains("not a radiant checkpoint"), "{e}");
    let e = assert_clean_failure(&resume(&[], &dir.join("missing.ckpt")), "missing");
    assert!(e.contains("cannot read the checkpoint"), "{e}");
    // The image the refused runs would have written was never started.
    assert!(!dir.join("x.pfm").exists());

    let out = run(
        &["render", "--checkpoint-every", "0", "--checkpoint"],
        &[&ckpt],
    );
    let e = stderr_of(&out);
    assert!(
        !out.status.success() && e.contains("positive number of seconds"),
        "{e}"
    );
    let out = run(&["render", "--stop-after", "2"], &[]);
    let e = assert_clean_failure(&out, "--stop-after alone");
    assert!(e.contains("--checkpoint"), "{e}");
}
