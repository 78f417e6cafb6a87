//! Lens cross-section as SVG: element outlines, the stop, the film plane and meridional ray
//! bundles from three film points (on the axis, mid-field and the edge of the lit field).
//! Light travels left to right: the scene is on the left, the film on the right.

use super::{ApertureClipping, LensRay, RealisticCamera, image_circle};
use radiant_math::{DVec2, DVec3};
use std::fmt::Write;

/// Drawing width of the optical part, in SVG user units.
const DRAWING_WIDTH: f64 = 1000.0;
const MARGIN: f64 = 40.0;
/// Points per surface outline.
const ARC_POINTS: usize = 32;
/// Rays per bundle.
const BUNDLE_RAYS: usize = 13;
const BUNDLE_COLOURS: [&str; 3] = ["#1f77b4", "#2ca02c", "#d62728"];

/// The camera's lens cross-section (x–z meridional plane) as an SVG document.
pub fn lens_svg(camera: &RealisticCamera) -> String {
    let system = camera.system();
    let interfaces = system.interfaces();
    let gap = camera.film_gap();
    let half_diagonal = 0.5 * camera.film_diagonal();
    let front = system.total_track();
    // Room in front of the lens for the outgoing rays.
    let lead_in = 0.3 * (front + gap);
    let z_left = front + lead_in;
    let scale = DRAWING_WIDTH / (z_left + gap);
    let max_radius = interfaces
        .iter()
        .map(|s| s.aperture_radius)
        .fold(half_diagonal, f64::max);
    let half_height = 1.25 * max_radius * scale;
    let width = DRAWING_WIDTH + 2.0 * MARGIN;
    let height = 2.0 * half_height + 2.0 * MARGIN + 40.0;
    let cy = MARGIN + half_height;
    let to_svg = |z: f64, x: f64| DVec2::new(MARGIN + (z_left - z) * scale, cy - x * scale);

    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.1} {height:.1}">"#
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let axis_a = to_svg(z_left, 0.0);
    let axis_b = to_svg(-gap, 0.0);
    let _ = writeln!(
        out,
        r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#888" stroke-dasharray="8 4 2 4" stroke-width="0.8"/>"##,
        axis_a.x, axis_a.y, axis_b.x, axis_b.y
    );

    // Glass elements: the region between surface i and i+1 when the medium there is not air.
    let outline = |i: usize, from: f64, to: f64| -> Vec<DVec2> {
        let s = &interfaces[i];
        (0..=ARC_POINTS)
            .map(|k| {
                let h = from + (to - from) * k as f64 / ARC_POINTS as f64;
                to_svg(s.sag_z(h.abs()), h)
            })
            .collect()
    };
    for i in 0..interfaces.len().saturating_sub(1) {
        if interfaces[i].index_film_side <= 1.0 {
            continue;
        }
        let a0 = interfaces[i].aperture_radius;
        let a1 = interfaces[i + 1].aperture_radius;
        let mut points = outline(i, a0, -a0);
        points.extend(outline(i + 1, -a1, a1));
        let _ = writeln!(
            out,
            r##"<polygon points="{}" fill="#cfe3f5" stroke="#234" stroke-width="1.2"/>"##,
            polyline_points(&points)
        );
    }
    // Curved surfaces with air on both sides would otherwise be invisible.
    for (i, s) in interfaces.iter().enumerate() {
        if s.radius != 0.0 && s.index_film_side <= 1.0 && s.index_scene_side <= 1.0 {
            let points = outline(i, s.aperture_radius, -s.aperture_radius);
            let _ = writeln!(
                out,
                r##"<polyline points="{}" fill="none" stroke="#234" stroke-width="1.2"/>"##,
                polyline_points(&points)
            );
        }
    }
    // Flat apertures (the stop drawn heavier): blades from the rim outwards.
    let blade = 0.15 * max_radius;
    for (i, s) in interfaces.iter().enumerate() {
        if s.radius != 0.0 {
            continue;
        }
        let stroke = if i == system.stop_index() { 3.0 } else { 1.5 };
        for sign in [1.0, -1.0] {
            let a = to_svg(s.vertex_z, sign * s.aperture_radius);
            let b = to_svg(s.vertex_z, sign * (s.aperture_radius + blade));
            let _ = writeln!(
                out,
                r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="black" stroke-width="{stroke}"/>"##,
                a.x, a.y, b.x, b.y
            );
        }
    }
    // Film plane.
    let film_a = to_svg(-gap, half_diagonal);
    let film_b = to_svg(-gap, -half_diagonal);
    let _ = writeln!(
        out,
        r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#444" stroke-width="2.5"/>"##,
        film_a.x, film_a.y, film_b.x, film_b.y
    );
    let _ = writeln!(
        out,
        r#"<text x="{:.2}" y="{:.2}" font-family="sans-serif" font-size="12" text-anchor="middle">film</text>"#,
        film_a.x,
        film_a.y - 6.0
    );

    // Ray bundles from film points below the axis (so the bundles rise towards the scene for an
    // inverting lens), through the exit-pupil rectangle's meridional line.
    let pupil = camera.exit_pupil();
    // The edge of the field: the film corner, or the image circle when the corner lies outside.
    let lit_edge = image_circle(system, gap, half_diagonal).map_or(0.0, |c| c.film_radius);
    let field_radii = [0.0, 0.5 * lit_edge, lit_edge];
    for (radius, colour) in field_radii.iter().zip(BUNDLE_COLOURS) {
        let film = DVec2::new(-radius, 0.0);
        for k in 0..BUNDLE_RAYS {
            let u = DVec2::new((k as f64 + 0.5) / BUNDLE_RAYS as f64, 0.5);
            let Some((rear, _)) = pupil.sample(film, u) else {
                continue;
            };
            let origin = DVec3::new(film.x, 0.0, -gap);
            let dir = (DVec3::new(rear.x, rear.y, 0.0) - origin).normalize();
            let mut path = vec![to_svg(origin.z, origin.x)];
            let traced = system.trace_to_scene_recording(
                LensRay { origin, dir },
                ApertureClipping::Clip,
                0,
                |p| path.push(to_svg(p.z, p.x)),
            );
            let style = match traced {
                Ok(out_ray) => {
                    // Continue to the left edge of the drawing.
                    if out_ray.dir.z > 0.0 {
                        let t = (z_left - out_ray.origin.z) / out_ray.dir.z;
                        let end = out_ray.origin + t * out_ray.dir;
                        path.push(to_svg(end.z, end.x));
                    }
                    format!(r#"stroke="{colour}" stroke-width="0.9" stroke-opacity="0.85""#)
                }
                Err(_) => format!(
                    r#"stroke="{colour}" stroke-width="0.6" stroke-opacity="0.35" stroke-dasharray="3 3""#
                ),
            };
            let _ = writeln!(
                out,
                r#"<polyline points="{}" fill="none" {style}/>"#,
                polyline_points(&path)
            );
        }
    }

    let p = camera.paraxial();
    let focus = camera.focus_distance();
    let focus_text = if focus.is_infinite() {
        "infinity".to_string()
    } else {
        format!("{focus} m")
    };
    let _ = writeln!(
        out,
        r#"<text x="{MARGIN}" y="{:.1}" font-family="sans-serif" font-size="13">{}: EFL {:.2} mm, f/{:.2}, focus {focus_text}, film gap {:.3} mm; bundles at film radius 0, {:.2}, {:.2} mm</text>"#,
        height - 14.0,
        xml_escape(&system.name),
        p.efl,
        p.f_number,
        gap,
        field_radii[1],
        field_radii[2]
    );
    out.push_str("</svg>\n");
    out
}

fn polyline_points(points: &[DVec2]) -> String {
    let mut s = String::with_capacity(points.len() * 16);
    for p in points {
        let _ = write!(s, "{:.2},{:.2} ", p.x, p.y);
    }
    s.trim_end().to_string()
}

fn xml_escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
