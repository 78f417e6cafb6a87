//! Log–log convergence plots as inline SVG, written once when the report is made (they
//! need no script, and their numbers can be checked here).
//!
//! Monte Carlo estimators have variance ∝ 1/N, so relMSE against sample count (and,
//! at constant cost per sample, against time) falls on a line of slope −1 in log–log
//! axes; each plot marks that slope as a dashed reference line, and the legend gives each
//! method's measured slope, a least-squares fit over the later half of its snapshots
//! (early snapshots include start-up costs such as building a photon map).

use std::fmt::Write;

use crate::text::{html, significant};

/// One curve: a method's `(x, y)` points in snapshot order.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub color: &'static str,
    pub points: Vec<(f64, f64)>,
}

/// What one plot shows.
#[derive(Clone, Debug)]
pub struct PlotSpec<'a> {
    /// `id` attribute of the `<svg>` element.
    pub id: &'a str,
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    /// Slope of the dashed reference line, if any (−1 for relMSE).
    pub reference_slope: Option<f64>,
}

/// A base-10 logarithmic axis from `10^lo` to `10^hi` mapped onto pixels `p0..p1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogAxis {
    pub lo: i32,
    pub hi: i32,
    pub p0: f64,
    pub p1: f64,
}

impl LogAxis {
    /// The smallest whole-decade axis holding every value (at least one decade wide).
    pub fn covering(values: impl Iterator<Item = f64>, p0: f64, p1: f64) -> Option<LogAxis> {
        let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite() && *v > 0.0) {
            min = min.min(v);
            max = max.max(v);
        }
        if min > max {
            return None;
        }
        // A small tolerance keeps an exact power of ten (1e-3) from opening a new decade
        // through rounding in log10.
        let lo = (min.log10() + 1e-9).floor() as i32;
        let mut hi = (max.log10() - 1e-9).ceil() as i32;
        if hi <= lo {
            hi = lo + 1;
        }
        Some(LogAxis { lo, hi, p0, p1 })
    }

    /// Pixel position of `v > 0`.
    pub fn map(&self, v: f64) -> f64 {
        let t = (v.log10() - f64::from(self.lo)) / f64::from(self.hi - self.lo);
        self.p0 + t * (self.p1 - self.p0)
    }

    /// Tick values: `(value, is_major, has_label)`. Minor ticks at 2…9 × 10^k appear
    /// when the axis spans at most 5 decades; on one or two decades 2 and 5 get labels.
    pub fn ticks(&self) -> Vec<(f64, bool, bool)> {
        let span = self.hi - self.lo;
        let mut out = Vec::new();
        for k in self.lo..=self.hi {
            let decade = 10f64.powi(k);
            out.push((decade, true, true));
            if k == self.hi || span > 5 {
                continue;
            }
            for m in 2..=9 {
                let labelled = span <= 2 && (m == 2 || m == 5);
                out.push((f64::from(m) * decade, false, labelled));
            }
        }
        out
    }
}

/// Least-squares slope of `log10 y` against `log10 x` over the later half of `points`
/// (positive values only); `None` with fewer than two usable points or no spread in x.
pub fn fitted_slope(points: &[(f64, f64)]) -> Option<f64> {
    let usable: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.log10(), y.log10()))
        .collect();
    let tail = &usable[usable.len() / 2..];
    let tail = if tail.len() < 2 { &usable[..] } else { tail };
    if tail.len() < 2 {
        return None;
    }
    let n = tail.len() as f64;
    let mx = tail.iter().map(|p| p.0).sum::<f64>() / n;
    let my = tail.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = tail.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let sxy: f64 = tail.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 1e-12).then(|| sxy / sxx)
}

/// The label of a power of ten, `10^k`, with the exponent raised; other values plainly.
fn tick_label(v: f64) -> String {
    let k = v.log10().round();
    if (v - 10f64.powf(k)).abs() <= 1e-9 * v {
        let k = k as i32;
        return match k {
            0 => "1".to_string(),
            1 => "10".to_string(),
            _ => format!(
                "10<tspan dy=\"-6\" font-size=\"9\">{}</tspan>",
                k.to_string().replace('-', "−")
            ),
        };
    }
    significant(v, 1)
}

// Plot geometry, in SVG user units.
const WIDTH: f64 = 660.0;
const HEIGHT: f64 = 340.0;
const LEFT: f64 = 64.0;
const RIGHT: f64 = 440.0;
const TOP: f64 = 30.0;
const BOTTOM: f64 = 290.0;

/// The SVG of one log–log plot, indented by `indent`, or a short note when no series has
/// a positive point.
pub fn loglog_svg(spec: &PlotSpec, series: &[Series], indent: &str) -> String {
    let all = || series.iter().flat_map(|s| s.points.iter());
    let x_axis = LogAxis::covering(all().map(|p| p.0), LEFT, RIGHT);
    let y_axis = LogAxis::covering(all().map(|p| p.1), BOTTOM, TOP);
    let (Some(xa), Some(ya)) = (x_axis, y_axis) else {
        return format!(
            "{indent}<p class=\"plot-empty\">{}: no positive values to plot.</p>\n",
            html(spec.title)
        );
    };
    let mut s = String::new();
    let i1 = format!("{indent}  ");
    let _ = writeln!(
        s,
        "{indent}<svg id=\"{}\" class=\"plot\" viewBox=\"0 0 {WIDTH} {HEIGHT}\" width=\"{WIDTH}\" \
         height=\"{HEIGHT}\" role=\"img\" aria-label=\"{}\">",
        html(spec.id),
        html(spec.title)
    );
    let _ = writeln!(
        s,
        "{i1}<clipPath id=\"{}-clip\"><rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{}\" height=\"{}\"/></clipPath>",
        html(spec.id),
        RIGHT - LEFT,
        BOTTOM - TOP
    );
    let _ = writeln!(
        s,
        "{i1}<text class=\"plot-title\" x=\"{}\" y=\"18\" text-anchor=\"middle\">{}</text>",
        (LEFT + RIGHT) / 2.0,
        html(spec.title)
    );
    write_axes(&mut s, &i1, &xa, &ya, spec);

    // The reference slope goes through the first point of the first series with one,
    // across the whole plot, clipped to the axes.
    if let Some(slope) = spec.reference_slope
        && let Some(&(x0, y0)) = series
            .iter()
            .flat_map(|c| c.points.iter())
            .find(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
    {
        let (xl, xh) = (10f64.powi(xa.lo), 10f64.powi(xa.hi));
        let y_at = |x: f64| y0 * (x / x0).powf(slope);
        let _ = writeln!(
            s,
            "{i1}<g class=\"reference-slope\" clip-path=\"url(#{}-clip)\">",
            html(spec.id)
        );
        let _ = writeln!(
            s,
            "{i1}  <line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#777\" \
             stroke-dasharray=\"6 4\" stroke-width=\"1.5\"/>",
            xa.map(xl),
            ya.map(y_at(xl)),
            xa.map(xh),
            ya.map(y_at(xh))
        );
        let _ = writeln!(s, "{i1}</g>");
    }

    for c in series {
        write_series(&mut s, &i1, c, &xa, &ya, spec);
    }
    write_legend(&mut s, &i1, series, spec.reference_slope);
    let _ = writeln!(s, "{indent}</svg>");
    s
}

fn write_axes(s: &mut String, i1: &str, xa: &LogAxis, ya: &LogAxis, spec: &PlotSpec) {
    let _ = writeln!(
        s,
        "{i1}<rect class=\"plot-frame\" x=\"{LEFT}\" y=\"{TOP}\" width=\"{}\" height=\"{}\" \
         fill=\"none\" stroke=\"#333\"/>",
        RIGHT - LEFT,
        BOTTOM - TOP
    );
    let _ = writeln!(
        s,
        "{i1}<g class=\"x-ticks\" font-size=\"11\" text-anchor=\"middle\">"
    );
    for (v, major, labelled) in xa.ticks() {
        let x = xa.map(v);
        let len = if major { 6.0 } else { 3.0 };
        if major {
            let _ = writeln!(
                s,
                "{i1}  <line x1=\"{x:.1}\" y1=\"{TOP}\" x2=\"{x:.1}\" y2=\"{BOTTOM}\" stroke=\"#e4e4e4\"/>"
            );
        }
        let _ = writeln!(
            s,
            "{i1}  <line x1=\"{x:.1}\" y1=\"{BOTTOM}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#333\"/>",
            BOTTOM - len
        );
        if labelled {
            let _ = writeln!(
                s,
                "{i1}  <text x=\"{x:.1}\" y=\"{}\">{}</text>",
                BOTTOM + 16.0,
                tick_label(v)
            );
        }
    }
    let _ = writeln!(s, "{i1}</g>");
    let _ = writeln!(
        s,
        "{i1}<g class=\"y-ticks\" font-size=\"11\" text-anchor=\"end\">"
    );
    for (v, major, labelled) in ya.ticks() {
        let y = ya.map(v);
        let len = if major { 6.0 } else { 3.0 };
        if major {
            let _ = writeln!(
                s,
                "{i1}  <line x1=\"{LEFT}\" y1=\"{y:.1}\" x2=\"{RIGHT}\" y2=\"{y:.1}\" stroke=\"#e4e4e4\"/>"
            );
        }
        let _ = writeln!(
            s,
            "{i1}  <line x1=\"{LEFT}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#333\"/>",
            LEFT + len
        );
        if labelled {
            let _ = writeln!(
                s,
                "{i1}  <text x=\"{}\" y=\"{:.1}\">{}</text>",
                LEFT - 6.0,
                y + 4.0,
                tick_label(v)
            );
        }
    }
    let _ = writeln!(s, "{i1}</g>");
    let _ = writeln!(
        s,
        "{i1}<text class=\"axis-label\" x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
        (LEFT + RIGHT) / 2.0,
        HEIGHT - 14.0,
        html(spec.x_label)
    );
    let _ = writeln!(
        s,
        "{i1}<text class=\"axis-label\" transform=\"translate(16 {}) rotate(-90)\" \
         text-anchor=\"middle\">{}</text>",
        (TOP + BOTTOM) / 2.0,
        html(spec.y_label)
    );
}

fn write_series(s: &mut String, i1: &str, c: &Series, xa: &LogAxis, ya: &LogAxis, spec: &PlotSpec) {
    let pts: Vec<(f64, f64)> = c
        .points
        .iter()
        .copied()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .collect();
    let _ = writeln!(
        s,
        "{i1}<g class=\"series\" data-name=\"{}\" stroke=\"{}\" fill=\"{}\">",
        html(&c.name),
        c.color,
        c.color
    );
    if pts.len() > 1 {
        let path: Vec<String> = pts
            .iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", xa.map(x), ya.map(y)))
            .collect();
        let _ = writeln!(
            s,
            "{i1}  <polyline fill=\"none\" stroke-width=\"1.8\" points=\"{}\"/>",
            path.join(" ")
        );
    }
    for &(x, y) in &pts {
        let _ = writeln!(
            s,
            "{i1}  <circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.6\"><title>{}: {} = {}, {} = {}</title></circle>",
            xa.map(x),
            ya.map(y),
            html(&c.name),
            html(spec.x_label),
            significant(x, 4),
            html(spec.y_label),
            significant(y, 4)
        );
    }
    let _ = writeln!(s, "{i1}</g>");
}

fn write_legend(s: &mut String, i1: &str, series: &[Series], reference_slope: Option<f64>) {
    let x = RIGHT + 16.0;
    let _ = writeln!(s, "{i1}<g class=\"legend\" font-size=\"12\">");
    let mut y = TOP + 8.0;
    for c in series {
        let slope = fitted_slope(&c.points)
            .map(|k| format!(" (slope {})", significant(k, 2).replace('-', "−")))
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "{i1}  <line x1=\"{x}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"{}\" stroke-width=\"2.5\"/>",
            x + 22.0,
            c.color
        );
        let _ = writeln!(
            s,
            "{i1}  <text x=\"{}\" y=\"{}\">{}{slope}</text>",
            x + 28.0,
            y + 4.0,
            html(&c.name)
        );
        y += 20.0;
    }
    if let Some(k) = reference_slope {
        let _ = writeln!(
            s,
            "{i1}  <line x1=\"{x}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#777\" \
             stroke-dasharray=\"6 4\" stroke-width=\"1.5\"/>",
            x + 22.0
        );
        let _ = writeln!(
            s,
            "{i1}  <text class=\"reference-label\" x=\"{}\" y=\"{}\">expected slope {}</text>",
            x + 28.0,
            y + 4.0,
            significant(k, 2).replace('-', "−")
        );
    }
    let _ = writeln!(s, "{i1}</g>");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_covers_whole_decades() {
        let a = LogAxis::covering([0.002, 0.5, 3.0].into_iter(), 0.0, 300.0).unwrap();
        assert_eq!((a.lo, a.hi), (-3, 1));
        assert!((a.map(1e-3) - 0.0).abs() < 1e-9);
        assert!((a.map(10.0) - 300.0).abs() < 1e-9);
        assert!((a.map(0.1) - 150.0).abs() < 1e-9);
        // Exact powers of ten do not open an extra decade; a single value gets one decade.
        let b = LogAxis::covering([1e-3, 1.0].into_iter(), 0.0, 1.0).unwrap();
        assert_eq!((b.lo, b.hi), (-3, 0));
        let c = LogAxis::covering([5.0].into_iter(), 0.0, 1.0).unwrap();
        assert_eq!((c.lo, c.hi), (0, 1));
        // Non-positive and non-finite values are ignored.
        assert!(LogAxis::covering([0.0, -1.0, f64::NAN].into_iter(), 0.0, 1.0).is_none());
    }

    #[test]
    fn ticks_thin_out_on_wide_axes() {
        let narrow = LogAxis {
            lo: 0,
            hi: 1,
            p0: 0.0,
            p1: 1.0,
        };
        let t = narrow.ticks();
        assert_eq!(t.len(), 2 + 8);
        let labelled: Vec<f64> = t.iter().filter(|t| t.2).map(|t| t.0).collect();
        assert_eq!(labelled, vec![1.0, 2.0, 5.0, 10.0]);
        let wide = LogAxis {
            lo: -8,
            hi: 0,
            p0: 0.0,
            p1: 1.0,
        };
        assert!(wide.ticks().iter().all(|t| t.1));
        assert_eq!(wide.ticks().len(), 9);
    }

    #[test]
    fn fitted_slope_recovers_power_laws() {
        let pts: Vec<(f64, f64)> = (0..10)
            .map(|i| 2f64.powi(i))
            .map(|n| (n, 3.0 / n))
            .collect();
        assert!((fitted_slope(&pts).unwrap() + 1.0).abs() < 1e-12);
        // Only the later half counts: a bent start does not change the slope.
        let mut bent = pts.clone();
        bent[0].1 = 100.0;
        bent[1].1 = 50.0;
        assert!((fitted_slope(&bent).unwrap() + 1.0).abs() < 1e-12);
        let sppm: Vec<(f64, f64)> = pts.iter().map(|&(n, _)| (n, n.powf(-2.0 / 3.0))).collect();
        assert!((fitted_slope(&sppm).unwrap() + 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(fitted_slope(&[(1.0, 1.0)]), None);
        assert_eq!(fitted_slope(&[(1.0, 1.0), (1.0, 2.0)]), None);
    }

    #[test]
    fn svg_has_axes_legend_and_reference_line() {
        let series = vec![Series {
            name: "path <tracing>".into(),
            color: "#0072B2",
            points: (0..6).map(|i| (10f64.powi(i), 10f64.powi(-i))).collect(),
        }];
        let spec = PlotSpec {
            id: "p",
            title: "relMSE vs samples",
            x_label: "samples",
            y_label: "relMSE",
            reference_slope: Some(-1.0),
        };
        let svg = loglog_svg(&spec, &series, "");
        assert!(svg.starts_with("<svg id=\"p\""));
        assert!(svg.contains("path &lt;tracing&gt; (slope −1.0)"), "{svg}");
        assert!(svg.contains("expected slope −1.0"));
        assert_eq!(svg.matches("<circle").count(), 6);
        // The reference line goes through the first point (1, 1) with slope −1, so on these
        // square decade axes it runs corner to corner of the frame.
        let line = svg
            .lines()
            .find(|l| l.contains("stroke-dasharray"))
            .unwrap();
        assert!(
            line.contains("x1=\"64.0\" y1=\"30.0\" x2=\"440.0\" y2=\"290.0\""),
            "{line}"
        );
        let empty = loglog_svg(&spec, &[], "");
        assert!(empty.contains("no positive values"));
    }
}
