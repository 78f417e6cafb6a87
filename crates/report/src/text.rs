//! Escaping and number formatting for the generated HTML, SVG and JSON.

use std::fmt::Write;

/// `s` with the five HTML-special characters escaped; safe in text and quoted attributes.
pub fn html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// `s` as a JSON string literal. `<`, `>` and `&` are written as `\u` escapes so the
/// literal can sit inside a `<script>` element without ever closing it.
pub fn json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '<' | '>' | '&' | '\u{2028}' | '\u{2029}' => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `x` as a JSON number: the shortest decimal that parses back to the same f64
/// (Rust's `Debug` form, e.g. `0.1`, `1e-7`, `3.0`); `null` when not finite.
pub fn json_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else {
        "null".to_string()
    }
}

/// `x` rounded to `digits` significant digits for display, switching to scientific
/// notation (`1.234e-5`) outside [1e-3, 1e6). Non-finite values print as words.
pub fn significant(x: f64, digits: usize) -> String {
    if x.is_nan() {
        return "NaN".to_string();
    }
    if x.is_infinite() {
        return if x > 0.0 { "∞" } else { "−∞" }.to_string();
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let digits = digits.max(1);
    let magnitude = x.abs();
    if !(1e-3..1e6).contains(&magnitude) {
        return format!("{:.*e}", digits - 1, x);
    }
    let exponent = magnitude.log10().floor() as i32;
    let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
    let s = format!("{x:.decimals$}");
    // Rounding may carry into a new digit (9.9996 → "10.000"): redo with one decimal fewer.
    let carried = s
        .parse::<f64>()
        .is_ok_and(|r| r.abs() >= 10f64.powi(exponent + 1));
    if decimals > 0 && carried {
        return format!("{x:.*}", decimals - 1);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn html_escapes_markup() {
        assert_eq!(
            html(r#"<a href="x">&'</a>"#),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;"
        );
    }

    #[test]
    fn json_string_cannot_close_a_script() {
        let s = json_string("</script>\"\\\n\u{1}ꟻ");
        assert_eq!(s, r#""\u003c/script\u003e\"\\\n\u0001ꟻ""#);
    }

    #[test]
    fn json_numbers_round_trip() {
        for x in [0.1, 1e-7, 3.0, -2.5e300, 123456789.125, f64::MIN_POSITIVE] {
            let s = json_number(x);
            assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
        }
        assert_eq!(json_number(f64::NAN), "null");
        assert_eq!(json_number(f64::INFINITY), "null");
    }

    #[test]
    fn significant_digits() {
        assert_eq!(significant(0.0123456, 4), "0.01235");
        assert_eq!(significant(1234.5678, 4), "1235");
        assert_eq!(significant(9.99996, 4), "10.00");
        assert_eq!(significant(0.101856, 4), "0.1019");
        assert_eq!(significant(0.099996, 3), "0.100");
        assert_eq!(significant(-0.5, 3), "-0.500");
        assert_eq!(significant(1.5e-5, 3), "1.50e-5");
        assert_eq!(significant(2.0e7, 2), "2.0e7");
        assert_eq!(significant(0.0, 4), "0");
        assert_eq!(significant(f64::NAN, 4), "NaN");
    }
}
