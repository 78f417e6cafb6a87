//! The text report printed by `radiant lens`.

use super::{MM_PER_SCENE_UNIT, RealisticCamera, ThickLens, chief_ray, image_circle};
use std::fmt::Write;
use std::time::Duration;

/// A human-readable summary of the camera's lens: paraxial data, thick lens, focus, field of view
/// and exit-pupil statistics. `pupil_time` is the measured exit-pupil precomputation time, if any.
pub fn lens_report(camera: &RealisticCamera, pupil_time: Option<Duration>) -> String {
    let mut out = String::new();
    // Writing into a String cannot fail.
    let _ = write_report(&mut out, camera, pupil_time);
    out
}

fn write_report(
    out: &mut String,
    camera: &RealisticCamera,
    pupil_time: Option<Duration>,
) -> std::fmt::Result {
    let system = camera.system();
    let p = camera.paraxial();
    writeln!(
        out,
        "lens {}: {} surfaces, aperture stop at surface {} ({} mm, file: {} mm)",
        system.name,
        system.interfaces().len(),
        p.stop_index,
        fmt_num(p.stop_diameter),
        fmt_num(system.file_stop_diameter())
    )?;
    for w in camera.warnings() {
        writeln!(out, "warning: {w}")?;
    }
    writeln!(
        out,
        "paraxial (z from the front vertex, + towards the film; mm)"
    )?;
    writeln!(out, "  effective focal length   EFL = {:.6}", p.efl)?;
    writeln!(out, "  back focal distance      BFD = {:.6}", p.bfd)?;
    writeln!(out, "  front focal distance     FFD = {:.6}", p.ffd)?;
    writeln!(
        out,
        "  principal planes         H at z = {:.6}, H' at z = {:.6}",
        p.h1_z, p.h2_z
    )?;
    writeln!(out, "  total track                    {:.6}", p.total_track)?;
    writeln!(
        out,
        "  entrance pupil           z = {:.6}, diameter {:.6}",
        p.entrance_pupil_z, p.entrance_pupil_diameter
    )?;
    writeln!(
        out,
        "  exit pupil               {:.6} from the rear vertex, diameter {:.6}",
        p.exit_pupil_from_rear, p.exit_pupil_diameter
    )?;
    writeln!(
        out,
        "  paraxial f-number        f/{:.4} (EFL / entrance pupil); f/{:.4} with every rim (limited by surface {})",
        p.f_number, p.f_number_limited, p.axial_limiting_surface
    )?;

    let height = 0.001 * camera.film_diagonal();
    if let Ok(t) = ThickLens::from_traced_rays(system, height) {
        writeln!(
            out,
            "thick lens from exact rays at {height} mm (from the rear vertex, + towards the film; mm)"
        )?;
        writeln!(
            out,
            "  f = {:.6}, H' = {:.6}, F' = {:.6}, H = {:.6}, F = {:.6}",
            t.focal_length(),
            t.image_principal,
            t.image_focal,
            t.object_principal,
            t.object_focal
        )?;
        writeln!(
            out,
            "  closest focus {:.4} m from the film",
            t.closest_focus_mm() / MM_PER_SCENE_UNIT
        )?;
    }

    let size = camera.film_size();
    let (w, h) = camera.resolution();
    writeln!(
        out,
        "film {} mm diagonal ({:.3} x {:.3} mm, {w}x{h} pixels)",
        fmt_num(camera.film_diagonal()),
        size.x,
        size.y
    )?;
    let focus = camera.focus_distance();
    let focus_text = if focus.is_infinite() {
        "infinity".to_string()
    } else {
        format!("{} m", fmt_num(focus))
    };
    writeln!(
        out,
        "  focus at {focus_text}: film {:.6} mm behind the rear vertex",
        camera.film_gap()
    )?;

    let half_diagonal = 0.5 * camera.film_diagonal();
    match chief_ray(system, camera.film_gap(), half_diagonal) {
        Some(c) => writeln!(
            out,
            "  field of view on the diagonal {:.3} deg (chief ray at the corner {:.3} deg{})",
            2.0 * c.field_angle.to_degrees(),
            c.field_angle.to_degrees(),
            if c.vignetted {
                ", clipped by a rim"
            } else {
                ""
            }
        )?,
        None => writeln!(
            out,
            "  no chief ray reaches the film corners ({half_diagonal} mm from the centre)"
        )?,
    }
    if let Some(circle) = image_circle(system, camera.film_gap(), half_diagonal)
        && circle.film_radius < half_diagonal
    {
        writeln!(
            out,
            "  image circle (chief ray clear of every rim) radius {:.3} mm at {:.3} deg: field of view {:.3} deg across it",
            circle.film_radius,
            circle.field_angle.to_degrees(),
            2.0 * circle.field_angle.to_degrees()
        )?;
    }

    let buckets = camera.exit_pupil().buckets();
    let lit = buckets.iter().filter(|b| b.is_some()).count();
    write!(
        out,
        "exit-pupil bounds: {} radial buckets, {lit} with light",
        buckets.len()
    )?;
    match pupil_time {
        Some(t) => writeln!(out, ", precomputed in {:.1} ms", t.as_secs_f64() * 1e3)?,
        None => writeln!(out)?,
    }
    let e0 = mean_weight_at_film_radius(camera, 0.0);
    writeln!(
        out,
        "  axial irradiance for unit radiance (mean ray weight, pbrt convention) {e0:.5}; pi/(4N^2) = {:.5}",
        std::f64::consts::PI / (4.0 * p.f_number * p.f_number)
    )?;
    write!(
        out,
        "  relative illumination E(r)/E(0) along the film x axis:"
    )?;
    let half_width = 0.5 * size.x;
    for k in 1..=4 {
        let r = half_width * k as f64 / 4.0;
        let e = mean_weight_at_film_radius(camera, r);
        write!(
            out,
            "  {r:.2} mm: {:.4}",
            if e0 > 0.0 { e / e0 } else { 0.0 }
        )?;
    }
    writeln!(out)?;
    if let Some(Some(axial)) = buckets.first() {
        writeln!(
            out,
            "  on the axis: x in [{:.4}, {:.4}] mm, |y| <= {:.4} mm on the rear vertex plane",
            axial.x_min, axial.x_max, axial.y_max
        )?;
    }
    Ok(())
}

/// Shortest decimal that reads back as the same number (e.g. "17.1", "10").
fn fmt_num(v: f64) -> String {
    format!("{v}")
}

/// Lens-sample strata per side for the illumination table.
const ILLUMINATION_STRATA: usize = 48;

/// Mean camera-ray weight (blocked rays count 0) at film radius `r` mm along the +x film axis:
/// the film irradiance for a unit-radiance sky, E(r).
pub(super) fn mean_weight_at_film_radius(camera: &RealisticCamera, r: f64) -> f64 {
    let (w, h) = camera.resolution();
    let size = camera.film_size();
    // Film point (r, 0) in lens space is raster-left of the centre (the image is inverted).
    let raster = radiant_math::Vec2::new((0.5 - r / size.x) as f32 * w as f32, 0.5 * h as f32);
    let n = ILLUMINATION_STRATA;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let u =
                radiant_math::Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            if let Some(s) = camera.generate_ray(raster, u) {
                sum += s.weight as f64;
            }
        }
    }
    sum / (n * n) as f64
}
