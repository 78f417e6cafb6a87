//! The report document: static HTML for everything that does not change (header,
//! metrics table, convergence plots), the image data as base64 blobs, and the page's
//! script and style inlined from `assets/`, so the file opens anywhere with no network.

use std::fmt::Write;

use crate::encode::{base64_lines, float_bytes};
use crate::plot::{PlotSpec, Series, loglog_svg};
use crate::study::{MethodResult, Precision, ReportImage, StudyReport};
use crate::table::metrics_table;
use crate::text::{html, json_number, json_string};

/// Okabe & Ito's colour-blind-safe palette ("Color Universal Design", 2008), reordered so
/// the first colours are the most distinct on white; the reference is drawn in grey.
pub const METHOD_COLORS: [&str; 7] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000",
];
const REFERENCE_COLOR: &str = "#777777";

const STYLE: &str = include_str!("assets/report.css");
const SELFTEST_HOOKS_JS: &str = include_str!("assets/selftest_hooks.js");
const COLORMAPS_JS: &str = include_str!("assets/colormaps.js");
const PIXELS_JS: &str = include_str!("assets/pixels.js");
const VIEWER_JS: &str = include_str!("assets/viewer.js");
const SELFTEST_JS: &str = include_str!("assets/selftest.js");

/// Base64 characters per line of an embedded blob.
const BLOB_LINE: usize = 120;

/// The colour of method `i` in plots, captions and the table.
pub fn method_color(i: usize) -> &'static str {
    METHOD_COLORS[i % METHOD_COLORS.len()]
}

/// Writes `report` as one self-contained HTML document.
///
/// Inconsistent parts (see [`StudyReport::problems`]) are listed as warnings at the top
/// and left out where they cannot be shown; everything else is still written.
pub fn write_report(report: &StudyReport) -> String {
    let problems = report.problems();
    let mut s = String::new();
    s.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n");
    s.push_str("  <meta charset=\"utf-8\">\n");
    s.push_str("  <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    let _ = writeln!(
        s,
        "  <title>radiant method study: {}</title>",
        html(&report.scene)
    );
    s.push_str("  <!-- Error hooks first, so the self-test sees errors in everything after. -->\n");
    push_inline(&mut s, "script", SELFTEST_HOOKS_JS);
    push_inline(&mut s, "style", STYLE);
    s.push_str("</head>\n<body>\n");
    write_header(&mut s, report, &problems);
    write_controls(&mut s, report);
    write_viewer(&mut s, report);
    write_swipe(&mut s, report);
    s.push_str("<section id=\"metrics-section\">\n  <h2>Metrics</h2>\n");
    let colors: Vec<&str> = (0..report.methods.len()).map(method_color).collect();
    s.push_str(&metrics_table(&report.methods, &colors, "  "));
    s.push_str(
        "  <p class=\"hint\">Against the reference; bold marks the best value in each column. \
         Hover a header for its definition.</p>\n",
    );
    s.push_str("</section>\n");
    write_convergence(&mut s, &report.methods);
    s.push_str(
        "<noscript><p class=\"warning\">The image viewer needs JavaScript; \
         the table and plots above do not.</p></noscript>\n",
    );
    write_data(&mut s, report);
    s.push_str("<!-- The page's scripts, in dependency order. -->\n");
    for js in [COLORMAPS_JS, PIXELS_JS, VIEWER_JS, SELFTEST_JS] {
        push_inline(&mut s, "script", js);
    }
    s.push_str("</body>\n</html>\n");
    s
}

/// `<tag>` + `body` indented by four spaces + `</tag>`, each on its own lines.
fn push_inline(s: &mut String, tag: &str, body: &str) {
    let _ = writeln!(s, "  <{tag}>");
    for line in body.lines() {
        if line.is_empty() {
            s.push('\n');
        } else {
            let _ = writeln!(s, "    {line}");
        }
    }
    let _ = writeln!(s, "  </{tag}>");
}

fn write_header(s: &mut String, report: &StudyReport, problems: &[String]) {
    s.push_str("<header>\n");
    let _ = writeln!(s, "  <h1>Method study: {}</h1>", html(&report.scene));
    if !report.notes.is_empty() {
        s.push_str("  <ul class=\"notes\">\n");
        for note in &report.notes {
            let _ = writeln!(s, "    <li>{}</li>", html(note));
        }
        s.push_str("  </ul>\n");
    }
    let r = &report.reference;
    let _ = write!(
        s,
        "  <p class=\"facts\">Image {}×{} pixels",
        r.width, r.height
    );
    if let Some(camera) = &report.camera {
        let _ = write!(s, "; camera: {}", html(camera));
    }
    if let Some(c) = report.crop {
        let _ = write!(
            s,
            "; metrics over the crop x ∈ [{}, {}), y ∈ [{}, {}) (dashed outline)",
            c.x0, c.x1, c.y0, c.y1
        );
    }
    s.push_str(".</p>\n");
    if !problems.is_empty() {
        s.push_str("  <ul class=\"warnings\">\n");
        for p in problems {
            let _ = writeln!(s, "    <li>{}</li>", html(p));
        }
        s.push_str("  </ul>\n");
    }
    s.push_str("</header>\n");
}

fn write_controls(s: &mut String, report: &StudyReport) {
    let any_flip = report.methods.iter().any(flip_usable);
    let flip_attr = if any_flip { "" } else { " disabled" };
    s.push_str("<section id=\"controls\">\n");
    s.push_str(
        "  <label>Exposure <input type=\"range\" id=\"exposure\" min=\"-10\" max=\"10\" \
         step=\"0.1\" value=\"0\"> <output id=\"exposure-value\">+0.0 EV</output></label>\n",
    );
    s.push_str("  <label>Show <select id=\"display-mode\">\n");
    s.push_str("    <option value=\"image\" selected>images</option>\n");
    s.push_str("    <option value=\"relerr\">relative squared error vs reference</option>\n");
    let _ = writeln!(
        s,
        "    <option value=\"flip\"{flip_attr}>ꟻLIP error map</option>"
    );
    s.push_str("  </select></label>\n");
    s.push_str(
        "  <span id=\"error-range\" hidden>range 10^<input type=\"number\" id=\"err-lo\" \
         value=\"-4\" step=\"1\"> to 10^<input type=\"number\" id=\"err-hi\" value=\"0\" \
         step=\"1\"></span>\n",
    );
    s.push_str("  <button type=\"button\" id=\"view-reset\">fit view</button>\n");
    s.push_str("  <span id=\"hover-position\" class=\"readout\"></span>\n");
    s.push_str(
        "  <div id=\"legend\" hidden><div id=\"legend-title\"></div>\
         <canvas id=\"legend-bar\" width=\"256\" height=\"12\"></canvas>\
         <div id=\"legend-ticks\"></div></div>\n",
    );
    s.push_str("</section>\n");
}

/// A panel per image: the reference first, then the methods in order.
fn write_viewer(s: &mut String, report: &StudyReport) {
    s.push_str("<section id=\"viewer\">\n  <h2>Images</h2>\n");
    s.push_str(
        "  <p class=\"hint\">Wheel: zoom about the cursor. Drag: pan. Double-click: fit.\n    \
         All views follow each other; the value under the cursor is shown under each image\n    \
         (linear RGB, before exposure).</p>\n",
    );
    s.push_str("  <div id=\"panels\">\n");
    for (i, (name, color)) in image_names(report).enumerate() {
        let _ = writeln!(
            s,
            "    <figure class=\"panel\" data-image=\"{i}\">\n      <canvas class=\"view\"></canvas>\n      \
             <figcaption><span class=\"swatch\" style=\"background:{color}\"></span>\
             <span class=\"name\">{}</span> <span class=\"readout\"></span></figcaption>\n    </figure>",
            html(&name)
        );
    }
    s.push_str("  </div>\n</section>\n");
}

fn write_swipe(s: &mut String, report: &StudyReport) {
    s.push_str("<section id=\"swipe\">\n  <h2>A/B swipe</h2>\n  <div class=\"swipe-controls\">\n");
    let default_b = usize::from(!report.methods.is_empty());
    for (id, label, selected) in [
        ("swipe-a", "A (left)", 0),
        ("swipe-b", "B (right)", default_b),
    ] {
        let _ = writeln!(s, "    <label>{label} <select id=\"{id}\">");
        for (i, (name, _)) in image_names(report).enumerate() {
            let sel = if i == selected { " selected" } else { "" };
            let _ = writeln!(
                s,
                "      <option value=\"{i}\"{sel}>{}</option>",
                html(&name)
            );
        }
        s.push_str("    </select></label>\n");
    }
    s.push_str(
        "    <label>split <input type=\"range\" id=\"swipe-position\" min=\"0\" max=\"1000\" \
         value=\"500\"></label>\n  </div>\n",
    );
    s.push_str("  <canvas id=\"swipe-canvas\" class=\"view\"></canvas>\n");
    s.push_str("  <p id=\"swipe-readout\" class=\"readout\"></p>\n</section>\n");
}

fn write_convergence(s: &mut String, methods: &[MethodResult]) {
    s.push_str("<section id=\"convergence\">\n  <h2>Convergence</h2>\n");
    s.push_str(
        "  <p class=\"hint\">Log–log axes. For Monte Carlo estimators relMSE falls as 1/N, a\n    \
         line of slope −1 (dashed). Slopes in the legends are least-squares fits over the\n    \
         later half of each method's snapshots; biased consistent methods (photon mapping,\n    \
         SPPM) approach their limit more slowly.</p>\n",
    );
    let series = |f: fn(&crate::study::Snapshot) -> Option<(f64, f64)>| -> Vec<Series> {
        methods
            .iter()
            .enumerate()
            .map(|(i, m)| Series {
                name: m.name.clone(),
                color: method_color(i),
                points: m.convergence.iter().filter_map(f).collect(),
            })
            .filter(|c| !c.points.is_empty())
            .collect()
    };
    let plots: [(PlotSpec, Vec<Series>); 3] = [
        (
            PlotSpec {
                id: "plot-relmse-time",
                title: "relMSE vs time",
                x_label: "time (s)",
                y_label: "relMSE",
                reference_slope: Some(-1.0),
            },
            series(|p| Some((p.seconds, p.relmse))),
        ),
        (
            PlotSpec {
                id: "plot-relmse-samples",
                title: "relMSE vs samples",
                x_label: "samples per pixel / iterations",
                y_label: "relMSE",
                reference_slope: Some(-1.0),
            },
            series(|p| Some((p.samples as f64, p.relmse))),
        ),
        (
            PlotSpec {
                id: "plot-flip-time",
                title: "ꟻLIP mean vs time",
                x_label: "time (s)",
                y_label: "ꟻLIP mean",
                reference_slope: None,
            },
            series(|p| p.flip_mean.map(|f| (p.seconds, f))),
        ),
    ];
    s.push_str("  <div class=\"plots\">\n");
    for (i, (spec, series)) in plots.iter().enumerate() {
        // The ꟻLIP plot only appears when some snapshot has a ꟻLIP value.
        if i == 2 && series.is_empty() {
            continue;
        }
        s.push_str(&loglog_svg(spec, series, "    "));
    }
    s.push_str("  </div>\n</section>\n");
}

/// Display names and colours, reference first.
fn image_names(report: &StudyReport) -> impl Iterator<Item = (String, &'static str)> + '_ {
    std::iter::once(("reference".to_string(), REFERENCE_COLOR)).chain(
        report
            .methods
            .iter()
            .enumerate()
            .map(|(i, m)| (m.name.clone(), method_color(i))),
    )
}

fn flip_usable(m: &MethodResult) -> bool {
    m.flip_map
        .as_ref()
        .is_some_and(|f| f.len() == m.image.width * m.image.height)
}

/// The JSON description of the images and one `<script type="text/plain">` blob per
/// array. Scripts of an unknown type are not run; their text is the data.
fn write_data(s: &mut String, report: &StudyReport) {
    let precision = match report.precision {
        Precision::F32 => "f32",
        Precision::F16 => "f16",
    };
    let mut blobs: Vec<(String, Vec<u8>)> = Vec::new();
    let mut add_blob = |bytes: Vec<u8>| -> String {
        let id = format!("blob-{}", blobs.len());
        blobs.push((id.clone(), bytes));
        json_string(&id)
    };
    let mut image_entry = |name: &str, img: &ReportImage, flip: Option<&Vec<f32>>| -> String {
        let blob = if img.is_consistent() {
            let values = img.pixels.iter().flat_map(|p| p.iter().copied());
            add_blob(float_bytes(values, report.precision))
        } else {
            "null".to_string()
        };
        let flip = match flip {
            Some(f) if f.len() == img.width * img.height => {
                add_blob(float_bytes(f.iter().copied(), report.precision))
            }
            _ => "null".to_string(),
        };
        format!(
            "{{\"name\": {}, \"width\": {}, \"height\": {}, \"data\": {blob}, \"flip\": {flip}}}",
            json_string(name),
            img.width,
            img.height
        )
    };
    let mut entries = vec![image_entry("reference", &report.reference, None)];
    for m in &report.methods {
        entries.push(image_entry(&m.name, &m.image, m.flip_map.as_ref()));
    }
    let crop = match report.crop {
        Some(c) => format!(
            "{{\"x0\": {}, \"y0\": {}, \"x1\": {}, \"y1\": {}}}",
            c.x0, c.y0, c.x1, c.y1
        ),
        None => "null".to_string(),
    };
    s.push_str(
        "<!-- Image data: float arrays (little endian) as base64; index 0 is the reference. -->\n",
    );
    s.push_str("<script type=\"application/json\" id=\"report-data\">\n{\n");
    let _ = writeln!(s, "  \"scene\": {},", json_string(&report.scene));
    let _ = writeln!(s, "  \"precision\": \"{precision}\",");
    let _ = writeln!(s, "  \"crop\": {crop},");
    let _ = writeln!(s, "  \"relmseEpsilon\": {},", json_number(0.01));
    s.push_str("  \"images\": [\n");
    for (i, e) in entries.iter().enumerate() {
        let comma = if i + 1 < entries.len() { "," } else { "" };
        let _ = writeln!(s, "    {e}{comma}");
    }
    s.push_str("  ]\n}\n</script>\n");
    for (id, bytes) in &blobs {
        let _ = writeln!(
            s,
            "<script type=\"text/plain\" id=\"{id}\" class=\"float-data\">"
        );
        s.push_str(&base64_lines(bytes, BLOB_LINE, ""));
        s.push_str("</script>\n");
    }
}
