//! Exit-pupil bounds: for film points in radial buckets, a rectangle on the rear vertex plane
//! that contains every point through which a ray from the film can pass the whole lens. The camera
//! samples inside it (rotated to the film point's azimuth), so tighter bounds mean fewer wasted
//! rays, and bounds that miss part of the region would lose light. The idea of restricting the
//! lens samples per film radius is Kolb et al.'s (1995, section 4); the search is our own:
//!
//! 1. a hard candidate box from the rear element alone (rays must cross its cap inside its
//!    aperture, so their rear-plane crossings lie between two similar projections of that disc);
//! 2. a coarse grid over the half box y ≥ 0 (the region of a film point on +x is symmetric in y)
//!    for a few film radii across the bucket;
//! 3. each of the three extremes (x_min, x_max, y_max) refined by bisection on the grid lines
//!    next to the extreme, then by a golden-section search between those lines for the maximum
//!    of the boundary curve;
//! 4. padding for the film radii between the samples (half the largest change between
//!    neighbouring samples, or a film-sample step where the region vanishes).
//!
//! About 5·10⁵ exact traces per lens (0.15–0.25 s on two busy cores), where densely sampling
//! every bucket (e.g. 1024² rear-plane points × 64 buckets) takes ~7·10⁷.

use super::{ApertureClipping, LensError, LensRay, LensSystem};
use radiant_math::{DVec2, DVec3};
use rayon::prelude::*;

/// Rectangle on the rear vertex plane for film points on the +x axis: x in [x_min, x_max],
/// y in [−y_max, y_max] (mm, lens space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PupilRect {
    /// Lower x bound.
    pub x_min: f64,
    /// Upper x bound.
    pub x_max: f64,
    /// Half-height: y lies in [−y_max, y_max].
    pub y_max: f64,
}

impl PupilRect {
    /// Area in mm².
    pub fn area(&self) -> f64 {
        (self.x_max - self.x_min) * 2.0 * self.y_max
    }

    /// Whether (x, y) lies inside (for film points on +x).
    pub fn contains(&self, p: DVec2) -> bool {
        p.x >= self.x_min && p.x <= self.x_max && p.y.abs() <= self.y_max
    }
}

/// Exit-pupil bounds per radial film bucket, for one lens, stop and film distance.
#[derive(Clone, Debug)]
pub struct ExitPupilBounds {
    film_half_diagonal: f64,
    buckets: Vec<Option<PupilRect>>,
}

/// Film radii sampled across each bucket.
const FILM_SAMPLES: usize = 4;
/// Coarse grid intervals across the candidate box (x) and its upper half (y).
const GRID_X: usize = 48;
const GRID_Y: usize = 24;
/// Bisection steps on a grid interval: 2⁻¹² of a cell (~1e-4 mm); bisection reports the failing
/// end, so its residual only loosens the bound.
const BISECTION_STEPS: usize = 12;
/// Golden-section steps between grid lines: the bracket shrinks to 0.618¹⁰ ≈ 0.8 % of two cells.
/// The search can undershoot a corner of the boundary by its slope times the final bracket, so
/// that bracket width (slope ≤ 1) is added to the result.
const GOLDEN_STEPS: usize = 10;

impl ExitPupilBounds {
    /// The number of radial buckets the camera uses.
    pub const DEFAULT_BUCKETS: usize = 64;

    /// Computes bounds for film points up to `film_half_diagonal` mm from the axis, with the
    /// film `film_gap` mm behind the rear vertex.
    pub fn compute(
        system: &LensSystem,
        film_gap: f64,
        film_half_diagonal: f64,
        buckets: usize,
    ) -> Result<ExitPupilBounds, LensError> {
        let rear = system.rear();
        let rim_z = rear.sag_z(rear.aperture_radius);
        let clearance = film_gap + rim_z.min(0.0);
        if clearance.is_nan() || clearance <= 0.0 {
            return Err(LensError::InvalidParameter(format!(
                "{}: the film ({film_gap} mm behind the rear vertex) cuts through the rear element",
                system.name
            )));
        }
        if film_half_diagonal.is_nan() || film_half_diagonal <= 0.0 || buckets == 0 {
            return Err(LensError::InvalidParameter(format!(
                "exit pupil needs a positive film size and bucket count (got {film_half_diagonal} mm, {buckets})"
            )));
        }
        let buckets = (0..buckets)
            .into_par_iter()
            .map(|b| {
                let r0 = film_half_diagonal * b as f64 / buckets as f64;
                let r1 = film_half_diagonal * (b + 1) as f64 / buckets as f64;
                bucket_bounds(system, film_gap, r0, r1)
            })
            .collect();
        Ok(ExitPupilBounds {
            film_half_diagonal,
            buckets,
        })
    }

    /// Bounds per bucket, from the axis outwards (None: no light reaches those film radii).
    pub fn buckets(&self) -> &[Option<PupilRect>] {
        &self.buckets
    }

    /// The bucket rectangle covering film radius `r` (mm).
    pub fn rect_for_radius(&self, r: f64) -> Option<PupilRect> {
        let n = self.buckets.len();
        let index = ((r / self.film_half_diagonal) * n as f64).max(0.0) as usize;
        self.buckets[index.min(n - 1)]
    }

    /// A point on the rear vertex plane for film point `film` (mm, lens-space xy), uniform in its
    /// bucket's rectangle rotated to the film point's azimuth, with its area density (1/mm²).
    pub fn sample(&self, film: DVec2, u: DVec2) -> Option<(DVec2, f64)> {
        let r = film.length();
        let rect = self.rect_for_radius(r)?;
        let x = rect.x_min + u.x * (rect.x_max - rect.x_min);
        let y = (2.0 * u.y - 1.0) * rect.y_max;
        let (sin, cos) = if r > 0.0 {
            (film.y / r, film.x / r)
        } else {
            (0.0, 1.0)
        };
        Some((
            DVec2::new(cos * x - sin * y, sin * x + cos * y),
            1.0 / rect.area(),
        ))
    }
}

/// The three extremes, each expressed as a maximum of a coordinate s over the region.
#[derive(Clone, Copy)]
enum Side {
    /// s = x
    XMax,
    /// s = −x
    XMin,
    /// s = y
    YMax,
}

const SIDES: [Side; 3] = [Side::XMax, Side::XMin, Side::YMax];

/// The coarse grid for one film radius: node (ix, iy) at (x_lo + ix·hx, iy·hy).
struct Grid {
    x_lo: f64,
    x_hi: f64,
    hx: f64,
    hy: f64,
    pass: Vec<bool>,
}

impl Grid {
    fn pass(&self, ix: usize, iy: usize) -> bool {
        self.pass[iy * (GRID_X + 1) + ix]
    }
}

/// A side seen as "maximise s along lines of constant t".
struct SideView<'a> {
    side: Side,
    grid: &'a Grid,
    s0: f64,
    hs: f64,
    ns: usize,
    t0: f64,
    ht: f64,
    nt: usize,
}

impl SideView<'_> {
    fn new(side: Side, grid: &Grid) -> SideView<'_> {
        let (s0, hs, ns, t0, ht, nt) = match side {
            Side::XMax => (grid.x_lo, grid.hx, GRID_X, 0.0, grid.hy, GRID_Y),
            Side::XMin => (-grid.x_hi, grid.hx, GRID_X, 0.0, grid.hy, GRID_Y),
            Side::YMax => (0.0, grid.hy, GRID_Y, grid.x_lo, grid.hx, GRID_X),
        };
        SideView {
            side,
            grid,
            s0,
            hs,
            ns,
            t0,
            ht,
            nt,
        }
    }

    fn s(&self, i: usize) -> f64 {
        self.s0 + i as f64 * self.hs
    }

    fn t(&self, j: usize) -> f64 {
        self.t0 + j as f64 * self.ht
    }

    fn s_max(&self) -> f64 {
        self.s(self.ns)
    }

    fn pass(&self, i: usize, j: usize) -> bool {
        match self.side {
            Side::XMax => self.grid.pass(i, j),
            Side::XMin => self.grid.pass(GRID_X - i, j),
            Side::YMax => self.grid.pass(j, i),
        }
    }

    fn xy(&self, s: f64, t: f64) -> (f64, f64) {
        match self.side {
            Side::XMax => (s, t),
            Side::XMin => (-s, t),
            Side::YMax => (t, s),
        }
    }
}

/// Bounds for film radii in [r0, r1].
fn bucket_bounds(system: &LensSystem, film_gap: f64, r0: f64, r1: f64) -> Option<PupilRect> {
    let (x_lo, x_hi, y_hi) = candidate_box(system, film_gap, r0, r1);
    let mut grid = Grid {
        x_lo,
        x_hi,
        hx: (x_hi - x_lo) / GRID_X as f64,
        hy: y_hi / GRID_Y as f64,
        pass: vec![false; (GRID_X + 1) * (GRID_Y + 1)],
    };
    // Per film sample: the refined (x_max, −x_min, y_max), or None when no light passes.
    let mut extremes = [None::<[f64; 3]>; FILM_SAMPLES];
    let dr = (r1 - r0) / (FILM_SAMPLES - 1) as f64;
    for (k, slot) in extremes.iter_mut().enumerate() {
        let r = r0 + k as f64 * dr;
        let passes = |x: f64, y: f64| passes_lens(system, film_gap, r, x, y);
        let mut any = false;
        for iy in 0..=GRID_Y {
            for ix in 0..=GRID_X {
                let p = passes(x_lo + ix as f64 * grid.hx, iy as f64 * grid.hy);
                grid.pass[iy * (GRID_X + 1) + ix] = p;
                any |= p;
            }
        }
        if any {
            *slot = Some(SIDES.map(|side| side_extreme(&SideView::new(side, &grid), &passes)));
        }
    }
    let mut bound = [0.0f64; 3];
    for (side_index, side_bound) in bound.iter_mut().enumerate() {
        let values = extremes.map(|e| e.map(|e| e[side_index]));
        let max = values
            .iter()
            .flatten()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        if max == f64::NEG_INFINITY {
            return None;
        }
        // Padding for the film radii between samples: the rear-plane region moves smoothly with
        // the film point, so half the largest change between neighbours covers the bulge of the
        // extreme between them; where the region vanishes between two samples, one film step
        // (the region moves by less than the film point when the exit pupil is in front of the
        // rear plane) covers its last appearance.
        let mut pad = 0.0f64;
        for pair in values.windows(2) {
            pad = match (pair[0], pair[1]) {
                (Some(a), Some(b)) => pad.max(0.5 * (a - b).abs()),
                (Some(_), None) | (None, Some(_)) => pad.max(dr),
                (None, None) => pad,
            };
        }
        *side_bound = max + pad;
    }
    let rect = PupilRect {
        x_max: bound[0].min(x_hi),
        x_min: (-bound[1]).max(x_lo),
        y_max: bound[2].min(y_hi),
    };
    (rect.area() > 0.0).then_some(rect)
}

/// A hard bound from the rear element: a passing ray from film point (r, 0, −g) crosses the rear
/// cap at P with |P_xy| ≤ a and z_P between the vertex and the rim, so its rear-plane crossing is
/// F + k(P − F) with k = g/(g + z_P). Returns (x_lo, x_hi, y_hi) over r in [r0, r1].
fn candidate_box(system: &LensSystem, film_gap: f64, r0: f64, r1: f64) -> (f64, f64, f64) {
    let rear = system.rear();
    let a = rear.aperture_radius;
    let rim_z = rear.sag_z(a);
    let k_min = film_gap / (film_gap + rim_z.max(0.0));
    let k_max = film_gap / (film_gap + rim_z.min(0.0));
    let mut x_lo = f64::INFINITY;
    let mut x_hi = f64::NEG_INFINITY;
    for r in [r0, r1] {
        for k in [k_min, k_max] {
            x_lo = x_lo.min(r - k * (a + r));
            x_hi = x_hi.max(r + k * (a - r));
        }
    }
    // A hair of slack so the box edge itself never passes through round-off.
    let slack = 1e-9 * (a + r1);
    (x_lo - slack, x_hi + slack, k_max * a + slack)
}

/// Whether the ray from film point (r, 0, −g) through (x, y) on the rear vertex plane passes.
fn passes_lens(system: &LensSystem, film_gap: f64, r: f64, x: f64, y: f64) -> bool {
    let origin = DVec3::new(r, 0.0, -film_gap);
    let dir = (DVec3::new(x, y, 0.0) - origin).normalize();
    system
        .trace_to_scene(LensRay { origin, dir }, ApertureClipping::Clip)
        .is_ok()
}

/// The maximum of s over the passing region, refined from the grid (see the module comment).
fn side_extreme(view: &SideView, passes: &impl Fn(f64, f64) -> bool) -> f64 {
    let pass_st = |s: f64, t: f64| {
        let (x, y) = view.xy(s, t);
        passes(x, y)
    };
    // Outermost passing node on every grid line of constant t.
    let outermost = |j: usize| (0..=view.ns).rev().find(|&i| view.pass(i, j));
    let global = (0..=view.nt).filter_map(outermost).max().unwrap_or(0);

    // Lines whose outermost node is within one cell of the global one can hold the extreme.
    let mut best = f64::NEG_INFINITY;
    let mut best_line = 0;
    let mut best_node = global;
    for j in 0..=view.nt {
        let Some(i) = outermost(j) else { continue };
        if i + 1 < global {
            continue;
        }
        if i == view.ns {
            return view.s_max();
        }
        let b = bisect_boundary(view.s(i), view.s(i + 1), view.t(j), &pass_st);
        if b > best {
            (best, best_line, best_node) = (b, j, i);
        }
    }

    // Boundary position on an arbitrary line t: walk out from one cell inside the best line's
    // node until failing, then bisect.
    let start = view.s(best_node) - view.hs;
    let boundary_at = |t: f64| -> f64 {
        if !pass_st(start, t) {
            return f64::NEG_INFINITY;
        }
        let mut inside = start;
        loop {
            let outside = inside + view.hs;
            if outside >= view.s_max() {
                return view.s_max();
            }
            if !pass_st(outside, t) {
                return bisect_boundary(inside, outside, t, &pass_st);
            }
            inside = outside;
        }
    };
    let t_a = view.t(best_line.saturating_sub(1));
    let t_b = view.t((best_line + 1).min(view.nt));
    let final_bracket = (t_b - t_a) * GOLDEN_SHRINK.powi(GOLDEN_STEPS as i32);
    best.max(golden_max(t_a, t_b, &boundary_at)) + final_bracket
}

/// Largest s in [inside, outside] that passes on line t (inside passes, outside does not).
fn bisect_boundary(
    mut inside: f64,
    mut outside: f64,
    t: f64,
    pass_st: &impl Fn(f64, f64) -> bool,
) -> f64 {
    for _ in 0..BISECTION_STEPS {
        let m = 0.5 * (inside + outside);
        if pass_st(m, t) {
            inside = m;
        } else {
            outside = m;
        }
    }
    // Report the failing end: a conservative bound.
    outside
}

/// 1/φ: the factor by which each golden-section step shrinks the bracket.
const GOLDEN_SHRINK: f64 = 0.618_033_988_749_894_9;

/// Golden-section search for the maximum of `f` on [a, b]; returns the best value seen.
fn golden_max(mut a: f64, mut b: f64, f: &impl Fn(f64) -> f64) -> f64 {
    let inv_phi = GOLDEN_SHRINK;
    let mut c = b - inv_phi * (b - a);
    let mut d = a + inv_phi * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    let mut best = fc.max(fd);
    for _ in 0..GOLDEN_STEPS {
        if fc >= fd {
            b = d;
            (d, fd) = (c, fc);
            c = b - inv_phi * (b - a);
            fc = f(c);
            best = best.max(fc);
        } else {
            a = c;
            (c, fc) = (d, fd);
            d = a + inv_phi * (b - a);
            fd = f(d);
            best = best.max(fd);
        }
    }
    best
}
