//! `radiant study` end to end: the report's metrics table holds exactly what `radiant
//! compare --json --flip` prints for the saved images, the page passes its own
//! self-test in headless Chromium (no console errors; the swipe slider and exposure
//! change the canvas pixels to the expected sRGB values; the table read back from the
//! page equals compare's numbers), crops and a realistic camera work, and the path
//! tracer's relMSE on the Cornell box falls as 1/N.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

mod common;
use common::*;

fn radiant(args: &[&str]) -> (String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("radiant binary runs");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(out.status.success(), "radiant {args:?} failed:\n{stderr}");
    (stdout, stderr)
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// One row of the metrics table: `data-key` → `data-value`.
type Row = Vec<(String, Option<f64>)>;

/// The metrics table of a report: per `data-method` row, its cells.
fn table(html: &str) -> Vec<(String, Row)> {
    let body = &html[html.find("<tbody>").expect("table body")..];
    let body = &body[..body.find("</tbody>").expect("table body end")];
    body.split("<tr data-method=\"")
        .skip(1)
        .map(|row| {
            let name = row[..row.find('"').unwrap()].replace("&amp;", "&");
            let cells = row
                .split("<td data-key=\"")
                .skip(1)
                .map(|cell| {
                    let key = cell[..cell.find('"').unwrap()].to_string();
                    let v = cell.split("data-value=\"").nth(1).unwrap();
                    let v = &v[..v.find('"').unwrap()];
                    (key, v.parse::<f64>().ok())
                })
                .collect();
            (name, cells)
        })
        .collect()
}

fn cell(row: &[(String, Option<f64>)], key: &str) -> Option<f64> {
    row.iter()
        .find(|(k, _)| k == key)
        .unwrap_or_else(|| panic!("no {key} cell"))
        .1
}

/// What `radiant compare TEST REF --json --flip [--crop C]` prints.
fn compare_json(test: &Path, reference: &Path, crop: Option<&str>) -> String {
    let mut args = vec!["compare", s(test), s(reference), "--json", "--flip"];
    if let Some(c) = crop {
        args.extend(["--crop", c]);
    }
    radiant(&args).0.trim().to_string()
}

/// The text of number `key` in a flat JSON object. Read as text and parsed with Rust's
/// correctly rounded parser: serde_json's default float parsing may be off by an ulp.
fn field<'a>(json: &'a str, key: &str) -> &'a str {
    let marker = format!("\"{key}\": ");
    let at = json
        .find(&marker)
        .unwrap_or_else(|| panic!("no {key} in {json}"))
        + marker.len();
    let rest = &json[at..];
    rest[..rest.find([',', '}']).unwrap()].trim()
}

fn number(json: &str, key: &str) -> Option<f64> {
    field(json, key).parse().ok()
}

/// Every number of the report's table row equals compare's, exactly (both print the
/// shortest representation that round-trips).
fn assert_row_matches(row: &[(String, Option<f64>)], cmp: &str, what: &str) {
    for (key, json_key) in [
        ("relmse", "relmse"),
        ("rmse", "rmse"),
        ("mae", "mae"),
        ("flip", "flip_mean"),
    ] {
        assert_eq!(
            cell(row, key),
            number(cmp, json_key),
            "{what}: {key} in the report vs compare {cmp}"
        );
    }
}

const METHODS: [(&str, &str); 2] = [("path", "path tracing"), ("sppm", "SPPM")];

fn find_chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("RADIANT_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| {
            ["chromium", "chromium-browser", "google-chrome"]
                .into_iter()
                .map(move |n| dir.join(n))
        })
        .find(|p| p.is_file())
}

/// The page's self-test result (`file#selftest`, DOM dumped by headless Chromium).
fn selftest(chromium: &Path, file: &Path) -> Value {
    let profile = file.with_extension("chromium-profile");
    let _ = std::fs::remove_dir_all(&profile);
    let mut child = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg("--dump-dom")
        .arg(format!("file://{}#selftest", file.display()))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("start chromium");
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        stdout.read_to_string(&mut s).map(|_| s)
    });
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish within 120 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let dom = reader.join().unwrap().unwrap();
    let _ = std::fs::remove_dir_all(&profile);
    let open = "<pre id=\"selftest-result\">";
    let at = dom.rfind(open).expect("self-test result in the page");
    let body = &dom[at + open.len()..];
    let body = &body[..body.find("</pre>").unwrap()];
    let text = body
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&nbsp;", "\u{a0}")
        .replace("&amp;", "&");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("bad JSON ({e}):\n{text}"))
}

fn bytes3(v: &Value) -> Vec<i64> {
    v.as_array().unwrap()[..3]
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect()
}

#[test]
fn study_report_agrees_with_compare_and_checks_itself_in_chromium() {
    let dir = temp_dir("box");
    let report = dir.join("report.html");
    let images = dir.join("images");
    let (stdout, stderr) = radiant(&[
        "study",
        "cornell-box",
        "--resolution",
        "64x64",
        "--equal-spp",
        "16",
        "--methods",
        "path,sppm",
        "--reference-spp",
        "256",
        "--save-images",
        s(&images),
        "-o",
        s(&report),
    ]);
    assert!(stderr.contains("no --reference given"), "{stderr}");
    assert!(stdout.starts_with("method"), "{stdout}");
    let html = std::fs::read_to_string(&report).unwrap();
    assert!(
        html.contains("reference: rendered by this study with the path tracer, 256 spp"),
        "the report says how the reference was made"
    );
    let rows = table(&html);
    assert_eq!(rows.len(), METHODS.len());
    let mut expected = Vec::new();
    for ((integrator, label), (name, row)) in METHODS.iter().zip(&rows) {
        assert_eq!(name, label);
        assert_eq!(cell(row, "effort"), Some(16.0), "{label}");
        let cmp = compare_json(
            &images.join(format!("{integrator}.exr")),
            &images.join("reference.exr"),
            None,
        );
        assert_row_matches(row, &cmp, label);
        expected.push(cmp);
    }
    // Every snapshot up to 16 spp is plotted: 1, 2, 4, 8, 16.
    let points = html
        .matches("<title>path tracing: samples per pixel")
        .count();
    assert_eq!(points, 5, "relMSE-vs-samples points of the path tracer");

    let Some(chromium) = find_chromium() else {
        println!(
            "SKIPPED the browser half of study_report_agrees_with_compare_and_checks_itself_in_chromium: \
             no chromium on PATH (install Debian's `chromium` or set RADIANT_CHROMIUM)"
        );
        return;
    };
    let result = selftest(&chromium, &report);
    assert_eq!(result["errors"], serde_json::json!([]), "console errors");
    assert_eq!(result["settled"], true);
    assert_eq!(
        result["finished"], true,
        "self-test: {}",
        result["exception"]
    );
    assert_eq!(result["externalReferences"], serde_json::json!([]));
    for control in ["swipe", "exposure"] {
        let c = &result["checks"][control];
        assert_eq!(c["changed"], true, "{control} changed no pixel: {c}");
        assert_eq!(c["ok"], true, "{control}: {c}");
        // The page's expectation is computed from its decoded data; check it is not
        // trivially met by a blank canvas.
        assert_ne!(bytes3(&c["before"]), vec![0, 0, 0], "{control}: {c}");
    }
    let page_rows = result["table"]["rows"].as_array().unwrap();
    assert_eq!(page_rows.len(), METHODS.len());
    for ((_, label), (row, cmp)) in METHODS.iter().zip(page_rows.iter().zip(&expected)) {
        assert_eq!(row["method"], *label);
        for (key, json_key) in [
            ("relmse", "relmse"),
            ("rmse", "rmse"),
            ("mae", "mae"),
            ("flip", "flip_mean"),
        ] {
            // Both sides print the shortest round-trip digits: equal text, read alike.
            let want: Value = serde_json::from_str(field(cmp, json_key)).unwrap();
            assert_eq!(
                row["cells"][key]["value"], want,
                "{label} {key}: page vs compare {cmp}"
            );
        }
    }
}

#[test]
fn crop_on_a_realistic_camera() {
    let dir = temp_dir("lens");
    let scene = radiant_testkit::repo_path("scenes/lens/lens-dgauss.pbrt");
    let report = dir.join("report.html");
    let images = dir.join("images");
    let crop = "8,4,40,28";
    radiant(&[
        "study",
        s(&scene),
        "--resolution",
        "48x32",
        "--equal-spp",
        "4",
        "--methods",
        "path,sppm",
        "--reference-spp",
        "32",
        "--crop",
        crop,
        "--save-images",
        s(&images),
        "-o",
        s(&report),
        "--quiet",
    ]);
    let html = std::fs::read_to_string(&report).unwrap();
    assert!(html.contains("camera: realistic, lens dgauss.50mm.dat"));
    assert!(html.contains("metrics over the crop x ∈ [8, 40), y ∈ [4, 28)"));
    let rows = table(&html);
    for ((integrator, label), (_, row)) in METHODS.iter().zip(&rows) {
        let test = images.join(format!("{integrator}.exr"));
        let reference = images.join("reference.exr");
        assert_row_matches(row, &compare_json(&test, &reference, Some(crop)), label);
        // The crop matters: the whole image's relMSE differs.
        let whole = compare_json(&test, &reference, None);
        assert_ne!(cell(row, "relmse"), number(&whole, "relmse"), "{label}");
    }
}

/// The path tracer's relMSE on the Cornell box against the shared 256² reference (its own
/// relMSE ≈ 2·10⁻⁵, far below the render's): the least-squares slope over the later
/// snapshots is −1 ± 0.1 in log–log, as for any unbiased estimator with finite variance
/// and independent samples — the scene's own file with `Sampler "independent"`. (With
/// the scene's Owen-scrambled Sobol' points the slope is steeper, −1.09 to −1.11 at
/// these sample counts: they integrate the image's smooth parts faster than 1/N.)
#[test]
fn path_tracer_relmse_falls_as_one_over_n() {
    let dir = temp_dir("slope");
    let reference = radiant_testkit::shared_root().join("refs/cornell-box-256-ref.exr");
    let scene = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.pbrt"),
    )
    .expect("scenes/cornell-box.pbrt");
    assert!(
        scene.contains("Sampler \"sobol\""),
        "the scene's sampler line"
    );
    let independent = dir.join("cornell-box-independent.pbrt");
    std::fs::write(
        &independent,
        scene.replace("Sampler \"sobol\"", "Sampler \"independent\""),
    )
    .unwrap();
    let (stdout, _) = radiant(&[
        "study",
        s(&independent),
        "--equal-spp",
        "64",
        "--methods",
        "path",
        "--reference",
        s(&reference),
        "-o",
        s(&dir.join("report.html")),
        "--quiet",
    ]);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("path "))
        .unwrap_or_else(|| panic!("{stdout}"));
    let slope: f64 = line.split_whitespace().nth(6).unwrap().parse().unwrap();
    assert!(
        (slope + 1.0).abs() <= 0.1,
        "relMSE slope {slope}:\n{stdout}"
    );
}

#[test]
fn compare_flip_diff_and_html() {
    let dir = temp_dir("compare");
    let refs = radiant_testkit::shared_root().join("refs");
    let (box_ref, caustics) = (
        refs.join("cornell-box-256-ref.exr"),
        refs.join("cornell-caustics-256-ref.exr"),
    );
    let diff = dir.join("flip.png");
    let page = dir.join("pair.html");
    let (stdout, _) = radiant(&[
        "compare",
        s(&caustics),
        s(&box_ref),
        "--flip",
        "--diff",
        s(&diff),
        "--html",
        s(&page),
    ]);
    let flip: f64 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("flip_mean "))
        .unwrap_or_else(|| panic!("{stdout}"))
        .parse()
        .unwrap();
    // Two different scenes: a large perceived difference, but not everywhere maximal.
    assert!(flip > 0.05 && flip < 0.9, "flip {flip}");
    // The --diff PNG is the ꟻLIP map in magma: its mean, read back through the colour
    // map's lightness order, matches the printed mean to within 8-bit quantisation.
    let png = radiant::image::png::read_png(&diff).unwrap();
    assert_eq!((png.width, png.height), (256, 256));
    let magma = radiant::image::flip::MAGMA;
    let to_byte = |v: f32| radiant::image::png::encode_srgb8(v);
    let mut sum = 0.0;
    for p in &png.pixels {
        let c = p.to_array().map(to_byte);
        let i = magma.iter().position(|m| *m == c).expect("a magma colour");
        sum += i as f64 / 255.0;
    }
    let mean = sum / png.pixels.len() as f64;
    assert!((mean - flip).abs() < 2.0 / 255.0, "{mean} vs {flip}");
    // An image against itself: no ꟻLIP error.
    let (same, _) = radiant(&["compare", s(&box_ref), s(&box_ref), "--flip", "--json"]);
    assert!(same.contains("\"flip_mean\": 0.0"), "{same}");

    let html = std::fs::read_to_string(&page).unwrap();
    let rows = table(&html);
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].0, "cornell-caustics-256-ref.exr");
    assert_row_matches(&rows[0].1, &compare_json(&caustics, &box_ref, None), "pair");
    assert_eq!(
        html.matches("class=\"panel\"").count(),
        2,
        "reference and test"
    );
}
