//! The `radiant compare` subcommand end to end: output layout, agreement with
//! `shared/tools/compare.py`, and clean failures.

use std::path::PathBuf;
use std::process::Command;

fn refs() -> PathBuf {
    radiant_testkit::shared_root().join("refs")
}

fn radiant(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("radiant binary runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn figure(stdout: &str, name: &str) -> f64 {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(' ')?.parse().ok())
        .unwrap_or_else(|| panic!("no `{name}` in output:\n{stdout}"))
}

#[test]
fn matches_compare_py_on_the_references() {
    let test = refs().join("cornell-caustics-256-ref.pfm");
    let reference = refs().join("cornell-box-256-ref.exr");
    let (ok, stdout, stderr) = radiant(&[
        "compare",
        test.to_str().unwrap(),
        reference.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    // `python3 shared/tools/compare.py cornell-caustics-256-ref.pfm cornell-box-256-ref.pfm`
    // (numpy, an independent implementation) prints these six-digit figures; the EXR and
    // PFM copies of the box reference are identical, so either may be the reference here.
    let expected = [
        ("rmse", 0.217349),
        ("relmse", 3.27418),
        ("mae", 0.0330826),
        ("mean_test", 0.169846),
        ("mean_ref", 0.150794),
    ];
    for (name, want) in expected {
        let got = figure(&stdout, name);
        // Both sides print 6 significant digits: equal strings, hence equal numbers.
        assert_eq!(got, want, "{name}:\n{stdout}");
    }
    assert_eq!(figure(&stdout, "nonfinite"), 0.0);
}

#[test]
fn crop_json_and_diff() {
    let box_ref = refs().join("cornell-box-256-ref.pfm");
    let dir = std::env::temp_dir().join(format!("radiant-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let diff = dir.join("diff.png");
    let (ok, stdout, stderr) = radiant(&[
        "compare",
        box_ref.to_str().unwrap(),
        box_ref.to_str().unwrap(),
        "--crop",
        "10,20,30,40",
        "--json",
        "--diff",
        diff.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let line = stdout.trim();
    assert!(line.starts_with('{') && line.ends_with('}'), "{line}");
    assert!(
        line.contains("\"rmse\": 0.0") && line.contains("\"nonfinite\": 0"),
        "{line}"
    );
    // An image against itself: zero error everywhere, so the ramp's scale is 0.
    assert!(line.contains("\"diff_scale\": 0.0"), "{line}");
    let png = radiant::image::png::read_png(&diff).unwrap();
    std::fs::remove_file(&diff).ok();
    assert_eq!((png.width, png.height), (256, 256));
}

#[test]
fn failures_exit_nonzero_and_name_the_file() {
    let box_ref = refs().join("cornell-box-256-ref.pfm");
    let furnace = refs().join("furnace-64-analytic.pfm");
    let (ok, _, stderr) = radiant(&["compare", "no-such-render.exr", box_ref.to_str().unwrap()]);
    assert!(!ok && stderr.contains("no-such-render.exr"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");

    let (ok, _, stderr) = radiant(&[
        "compare",
        furnace.to_str().unwrap(),
        box_ref.to_str().unwrap(),
    ]);
    assert!(
        !ok && stderr.contains("furnace-64-analytic.pfm"),
        "{stderr}"
    );
    assert!(
        stderr.contains("64x64") && stderr.contains("256x256"),
        "{stderr}"
    );

    let (ok, _, stderr) = radiant(&[
        "compare",
        box_ref.to_str().unwrap(),
        box_ref.to_str().unwrap(),
        "--crop",
        "0,0,300,10",
    ]);
    assert!(!ok && stderr.contains("crop"), "{stderr}");
}

/// A reader that stops reading (`radiant compare a b | head -1`) ends the command
/// quietly with success, not with a panic; a standard output that cannot be written
/// for another reason is a clear error.
#[test]
fn a_closed_standard_output_is_not_a_panic() {
    let image = refs().join("cornell-box-256-ref.exr");
    let image = image.to_str().unwrap();
    let compare_into = |stdout: std::process::Stdio| {
        Command::new(env!("CARGO_BIN_EXE_radiant"))
            .args(["compare", image, image])
            .env("RUST_BACKTRACE", "0")
            .stdout(stdout)
            .output()
            .expect("radiant binary runs")
    };
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let out = compare_into(writer.into());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
    if std::path::Path::new("/dev/full").exists() {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full opens");
        let out = compare_into(full.into());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains("standard output"), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

/// NaN in either image is counted in that image's own figure, and the metrics stay
/// finite: a test NaN counts as 0, a reference NaN is left out.
#[test]
fn non_finite_values_are_counted_in_each_image() {
    use radiant::color::Rgb;
    use radiant::image::{Image, ImageMeta, write_image};
    let dir = std::env::temp_dir().join(format!("radiant-compare-nan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut clean = Image::new(2, 2);
    clean.pixels.fill(Rgb::splat(0.5));
    let mut nan = clean.clone();
    nan.set(1, 1, Rgb::splat(f32::NAN));
    let (a, b) = (dir.join("clean.pfm"), dir.join("nan.pfm"));
    write_image(&a, &clean, &ImageMeta::default(), 0.0).unwrap();
    write_image(&b, &nan, &ImageMeta::default(), 0.0).unwrap();
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());

    // The reference has the NaN pixel: left out, so the rest matches exactly.
    let (ok, stdout, stderr) = radiant(&["compare", a, b]);
    assert!(ok, "{stderr}");
    assert_eq!(figure(&stdout, "nonfinite"), 0.0, "{stdout}");
    assert_eq!(figure(&stdout, "nonfinite_ref"), 3.0, "{stdout}");
    assert_eq!(figure(&stdout, "rmse"), 0.0, "{stdout}");
    assert_eq!(figure(&stdout, "mean_ref"), 0.5, "{stdout}");

    // The test has it: counted as 0 against the reference's 0.5.
    let (ok, stdout, stderr) = radiant(&["compare", b, a, "--json"]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("\"nonfinite\": 3") && stdout.contains("\"nonfinite_ref\": 0"),
        "{stdout}"
    );
    assert!(stdout.contains("\"rmse\": 0.25"), "{stdout}");

    // A reference with nothing finite to compare against is an error.
    let (ok, _, stderr) = radiant(&["compare", a, b, "--crop", "1,1,2,2"]);
    assert!(!ok && stderr.contains("NaN or infinite"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}
