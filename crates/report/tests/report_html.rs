//! Checks on the generated document that need no browser: it is self-contained, its
//! embedded data decode back to the images given, it stays within its size budget, and
//! problems are reported rather than hidden.

mod common;

use common::*;
use radiant_report::{
    Effort, MethodResult, MetricsRow, Precision, ReportImage, StudyReport, stored_value,
    write_report,
};
use serde_json::Value;

fn data_json(html: &str) -> Value {
    let text = script_text(html, "report-data").expect("report-data script");
    serde_json::from_str(text).expect("report data is JSON")
}

fn floats(html: &str, blob: &Value, precision: Precision) -> Vec<f32> {
    let id = blob.as_str().expect("blob id");
    let bytes = base64_decode(script_text(html, id).expect("blob script"));
    match precision {
        Precision::F32 => bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect(),
        Precision::F16 => bytes
            .chunks_exact(2)
            .map(|b| radiant_report::f16_bits_to_f32(u16::from_le_bytes(b.try_into().unwrap())))
            .collect(),
    }
}

#[test]
fn document_is_self_contained() {
    let html = write_report(&study(Precision::F32));
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.trim_end().ends_with("</html>"));
    let lower = html.to_lowercase();
    for banned in ["http://", "https://", "<link", " src=", "@import"] {
        assert!(!lower.contains(banned), "found {banned:?}");
    }
    // url(...) only for the plots' own clip paths.
    assert!(
        lower
            .match_indices("url(")
            .all(|(i, _)| lower[i..].starts_with("url(#"))
    );
    // Five inline scripts of our own plus the data: none may be closed early by the
    // scene name, which contains "</script>".
    assert!(html.contains("known pixels &lt;/script&gt; &amp; co"));
    let data = data_json(&html);
    assert_eq!(data["scene"], "known pixels </script> & co");
    // Readable: every line of the document is short except the plots' point lists.
    let long = html
        .lines()
        .filter(|l| l.len() > 200 && !l.contains("points="))
        .count();
    assert_eq!(long, 0, "lines over 200 characters");
}

#[test]
fn embedded_images_decode_to_the_given_values() {
    for precision in [Precision::F32, Precision::F16] {
        let report = study(precision);
        let html = write_report(&report);
        let data = data_json(&html);
        assert_eq!(
            data["precision"],
            if precision == Precision::F32 {
                "f32"
            } else {
                "f16"
            }
        );
        let images = data["images"].as_array().expect("images");
        assert_eq!(images.len(), 1 + report.methods.len());
        let given: Vec<&ReportImage> = std::iter::once(&report.reference)
            .chain(report.methods.iter().map(|m| &m.image))
            .collect();
        for (entry, img) in images.iter().zip(given) {
            assert_eq!(entry["width"], img.width);
            assert_eq!(entry["height"], img.height);
            let got = floats(&html, &entry["data"], precision);
            let want: Vec<f32> = img
                .pixels
                .iter()
                .flatten()
                .map(|&v| stored_value(v, precision))
                .collect();
            assert_eq!(got, want, "{} at {precision:?}", entry["name"]);
        }
        // Only alpha has a ꟻLIP map.
        let flip = floats(&html, &images[1]["flip"], precision);
        let want: Vec<f32> = report.methods[0].flip_map.as_ref().unwrap().clone();
        let want: Vec<f32> = want.iter().map(|&v| stored_value(v, precision)).collect();
        assert_eq!(flip, want);
        assert!(images[2]["flip"].is_null() && images[3]["flip"].is_null());
    }
}

#[test]
fn size_mismatches_are_reported_not_hidden() {
    let mut report = study(Precision::F32);
    report.methods[0].flip_map = Some(vec![0.5; 3]);
    let html = write_report(&report);
    // gamma is half size; alpha's map has the wrong length and is left out.
    assert!(html.contains("gamma: image is 32×24, reference is 64×48; no error views"));
    assert!(html.contains("alpha: ꟻLIP map has 3 values for 3072 pixels; left out"));
    assert!(data_json(&html)["images"][1]["flip"].is_null());
    // With no usable map the ꟻLIP view cannot be chosen.
    assert!(html.contains("<option value=\"flip\" disabled>"));
    let mut consistent = study(Precision::F32);
    consistent.methods.pop(); // gamma
    let clean = write_report(&consistent);
    assert!(!clean.contains("class=\"warnings\""));
    assert!(clean.contains("<option value=\"flip\">"));
}

#[test]
fn page_has_the_viewer_table_and_plots() {
    let report = study(Precision::F32);
    let html = write_report(&report);
    assert_eq!(html.matches("<figure class=\"panel\"").count(), 4);
    for id in [
        "exposure",
        "display-mode",
        "swipe-a",
        "swipe-b",
        "swipe-position",
        "swipe-canvas",
        "metrics",
        "plot-relmse-time",
        "plot-relmse-samples",
        "plot-flip-time",
    ] {
        assert!(html.contains(&format!("id=\"{id}\"")), "missing #{id}");
    }
    assert_eq!(html.matches("expected slope −1.0").count(), 2);
    // alpha's series falls exactly as 1/N, so its fitted slope reads −1.0 in both plots.
    assert_eq!(html.matches(">alpha (slope −1.0)</text>").count(), 2);
    assert!(html.contains("data-key=\"relmse\" data-value=\"1.5e-7\" class=\"best\">1.500e-7<"));
}

fn big_method(i: u64, size: usize) -> MethodResult {
    MethodResult {
        name: format!("method {i}"),
        image: ReportImage::from_fn(size, size, |x, y| {
            [x as f32 * 0.01, y as f32 * 0.003 + i as f32, 0.7]
        }),
        flip_map: Some(vec![0.25; size * size]),
        metrics: MetricsRow {
            relmse: 0.01,
            rmse: 0.1,
            mae: 0.05,
            flip_mean: Some(0.2),
            seconds: 10.0,
            effort: Effort::SamplesPerPixel(64),
        },
        convergence: vec![],
    }
}

#[test]
fn report_of_five_256_images_stays_under_20_mb() {
    let make = |precision| StudyReport {
        scene: "size".to_string(),
        notes: vec![],
        camera: None,
        crop: None,
        reference: ReportImage::filled(256, 256, [0.5, 0.5, 0.5]),
        methods: (0..4).map(|i| big_method(i, 256)).collect(),
        precision,
    };
    let f32_len = write_report(&make(Precision::F32)).len();
    let f16_len = write_report(&make(Precision::F16)).len();
    // Raw data: 5 RGB images + 4 ꟻLIP maps = 19 × 65536 floats; base64 adds 4/3.
    let raw = 19.0 * 65536.0 * 4.0 * 4.0 / 3.0;
    assert!(f32_len < 20_000_000, "{f32_len} bytes");
    assert!(
        (f32_len as f64) < raw * 1.05,
        "{f32_len} bytes for {raw} of data"
    );
    assert!(
        (f16_len as f64) < 0.55 * f32_len as f64,
        "f16 {f16_len} vs f32 {f32_len}"
    );
}
