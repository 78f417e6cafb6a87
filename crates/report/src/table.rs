//! The per-method metrics table, written as static HTML.
//!
//! Every numeric cell carries the exact number in `data-value` (shortest round-trip
//! form) next to its rounded text, so the page's self-test — and anyone reading the
//! source — can check the table against the data it was made from.

use std::fmt::Write;

use crate::study::{MethodResult, MetricsRow};
use crate::text::{html, json_number, significant};

/// One numeric column of the table.
struct Column {
    /// `data-key` of the cells.
    key: &'static str,
    /// Header text (HTML).
    header: &'static str,
    /// Header tooltip.
    title: &'static str,
    value: fn(&MetricsRow) -> Option<f64>,
    /// Whether the smallest value is the best one (otherwise the largest).
    lower_is_better: bool,
}

/// Work-normalised efficiency 1 / (relMSE × seconds): for an unbiased Monte Carlo
/// estimator relMSE ∝ 1/time, so this is constant over a render and compares methods
/// at equal time (Veach's "efficiency", 1/(variance × cost)).
pub fn efficiency(m: &MetricsRow) -> Option<f64> {
    let work = m.relmse * m.seconds;
    (work > 0.0 && work.is_finite()).then(|| 1.0 / work)
}

const COLUMNS: [Column; 7] = [
    Column {
        key: "relmse",
        header: "relMSE",
        title: "mean of (a−b)²/(b²+0.01) over pixels and channels; b the reference",
        value: |m| Some(m.relmse),
        lower_is_better: true,
    },
    Column {
        key: "rmse",
        header: "RMSE",
        title: "root mean squared error",
        value: |m| Some(m.rmse),
        lower_is_better: true,
    },
    Column {
        key: "mae",
        header: "MAE",
        title: "mean absolute error",
        value: |m| Some(m.mae),
        lower_is_better: true,
    },
    Column {
        key: "flip",
        header: "ꟻLIP mean",
        title: "mean ꟻLIP perceptual error (0 = identical, 1 = maximal)",
        value: |m| m.flip_mean,
        lower_is_better: true,
    },
    Column {
        key: "seconds",
        header: "time (s)",
        title: "wall-clock render time",
        value: |m| Some(m.seconds),
        lower_is_better: true,
    },
    Column {
        key: "effort",
        header: "samples",
        title: "samples per pixel (spp) or iterations (it)",
        value: |m| Some(m.effort.count() as f64),
        lower_is_better: true,
    },
    Column {
        key: "efficiency",
        header: "1/(relMSE·s)",
        title: "efficiency: higher is better; constant over time for an unbiased estimator",
        value: efficiency,
        lower_is_better: false,
    },
];

/// The best value of each column over all methods (`None` where no method has one).
fn best_values(methods: &[MethodResult]) -> Vec<Option<f64>> {
    COLUMNS
        .iter()
        .map(|c| {
            let values = methods
                .iter()
                .filter_map(|m| (c.value)(&m.metrics))
                .filter(|v| v.is_finite());
            if c.lower_is_better {
                values.reduce(f64::min)
            } else {
                values.reduce(f64::max)
            }
        })
        .collect()
}

/// The `<table id="metrics">` element, indented by `indent`.
pub fn metrics_table(methods: &[MethodResult], colors: &[&str], indent: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{indent}<table id=\"metrics\">");
    let _ = writeln!(s, "{indent}  <thead>");
    let _ = writeln!(s, "{indent}    <tr>");
    let _ = writeln!(s, "{indent}      <th scope=\"col\">method</th>");
    for c in &COLUMNS {
        let _ = writeln!(
            s,
            "{indent}      <th scope=\"col\" data-key=\"{}\" title=\"{}\">{}</th>",
            c.key,
            html(c.title),
            c.header
        );
    }
    let _ = writeln!(s, "{indent}    </tr>");
    let _ = writeln!(s, "{indent}  </thead>");
    let _ = writeln!(s, "{indent}  <tbody>");
    let best = best_values(methods);
    for (i, m) in methods.iter().enumerate() {
        let color = colors.get(i).copied().unwrap_or("#000");
        let _ = writeln!(s, "{indent}    <tr data-method=\"{}\">", html(&m.name));
        let _ = writeln!(
            s,
            "{indent}      <th scope=\"row\"><span class=\"swatch\" style=\"background:{color}\"></span>{}</th>",
            html(&m.name)
        );
        for (c, best) in COLUMNS.iter().zip(&best) {
            let value = (c.value)(&m.metrics);
            // Sample counts are in different units per method: no best among them.
            let comparable = c.key != "effort";
            let class = if comparable && value.is_some() && value == *best && methods.len() > 1 {
                " class=\"best\""
            } else {
                ""
            };
            let text = match (c.key, value) {
                ("effort", _) => {
                    format!("{} {}", m.metrics.effort.count(), m.metrics.effort.unit())
                }
                (_, Some(v)) => significant(v, 4),
                (_, None) => "—".to_string(),
            };
            let data_value = value.map_or("null".to_string(), json_number);
            let unit = if c.key == "effort" {
                format!(" data-unit=\"{}\"", m.metrics.effort.unit())
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "{indent}      <td data-key=\"{}\" data-value=\"{data_value}\"{unit}{class}>{}</td>",
                c.key,
                html(&text)
            );
        }
        let _ = writeln!(s, "{indent}    </tr>");
    }
    let _ = writeln!(s, "{indent}  </tbody>");
    let _ = writeln!(s, "{indent}</table>");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{Effort, ReportImage};

    fn method(name: &str, relmse: f64, seconds: f64, flip: Option<f64>) -> MethodResult {
        MethodResult {
            name: name.into(),
            image: ReportImage::filled(1, 1, [0.0; 3]),
            flip_map: None,
            metrics: MetricsRow {
                relmse,
                rmse: 0.5,
                mae: 0.25,
                flip_mean: flip,
                seconds,
                effort: Effort::Iterations(12),
            },
            convergence: vec![],
        }
    }

    #[test]
    fn cells_carry_exact_values_and_best_marks() {
        let methods = [
            method("a", 0.1, 2.0, Some(0.3)),
            method("b&c", 0.05, 8.0, None),
        ];
        let t = metrics_table(&methods, &["#111", "#222"], "");
        assert!(t.contains("<tr data-method=\"b&amp;c\">"));
        assert!(
            t.contains("<td data-key=\"relmse\" data-value=\"0.05\" class=\"best\">0.05000</td>")
        );
        assert!(t.contains("<td data-key=\"relmse\" data-value=\"0.1\">0.1000</td>"));
        assert!(t.contains("<td data-key=\"flip\" data-value=\"null\">—</td>"));
        assert!(t.contains("data-key=\"effort\" data-value=\"12.0\" data-unit=\"it\""));
        // Efficiency: a = 1/(0.1·2) = 5, b = 1/(0.05·8) = 2.5; higher wins.
        assert!(
            t.contains("<td data-key=\"efficiency\" data-value=\"5.0\" class=\"best\">5.000</td>")
        );
        assert_eq!(t.matches("<tr data-method").count(), 2);
    }

    #[test]
    fn efficiency_needs_positive_work() {
        let m = method("a", 0.0, 1.0, None).metrics;
        assert_eq!(efficiency(&m), None);
        let m = method("a", 0.5, 4.0, None).metrics;
        assert_eq!(efficiency(&m), Some(0.5));
    }
}
