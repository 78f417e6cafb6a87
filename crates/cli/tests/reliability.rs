//! Nothing lost, nothing hung: outputs are replaced whole or not at all (full disk,
//! signals during the write), every stopping signal writes what was rendered, and bad
//! paths and values are refused before any work.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

use radiant::image::exr::read_exr_attributes;
use radiant::image::read_image;

mod common;
use common::*;

/// Files in `dir` whose names mark an unfinished write.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

/// Renders a small image to `path` (the "previous" output).
fn previous_render(path: &Path) -> Vec<u8> {
    let out = radiant()
        .args([
            "render",
            "--spp",
            "1",
            "--resolution",
            "8x8",
            "--quiet",
            "-o",
        ])
        .arg(path)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    std::fs::read(path).unwrap()
}

/// Runs `radiant ARGS` under a file-size limit of 4 KiB, with SIGXFSZ ignored so the
/// write fails with EFBIG ("File too large") as it does on a full disk with ENOSPC.
fn run_with_file_limit(args: &[&str]) -> Output {
    let mut script = String::from("trap '' XFSZ; ulimit -f 8; exec \"$0\"");
    for (i, _) in args.iter().enumerate() {
        // Braced: "$10" would be "$1" followed by "0".
        script.push_str(&format!(" \"${{{}}}\"", i + 1));
    }
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(BIN)
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn a_full_disk_keeps_the_previous_image_in_every_format() {
    let dir = temp_dir("full-disk");
    for ext in ["exr", "pfm", "png"] {
        let path = dir.join(format!("prev.{ext}"));
        let before = previous_render(&path);
        let path_s = path.to_str().unwrap();
        let out = run_with_file_limit(&[
            "render",
            "--spp",
            "1",
            "--resolution",
            "256x256",
            "--quiet",
            "-o",
            path_s,
        ]);
        let stderr = assert_clean_failure(&out, ext);
        assert!(stderr.contains("File too large"), "{ext}: {stderr}");
        assert!(stderr.contains(path_s), "{ext}: {stderr}");
        assert_eq!(
            std::fs::read(&path).unwrap(),
            before,
            "{ext}: previous file changed"
        );
        assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
    }
}

#[test]
fn a_full_disk_keeps_the_previous_gltf_and_its_buffer() {
    let dir = temp_dir("full-disk-gltf");
    let gltf = dir.join("lit.gltf");
    let bin = dir.join("lit.bin");
    let args = |g: &Path| {
        vec![
            "radiosity".to_string(),
            "--quiet".into(),
            "--max-patch-area".into(),
            "20000".into(),
            "--export".into(),
            g.to_str().unwrap().into(),
        ]
    };
    // The previous export: a coarse mesh, small enough for the limit.
    let out = radiant().args(args(&gltf)).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let (g0, b0) = (std::fs::read(&gltf).unwrap(), std::fs::read(&bin).unwrap());
    let mut fine = args(&gltf);
    fine[3] = "2000".into();
    let fine: Vec<&str> = fine.iter().map(String::as_str).collect();
    let out = run_with_file_limit(&fine);
    let stderr = assert_clean_failure(&out, "glTF");
    assert!(stderr.contains("File too large"), "{stderr}");
    assert_eq!(std::fs::read(&gltf).unwrap(), g0, "previous .gltf changed");
    assert_eq!(std::fs::read(&bin).unwrap(), b0, "previous .bin changed");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

/// An MSE curve that cannot be written (here past a file-size limit, as on a full disk)
/// fails the render, and the file keeps its last whole version.
#[test]
fn an_mse_curve_that_cannot_be_written_fails_the_render() {
    let dir = temp_dir("mse-full");
    let reference = dir.join("ref.pfm");
    let image = dir.join("test.pfm");
    let mse = dir.join("mse.txt");
    let tiny = ["--resolution", "2x2", "--quiet", "-o"];
    let out = radiant()
        .args(["render", "--spp", "64"])
        .args(tiny)
        .arg(&reference)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    // 300 passes of 64 samples: some 6 KB of lines, over the 4 KiB limit.
    let out = run_with_file_limit(&[
        "render",
        "--spp",
        "19200",
        "--mse-reference-image",
        reference.to_str().unwrap(),
        "--mse-reference-out",
        mse.to_str().unwrap(),
        "--resolution",
        "2x2",
        "--quiet",
        "-o",
        image.to_str().unwrap(),
    ]);
    let stderr = assert_clean_failure(&out, "mse curve");
    assert!(
        stderr.contains("--mse-reference-out") && stderr.contains("File too large"),
        "{stderr}"
    );
    let text = std::fs::read_to_string(&mse).unwrap();
    assert!(text.len() > 3000 && text.ends_with('\n'), "{text}");
    assert!(text.lines().all(|l| l.split_once(", ").is_some()), "{text}");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

/// Output paths that cannot be written are refused before the scene is even read: the
/// scene named here does not exist, and the error is about the output.
#[test]
fn bad_output_paths_fail_before_any_work() {
    let dir = temp_dir("bad-output");
    std::fs::write(dir.join("a-file"), b"x").unwrap();
    let cases = [
        ("out.jpg", "unknown image format"),
        ("noextension", "unknown image format"),
        ("missing/out.exr", "does not exist"),
        ("a-file/out.exr", "not a folder"),
    ];
    for (name, expect) in cases {
        let path = dir.join(name);
        let out = radiant()
            .args(["render", "no/such/scene.pbrt", "-o"])
            .arg(&path)
            .output()
            .unwrap();
        let stderr = assert_clean_failure(&out, name);
        assert!(stderr.contains(expect), "{name}: {stderr}");
        assert!(!stderr.contains("no/such/scene"), "{name}: {stderr}");
    }
    // A read-only folder (only meaningful where permissions bind: not for root).
    let ro = dir.join("read-only");
    std::fs::create_dir_all(&ro).unwrap();
    let mut perms = std::fs::metadata(&ro).unwrap().permissions();
    std::os::unix::fs::PermissionsExt::set_mode(&mut perms, 0o555);
    std::fs::set_permissions(&ro, perms).unwrap();
    if std::fs::write(ro.join("probe"), b"x").is_err() {
        let out = radiant()
            .args(["render", "no/such/scene.pbrt", "-o"])
            .arg(ro.join("out.exr"))
            .output()
            .unwrap();
        let stderr = assert_clean_failure(&out, "read-only folder");
        assert!(stderr.contains("ermission denied"), "{stderr}");
    }
    let out = radiant()
        .args(["radiosity", "no/such/scene.pbrt", "--export"])
        .arg(dir.join("lit.obj"))
        .output()
        .unwrap();
    let stderr = assert_clean_failure(&out, "radiosity export format");
    assert!(stderr.contains("unknown mesh format"), "{stderr}");
    let out = radiant()
        .args(["radiosity", "no/such/scene.pbrt", "--patches"])
        .arg(dir.join("missing/p.csv"))
        .output()
        .unwrap();
    let stderr = assert_clean_failure(&out, "radiosity patches folder");
    assert!(stderr.contains("does not exist"), "{stderr}");
}

/// Every other output of every subcommand is checked as `-o` is, before the work: the
/// scene or input named here does not exist, and the error is about the output.
#[test]
fn every_output_path_is_checked_before_any_work() {
    let dir = temp_dir("bad-outputs");
    let missing = |name: &str| dir.join("missing").join(name);
    let m = |name: &str| missing(name).to_str().unwrap().to_string();
    let cases: [(Vec<String>, &str); 6] = [
        (
            vec![
                "render".into(),
                "no/such/scene.pbrt".into(),
                "--partial".into(),
                m("p.part"),
            ],
            "cannot write the partial",
        ),
        (
            vec![
                "render".into(),
                "no/such/scene.pbrt".into(),
                "--mse-reference-image".into(),
                "no/such/ref.exr".into(),
                "--mse-reference-out".into(),
                m("mse.txt"),
            ],
            "cannot write --mse-reference-out",
        ),
        (
            vec![
                "radiosity".into(),
                "no/such/scene.pbrt".into(),
                "--save-solution".into(),
                m("s.bin"),
            ],
            "cannot write the solution",
        ),
        (
            vec![
                "lens".into(),
                "no/such/lens.dat".into(),
                "--svg".into(),
                m("x.svg"),
            ],
            "x.svg",
        ),
        (
            vec![
                "compare".into(),
                "no/such/a.exr".into(),
                "no/such/b.exr".into(),
                "--diff".into(),
                m("d.png"),
            ],
            "d.png",
        ),
        (
            vec![
                "compare".into(),
                "no/such/a.exr".into(),
                "no/such/b.exr".into(),
                "--html".into(),
                m("r.html"),
            ],
            "r.html",
        ),
    ];
    for (args, expect) in cases {
        let out = radiant().args(&args).output().unwrap();
        let what = args.join(" ");
        let stderr = assert_clean_failure(&out, &what);
        assert!(stderr.contains(expect), "{what}: {stderr}");
        assert!(stderr.contains("does not exist"), "{what}: {stderr}");
        assert!(!stderr.contains("no/such/"), "{what}: {stderr}");
        assert!(out.stdout.is_empty(), "{what}: printed before failing");
    }
}

fn spawn(args: &[&str], output: &Path) -> Child {
    radiant()
        .args(args)
        .arg("-o")
        .arg(output)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([format!("-{name}"), child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

/// The render has started its passes once the previous image is no longer the only
/// file... which cannot be seen from outside; waiting a while is the robust choice: the
/// renders below take minutes uninterrupted, so any moment in the first seconds lies
/// within the render.
fn let_it_run() {
    std::thread::sleep(Duration::from_millis(2000));
}

/// The reported sample count, from "… (N spp) …".
fn reported_spp(stderr: &str) -> i32 {
    let at = stderr.find(" spp)").expect("a sample count in the message");
    let start = stderr[..at].rfind('(').unwrap() + 1;
    stderr[start..at].parse().unwrap()
}

#[test]
fn every_stopping_signal_writes_the_partial_render() {
    let dir = temp_dir("signals");
    for (integrator, sig) in [
        ("path", "INT"),
        ("path", "TERM"),
        ("path", "HUP"),
        ("sppm", "TERM"),
    ] {
        let path = dir.join(format!("{integrator}-{sig}.exr"));
        previous_render(&path);
        let child = spawn(
            &[
                "render",
                "--integrator",
                integrator,
                "--spp",
                "1000000",
                "--resolution",
                "32x32",
                "--quiet",
            ],
            &path,
        );
        let_it_run();
        signal(&child, sig);
        let out = child.wait_with_output().unwrap();
        let what = format!("{integrator} SIG{sig}");
        let stderr = assert_clean_failure(&out, &what);
        let last = stderr.lines().last().unwrap_or("");
        assert!(
            last.starts_with("radiant: interrupted: wrote"),
            "{what}: {stderr}"
        );
        let img = read_image(&path).unwrap();
        assert_eq!((img.width, img.height), (32, 32), "{what}");
        assert!(img.mean() > 0.0, "{what}: black partial image");
        let spp = read_exr_attributes(&path).unwrap().samples_per_pixel;
        let reported = reported_spp(&stderr);
        assert!(reported > 0, "{what}: {stderr}");
        assert_eq!(spp, Some(reported), "{what}: header and message disagree");
    }
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

/// Two or three signals in quick succession during a large image's write: the output
/// is the previous file, untouched, or a complete image of the new size — never a
/// truncated one.
#[test]
fn repeated_signals_never_leave_a_truncated_image() {
    let dir = temp_dir("double-signal");
    for (k, (count, gap_ms)) in [(2, 30), (2, 150), (3, 20)].into_iter().enumerate() {
        let path = dir.join(format!("big-{k}.exr"));
        let before = previous_render(&path);
        let child = spawn(
            &[
                "render",
                "--spp",
                "1000000",
                "--resolution",
                "1200x1200",
                "--quiet",
            ],
            &path,
        );
        let_it_run();
        for i in 0..count {
            if i > 0 {
                std::thread::sleep(Duration::from_millis(gap_ms));
            }
            signal(&child, "INT");
        }
        let out = child.wait_with_output().unwrap();
        let stderr = stderr_of(&out);
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out.status.success(), "{stderr}");
        let now = std::fs::read(&path).unwrap();
        if now != before {
            let img = read_image(&path)
                .unwrap_or_else(|e| panic!("case {k}: unreadable output: {e}\n{stderr}"));
            assert_eq!((img.width, img.height), (1200, 1200), "case {k}");
            let spp = read_exr_attributes(&path).unwrap().samples_per_pixel;
            assert!(spp.is_some_and(|n| n > 0), "case {k}: {spp:?}");
        }
    }
}

/// A radiosity solve cut short writes neither image nor export (they would pass for
/// the solution) and says so; the previous files stay.
#[test]
fn an_interrupted_radiosity_solve_keeps_the_previous_outputs() {
    let dir = temp_dir("radiosity-signal");
    let image = dir.join("prev.exr");
    let before = previous_render(&image);
    let csv = dir.join("patches.csv");
    std::fs::write(&csv, b"previous table\n").unwrap();
    let child = radiant()
        .args([
            "radiosity",
            "--quiet",
            "--tolerance",
            "1e-9",
            "--max-iterations",
            "100000000",
            "--resolution",
            "16x16",
            "--patches",
        ])
        .arg(&csv)
        .arg("-o")
        .arg(&image)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let_it_run();
    signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    let stderr = assert_clean_failure(&out, "radiosity SIGTERM");
    assert!(
        stderr.contains("interrupted during the solve") && stderr.contains("no mesh"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&image).unwrap(), before);
    assert_eq!(std::fs::read(&csv).unwrap(), b"previous table\n");
}

/// Photon tracing cut short before the eye pass: no black 0-spp image over the output,
/// and a message that says so.
#[test]
fn a_photon_pass_cut_short_writes_no_black_image() {
    let dir = temp_dir("photon-signal");
    let path = dir.join("prev.exr");
    let before = previous_render(&path);
    let scene_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let text = std::fs::read_to_string(scene_dir.join("cornell-caustics.pbrt")).unwrap();
    // 10^8 photons: tracing alone takes minutes, so the signal lands in it.
    let text = text.replace(
        "Integrator \"path\" \"integer maxdepth\" [ 100 ]",
        "Integrator \"photonmap\" \"integer photons\" [ 100000000 ] \"integer causticphotons\" [ 1000 ]",
    );
    assert!(text.contains("100000000"));
    let scene = write_scene(&dir, "many-photons.pbrt", &text);
    let child = radiant()
        .arg("render")
        .arg(&scene)
        .args([
            "--resolution",
            "16x16",
            "--memory-limit",
            "64G",
            "--quiet",
            "-o",
        ])
        .arg(&path)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let_it_run();
    signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    let stderr = assert_clean_failure(&out, "photon map SIGINT");
    assert!(stderr.contains("no image written"), "{stderr}");
    assert_eq!(
        std::fs::read(&path).unwrap(),
        before,
        "previous image replaced"
    );
}

#[test]
fn bad_values_are_refused_like_their_scene_file_twins() {
    for (args, expect) in [
        (&["render", "--spp", "0"][..], "--spp"),
        (&["render", "--exposure", "NaN"][..], "finite"),
        (&["render", "--exposure", "inf"][..], "finite"),
        (
            &["radiosity", "--every", "0", "--sequence", "s-##.png"][..],
            "at least 1",
        ),
        (
            &["radiosity", "--max-patch-area=-1"][..],
            "--max-patch-area: error",
        ),
        (&["radiosity", "--solver", "newton"][..], "--solver: error"),
    ] {
        let out = radiant().args(args).output().unwrap();
        let stderr = stderr_of(&out);
        assert!(!out.status.success(), "{args:?} accepted: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
        assert!(!stderr.contains(":0:0"), "{args:?}: {stderr}");
    }
}

#[test]
fn threads_are_capped_with_a_warning() {
    let dir = temp_dir("threads");
    let out = radiant()
        .args([
            "render",
            "--threads",
            "100000",
            "--spp",
            "1",
            "--resolution",
            "16x16",
            "--quiet",
            "-o",
        ])
        .arg(dir.join("t.pfm"))
        .output()
        .unwrap();
    let stderr = stderr_of(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: --threads 100000: using"),
        "{stderr}"
    );
}

fn write_scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

const CAMERA: &str = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n\
                      Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n";

#[test]
fn scene_inputs_have_limits_and_dark_scenes_a_warning() {
    let dir = temp_dir("scene-limits");
    let render = |scene: &Path| {
        radiant()
            .args(["render", "--spp", "1", "--quiet", "-o"])
            .arg(dir.join("out.pfm"))
            .arg(scene)
            .output()
            .unwrap()
    };
    // Include of a device: refused without reading it.
    let dev = write_scene(&dir, "dev.pbrt", "Include \"/dev/zero\"\n");
    let out = render(&dev);
    let stderr = assert_clean_failure(&out, "Include /dev/zero");
    assert!(
        stderr.contains("dev.pbrt:1:1") && stderr.contains("device"),
        "{stderr}"
    );

    // A 10 MB token: refused, and the message shows only a short excerpt.
    let long = format!("{CAMERA}WorldBegin\nShape \"{}\"\n", "a".repeat(10 << 20));
    let tok = write_scene(&dir, "token.pbrt", &long);
    let out = render(&tok);
    let stderr = assert_clean_failure(&out, "long token");
    assert!(stderr.contains("token.pbrt:5:7"), "{stderr}");
    assert!(stderr.len() < 400, "message of {} bytes", stderr.len());
    let shown = stderr.split('\'').nth(1).unwrap_or("");
    assert!(
        shown.chars().filter(|&c| c == 'a').count() <= 80,
        "{stderr}"
    );

    // No lights: a warning; no Integrator line: none about the implied default.
    let dark = write_scene(
        &dir,
        "dark.pbrt",
        &format!("{CAMERA}WorldBegin\nShape \"sphere\"\n"),
    );
    let out = render(&dark);
    let stderr = stderr_of(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("dark.pbrt: warning: the scene has no lights"),
        "{stderr}"
    );
    assert!(
        !stderr.contains("volpath") && !stderr.contains(":0:0"),
        "{stderr}"
    );

    let empty = write_scene(&dir, "empty.pbrt", "WorldBegin\n");
    let out = render(&empty);
    let stderr = stderr_of(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("no shapes and no lights"), "{stderr}");

    let lit = write_scene(
        &dir,
        "lit.pbrt",
        &format!(
            "{CAMERA}WorldBegin\nLightSource \"point\" \"point3 from\" [0 0 5]\nShape \"sphere\"\n"
        ),
    );
    let out = render(&lit);
    let stderr = stderr_of(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
}

/// Requests far beyond the memory budget stop with a located error naming the parameter
/// and the estimate, before allocating: run under a 4 GB address-space limit, any
/// attempt would abort the process instead ("memory allocation failed", status 134).
#[test]
fn oversized_requests_fail_with_a_located_estimate() {
    let dir = temp_dir("oversized");
    let photons = write_scene(
        &dir,
        "photons.pbrt",
        &format!(
            "Integrator \"photonmap\"\n  \"integer photons\" [ 2000000000 ]\n{CAMERA}WorldBegin\n\
             LightSource \"point\" \"point3 from\" [0 0 5]\nShape \"sphere\"\n"
        ),
    );
    let photons = photons.to_str().unwrap();
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (
            &["render", "--resolution", "100000x100000"],
            "--resolution: error: a 100000x100000 film would need ≈",
        ),
        (
            &["radiosity", "--max-patch-area", "1e-12"],
            "--max-patch-area: error: maxpatcharea 1.00e-12 would make",
        ),
        (
            &["radiosity", "--subdivision", "4096"],
            "--subdivision: error: subdivision 4096 on",
        ),
        (
            &[
                "radiosity",
                "--solver",
                "gaussseidel",
                "--max-patch-area",
                "17",
            ],
            "dense form-factor matrix",
        ),
        (
            &["render", photons],
            "photons.pbrt:2:3: error: 2000000000 photons",
        ),
    ];
    for (args, expect) in cases {
        let mut all: Vec<&str> = args.to_vec();
        all.extend(["--memory-limit", "2G", "-o", out]);
        let mut script = String::from("ulimit -v 4000000; exec \"$0\"");
        for i in 0..all.len() {
            // Braced: "$10" would be "$1" followed by "0".
            script.push_str(&format!(" \"${{{}}}\"", i + 1));
        }
        let result = Command::new("sh")
            .arg("-c")
            .arg(script)
            .arg(BIN)
            .args(&all)
            .output()
            .unwrap();
        let stderr = assert_clean_failure(&result, expect);
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
        assert!(
            stderr.contains("the memory limit is 2.1 GB"),
            "{args:?}: {stderr}"
        );
    }
}

/// Geometry is counted before the world and its BVH are built: a mesh that would take
/// more than the budget stops the run at that shape's location, naming the count.
#[test]
fn geometry_over_the_budget_fails_at_the_shape() {
    let dir = temp_dir("geometry-budget");
    // A 64 × 64 grid of quads, 8192 triangles: about 0.8 MB by the estimate. (Loop
    // subdivision, which would make as many from a few lines, checks its own working
    // set while the scene is read.)
    let n = 64;
    let points: Vec<String> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| format!("{i} {j} 0")))
        .collect();
    let indices: Vec<String> = (0..n)
        .flat_map(|j| {
            (0..n).map(move |i| {
                let a = j * (n + 1) + i;
                let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
                format!("{a} {b} {d} {a} {d} {c}")
            })
        })
        .collect();
    let scene = write_scene(
        &dir,
        "mesh.pbrt",
        &format!(
            "{CAMERA}WorldBegin\nLightSource \"point\" \"point3 from\" [0 0 5]\n\
             Shape \"sphere\"\n\
             Shape \"trianglemesh\" \"point3 P\" [{}]\n\
             \"integer indices\" [{}]\n",
            points.join(" "),
            indices.join(" ")
        ),
    );
    let out = dir.join("out.exr");
    let run = |limit: &str| {
        radiant()
            .args(["render", "--quiet", "--memory-limit", limit, "-o"])
            .arg(&out)
            .arg(&scene)
            .output()
            .unwrap()
    };
    let result = run("500K");
    let stderr = assert_clean_failure(&result, "a mesh over the budget");
    assert!(
        stderr
            .contains("mesh.pbrt:7:1: error: 8193 primitives up to this shape would need ≈ 787 kB"),
        "{stderr}"
    );
    assert!(!out.exists());
    assert!(run("100M").status.success());
}

/// A dense solve over about 10^4 patches spends minutes on its form factors; they are
/// computed in blocks of rows that each ask for cancellation, so a signal ends the run
/// within a second (process exit included) and the previous image stays.
#[test]
fn a_signal_during_the_form_factors_stops_the_run_at_once() {
    let dir = temp_dir("factors-signal");
    let image = dir.join("prev.exr");
    let before = previous_render(&image);
    let child = radiant()
        .args([
            "radiosity",
            "--quiet",
            "--solver",
            "gaussseidel",
            "--max-patch-area",
            "240",
            "--resolution",
            "16x16",
            "-o",
        ])
        .arg(&image)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let_it_run();
    let sent = std::time::Instant::now();
    signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    let latency = sent.elapsed();
    let stderr = assert_clean_failure(&out, "radiosity form factors SIGINT");
    assert!(stderr.contains("interrupted during the solve"), "{stderr}");
    // Uninterrupted, the factors take over 8 s here: a bound of 5 s tells a phase that
    // polls from one that runs to its end, with room for a loaded machine.
    assert!(
        latency < Duration::from_secs(5),
        "{latency:?} from the signal to the exit"
    );
    assert_eq!(std::fs::read(&image).unwrap(), before);
}

/// Library errors that carry an OS error in their own message are not followed by the
/// same OS error again.
#[test]
fn os_errors_are_said_once() {
    let dir = temp_dir("os-error-once");
    let at = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let cases = [
        vec!["merge".into(), at("missing.part"), "-o".into(), at("m.exr")],
        vec!["lens".into(), at("missing.dat")],
        vec![
            "render".into(),
            "--integrator".into(),
            "radiosity".into(),
            "--solution".into(),
            at("missing.bin"),
            "--resolution".into(),
            "2x2".into(),
            "-o".into(),
            at("r.exr"),
        ],
    ];
    for args in cases {
        let out = radiant().args(&args).output().unwrap();
        let stderr = assert_clean_failure(&out, &args[0]);
        assert_eq!(stderr.matches("os error 2").count(), 1, "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
}
