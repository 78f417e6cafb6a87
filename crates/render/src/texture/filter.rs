//! Reading a MIP pyramid over a footprint: nearest texel, bilinear interpolation,
//! trilinear interpolation between the two levels whose texels match the footprint's
//! widest extent (Williams 1983), and the elliptical weighted average of Greene &
//! Heckbert (1986; Heckbert 1989, §3.5.8): a Gaussian over the ellipse the pixel maps
//! to, read from the level where the ellipse's minor axis spans about one texel.
//!
//! Coordinates: (s, t) ∈ [0, 1]² spans the image, t = 0 at its top row; texel (x, y)
//! has its centre at ((x + ½)/w, (y + ½)/h). Footprints are the derivatives of (s, t)
//! across one pixel.

use glam::Vec2;
use radiant_math::color::Rgb;
use radiant_scene::{ImageFilter, WrapMode};

use super::image::{Level, MipMap};

/// A lookup's footprint: (ds/dx, dt/dx) and (ds/dy, dt/dy).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub dst0: Vec2,
    pub dst1: Vec2,
}

/// Gaussian falloff of the EWA filter, exp(−α r²) on the unit ellipse (α = 2, as
/// Heckbert suggests: the weight at the ellipse's edge is small but not negligible).
const EWA_ALPHA: f32 = 2.0;

pub fn nearest(level: &Level, st: Vec2, wrap: WrapMode) -> Rgb {
    let x = (st.x * level.width as f32).floor() as i64;
    let y = (st.y * level.height as f32).floor() as i64;
    level.texel(x, y, wrap)
}

pub fn bilinear(level: &Level, st: Vec2, wrap: WrapMode) -> Rgb {
    let x = st.x * level.width as f32 - 0.5;
    let y = st.y * level.height as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let [t00, t10, t01, t11] = level.quad(x0, y0, wrap);
    (t00 * (1.0 - fx) + t10 * fx) * (1.0 - fy) + (t01 * (1.0 - fx) + t11 * fx) * fy
}

/// The continuous pyramid level where a footprint `width` (in st units) covers one
/// texel; 0 is the full image.
fn level_for(mip: &MipMap, width: f32) -> f32 {
    let res = mip.width().max(mip.height()) as f32;
    let top = (mip.levels.len() - 1) as f32;
    (width * res).max(1e-12).log2().clamp(0.0, top)
}

fn between_levels(mip: &MipMap, level: f32, f: impl Fn(&Level) -> Rgb) -> Rgb {
    let i = level.floor() as usize;
    let frac = level - i as f32;
    let a = f(&mip.levels[i]);
    if frac == 0.0 || i + 1 >= mip.levels.len() {
        return a;
    }
    a * (1.0 - frac) + f(&mip.levels[i + 1]) * frac
}

pub fn trilinear(mip: &MipMap, st: Vec2, fp: Footprint, wrap: WrapMode) -> Rgb {
    let width = 2.0
        * fp.dst0
            .x
            .abs()
            .max(fp.dst0.y.abs())
            .max(fp.dst1.x.abs())
            .max(fp.dst1.y.abs());
    let level = level_for(mip, width);
    between_levels(mip, level, |l| bilinear(l, st, wrap))
}

pub fn ewa(mip: &MipMap, st: Vec2, fp: Footprint, max_anisotropy: f32, wrap: WrapMode) -> Rgb {
    let (mut major, mut minor) = (fp.dst0, fp.dst1);
    if major.length_squared() < minor.length_squared() {
        std::mem::swap(&mut major, &mut minor);
    }
    let major_len = major.length();
    let mut minor_len = minor.length();
    if !(major_len.is_finite() && minor_len.is_finite()) {
        return bilinear(&mip.levels[0], st, wrap);
    }
    // Too eccentric an ellipse would sum too many texels: widen its minor axis (the
    // result blurs along it rather than costing without bound).
    if minor_len * max_anisotropy < major_len && minor_len > 0.0 {
        let grow = major_len / (minor_len * max_anisotropy);
        minor *= grow;
        minor_len *= grow;
    }
    if minor_len == 0.0 {
        return bilinear(&mip.levels[0], st, wrap);
    }
    let level = level_for(mip, minor_len);
    between_levels(mip, level, |l| ewa_level(l, st, major, minor, wrap))
}

/// The Gaussian-weighted average over the ellipse with conjugate semi-axes `a`, `b`
/// (st units) about `st`, on one level. The ellipse is the set of texel offsets d with
/// dᵀ Q d ≤ 1, Q from the footprint's Jacobian; adding one texel's width to it (the
/// "+1" terms) keeps a minimum footprint of one texel (Heckbert 1989).
fn ewa_level(level: &Level, st: Vec2, a: Vec2, b: Vec2, wrap: WrapMode) -> Rgb {
    let res = Vec2::new(level.width as f32, level.height as f32);
    let c = st * res - 0.5;
    let (a, b) = (a * res, b * res);
    let qa = a.y * a.y + b.y * b.y + 1.0;
    let qb = -2.0 * (a.x * a.y + b.x * b.y);
    let qc = a.x * a.x + b.x * b.x + 1.0;
    let f = qa * qc - 0.25 * qb * qb;
    let (qa, qb, qc) = (qa / f, qb / f, qc / f);
    let det = 4.0 * qa * qc - qb * qb;
    if !(det > 0.0 && det.is_finite()) {
        return bilinear(level, st, wrap);
    }
    // Bounding box of Ax² + Bxy + Cy² = 1.
    let half_x = (4.0 * qc / det).sqrt();
    let half_y = (4.0 * qa / det).sqrt();
    let (x0, x1) = ((c.x - half_x).ceil() as i64, (c.x + half_x).floor() as i64);
    let (y0, y1) = ((c.y - half_y).ceil() as i64, (c.y + half_y).floor() as i64);
    let edge = (-EWA_ALPHA).exp();
    let mut sum = Rgb::BLACK;
    let mut weight = 0.0f32;
    for y in y0..=y1 {
        let dy = y as f32 - c.y;
        for x in x0..=x1 {
            let dx = x as f32 - c.x;
            let r2 = qa * dx * dx + qb * dx * dy + qc * dy * dy;
            if r2 < 1.0 {
                let w = (-EWA_ALPHA * r2).exp() - edge;
                sum += level.texel(x, y, wrap) * w;
                weight += w;
            }
        }
    }
    if weight > 0.0 {
        sum / weight
    } else {
        bilinear(level, st, wrap)
    }
}

/// One lookup with the texture's filter.
pub fn lookup(
    mip: &MipMap,
    filter: ImageFilter,
    st: Vec2,
    fp: Footprint,
    max_anisotropy: f32,
    wrap: WrapMode,
) -> Rgb {
    match filter {
        ImageFilter::Point => nearest(&mip.levels[0], st, wrap),
        ImageFilter::Bilinear => bilinear(&mip.levels[0], st, wrap),
        ImageFilter::Trilinear => trilinear(mip, st, fp, wrap),
        ImageFilter::Ewa => ewa(mip, st, fp, max_anisotropy, wrap),
    }
}
