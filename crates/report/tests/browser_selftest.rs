//! Opens generated reports in headless Chromium with `#selftest` and checks what the page
//! reports about itself: no errors, the swipe slider and exposure change the displayed
//! pixels to the sRGB values computed here, the error views show the expected colours,
//! and the metrics table holds exactly the numbers given.
//!
//! Skipped, with a message, only when no Chromium binary can be found (set
//! `RADIANT_CHROMIUM` to choose one).

mod common;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;
use radiant_report::{Precision, StudyReport, efficiency, stored_value, write_report};
use serde_json::Value;

const NAMES: [&str; 5] = [
    "chromium",
    "chromium-browser",
    "google-chrome",
    "google-chrome-stable",
    "chrome",
];

fn find_chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("RADIANT_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| NAMES.iter().map(move |n| dir.join(n)))
        .find(|p| p.is_file())
}

/// Runs Chromium on `file#selftest` and returns the dumped DOM; panics after 120 s.
fn dump_dom(chromium: &Path, file: &Path, tag: &str) -> String {
    let profile = std::env::temp_dir().join(format!(
        "radiant-report-chromium-{}-{tag}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&profile);
    let url = format!("file://{}#selftest", file.display());
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
        .arg(&url)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {}: {e}", chromium.display()));
    // Read stdout on its own thread so a large dump cannot fill the pipe and stall.
    let mut stdout = child.stdout.take().expect("piped stdout");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        stdout.read_to_string(&mut s).map(|_| s)
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for chromium") {
            break status;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish within 120 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let dom = reader
        .join()
        .expect("reader thread")
        .expect("chromium stdout");
    let _ = std::fs::remove_dir_all(&profile);
    assert!(status.success(), "chromium exited with {status}");
    dom
}

/// The JSON in the last `<pre id="selftest-result">` (the script's own source mentions
/// the id too), with the HTML escapes of a text node undone.
fn selftest_json(dom: &str) -> Value {
    let open = "<pre id=\"selftest-result\">";
    let at = dom.rfind(open).unwrap_or_else(|| {
        let tail = &dom[dom.len().saturating_sub(2000)..];
        panic!("no self-test result in the page; DOM ends with:\n{tail}")
    });
    let body = &dom[at + open.len()..];
    let body = &body[..body.find("</pre>").expect("closed <pre>")];
    let text = body
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&nbsp;", "\u{a0}")
        .replace("&amp;", "&");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("bad JSON ({e}):\n{text}"))
}

fn bytes(v: &Value) -> Vec<i64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_i64().expect("integer"))
        .collect()
}

/// `got` (RGBA) matches `want` (RGB) within one 8-bit step, and alpha is opaque.
fn assert_rgb(got: &Value, want: [u8; 3], what: &str) {
    let got = bytes(got);
    let ok =
        got.len() == 4 && got[3] == 255 && (0..3).all(|c| (got[c] - i64::from(want[c])).abs() <= 1);
    assert!(ok, "{what}: displayed {got:?}, expected {want:?}");
}

/// JavaScript's `x.toPrecision(4)` for 1e-6 ≤ x < 1 (the readout's format).
fn to_precision4(x: f64) -> String {
    let decimals = (3 - x.log10().floor() as i32) as usize;
    format!("{x:.decimals$}")
}

fn expected_srgb(v: [f32; 3], stops: f64, precision: Precision) -> [u8; 3] {
    v.map(|c| srgb8(stored_value(c, precision), stops))
}

fn check_report(chromium: &Path, report: &StudyReport, tag: &str) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let file = dir.join(format!("selftest-{tag}.html"));
    std::fs::write(&file, write_report(report)).expect("write report");
    let result = selftest_json(&dump_dom(chromium, &file, tag));
    let p = report.precision;

    assert_eq!(result["errors"], serde_json::json!([]), "page errors");
    assert_eq!(
        result["settled"], true,
        "the page did not settle within the time budget"
    );
    assert_eq!(
        result["finished"], true,
        "self-test did not finish: {}",
        result["exception"]
    );
    assert_eq!(result["externalReferences"], serde_json::json!([]));
    assert_eq!(bytes(&result["pixel"]), vec![CX as i64, CY as i64]);

    // Swipe: split at the right edge shows A (reference), at the left edge B (alpha).
    let swipe = &result["checks"]["swipe"];
    assert_rgb(
        &swipe["before"],
        expected_srgb(REF_CENTER, 0.0, p),
        "swipe, A",
    );
    assert_rgb(
        &swipe["after"],
        expected_srgb(ALPHA_CENTER, 0.0, p),
        "swipe, B",
    );
    assert_eq!(swipe["changed"], true);

    // Exposure +1 stop doubles the linear value before sRGB encoding.
    let exposure = &result["checks"]["exposure"];
    assert_rgb(
        &exposure["before"],
        expected_srgb(REF_CENTER, 0.0, p),
        "exposure 0",
    );
    assert_rgb(
        &exposure["after"],
        expected_srgb(REF_CENTER, 1.0, p),
        "exposure +1",
    );
    assert_eq!(exposure["changed"], true);
    assert_eq!(exposure["label"], "+1.0 EV");

    // Error views: beyond the top of the relative-error scale, and ꟻLIP 1.0.
    let rel = result["checks"]["relerr"]["value"]
        .as_f64()
        .expect("relerr value");
    assert!(rel > 1.0, "relative squared error {rel}");
    assert_rgb(
        &result["checks"]["relerr"]["color"],
        VIRIDIS_TOP,
        "relative error colour",
    );
    assert_eq!(result["checks"]["flip"]["value"], 1.0);
    assert_rgb(&result["checks"]["flip"]["color"], MAGMA_TOP, "ꟻLIP colour");

    // Readout of the hovered pixel, in linear values before exposure.
    let readout = &result["checks"]["readout"];
    assert_eq!(readout["position"], format!("pixel ({CX}, {CY})"));
    let text = readout["text"].as_str().expect("readout text");
    for v in REF_CENTER {
        let shown = to_precision4(f64::from(stored_value(v, p)));
        assert!(text.contains(&shown), "readout {text:?} lacks {shown}");
    }
    let zoom = &result["checks"]["zoom"];
    assert!(
        zoom["spanAfter"].as_f64() < zoom["spanBefore"].as_f64(),
        "{zoom}"
    );
    let pan = &result["checks"]["pan"];
    let (moved, want) = (
        pan["moved"].as_f64().unwrap(),
        pan["expected"].as_f64().unwrap(),
    );
    assert!(want > 0.0 && (moved - want).abs() < 1e-9 * want, "{pan}");
    let sync = &result["checks"]["sync"];
    let ref_bytes = expected_srgb(REF_CENTER, 0.0, p);
    assert_rgb(
        &sync["reference"],
        ref_bytes,
        "reference panel after zoom and pan",
    );
    assert_rgb(&sync["swipe"], ref_bytes, "swipe canvas after zoom and pan");
    let alpha_bytes = expected_srgb(ALPHA_CENTER, 0.0, p);
    assert_rgb(
        &sync["method"],
        alpha_bytes,
        "method panel after zoom and pan",
    );
    let nearest = &result["checks"]["nearest"];
    assert_rgb(&nearest["left"], ref_bytes, "magnified pixel, left edge");
    assert_rgb(&nearest["right"], ref_bytes, "magnified pixel, right edge");

    // The table holds exactly the given numbers, and its text rounds them.
    let rows = result["table"]["rows"].as_array().expect("table rows");
    assert_eq!(rows.len(), report.methods.len());
    for (row, m) in rows.iter().zip(&report.methods) {
        assert_eq!(row["method"], m.name.as_str());
        let e = &m.metrics;
        let expected = [
            ("relmse", Some(e.relmse)),
            ("rmse", Some(e.rmse)),
            ("mae", Some(e.mae)),
            ("flip", e.flip_mean),
            ("seconds", Some(e.seconds)),
            ("effort", Some(e.effort.count() as f64)),
            ("efficiency", efficiency(e)),
        ];
        for (key, want) in expected {
            let cell = &row["cells"][key];
            assert_eq!(cell["value"].as_f64(), want, "{} {key}: {cell}", m.name);
            let text = cell["text"].as_str().expect("cell text");
            match want {
                None => assert_eq!(text, "—"),
                Some(v) if key == "effort" => {
                    assert_eq!(text, format!("{} {}", v, e.effort.unit()))
                }
                Some(v) => {
                    let shown: f64 = text
                        .parse()
                        .unwrap_or_else(|_| panic!("{key} text {text:?}"));
                    assert!((shown - v).abs() <= 5e-4 * v.abs(), "{key}: {text} for {v}");
                }
            }
        }
    }
}

#[test]
fn page_checks_itself_in_headless_chromium() {
    let Some(chromium) = find_chromium() else {
        println!(
            "SKIPPED page_checks_itself_in_headless_chromium: no chromium binary found on PATH \
             (install Debian's `chromium` package or set RADIANT_CHROMIUM)"
        );
        eprintln!("SKIPPED browser self-test: no chromium binary found");
        return;
    };
    check_report(&chromium, &study(Precision::F32), "f32");
    check_report(&chromium, &study(Precision::F16), "f16");
}
