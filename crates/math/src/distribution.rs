//! A piecewise-constant 1D distribution, used for discrete choices such as picking a
//! light in proportion to its power or a triangle in proportion to its area, and a
//! piecewise-constant 2D density over the unit square built from it (marginal over
//! rows, then the chosen row's conditional), used for environment images.

use glam::Vec2;

/// Discrete distribution over `n` items with weights `w_i >= 0`. Sampling inverts the
/// CDF, so it is monotone in u (stratified u give stratified items) and exactly
/// reproducible. A guide table (Chen & Asau, "On generating random variates from an
/// empirical distribution", AIIE Transactions 6(2), 1974) narrows the search to the
/// items of one of 2^k equal intervals of u, about one item on average: a large
/// distribution (an environment image's rows) is then two memory reads instead of a
/// binary search's log₂ n dependent ones.
#[derive(Clone, Debug, Default)]
pub struct Distribution1D {
    /// Normalised CDF with `cdf[0] = 0` and `cdf[n] = 1`.
    cdf: Vec<f64>,
    pmf: Vec<f32>,
    /// `guide[k]`: the item that u = k / K falls in, for K = `guide.len() − 1`, a power
    /// of two (so that k / K and u · K are exact).
    guide: Vec<u32>,
    total: f64,
}

impl Distribution1D {
    /// Builds the distribution. All-zero (or empty) weights give a uniform distribution
    /// over the items so that sampling is still defined; `total()` then reports 0.
    pub fn new(weights: &[f32]) -> Distribution1D {
        let n = weights.len();
        let total: f64 = weights.iter().map(|&w| w.max(0.0) as f64).sum();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut acc = 0.0f64;
        for &w in weights {
            acc += if total > 0.0 {
                w.max(0.0) as f64 / total
            } else {
                1.0 / n as f64
            };
            cdf.push(acc);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let pmf = (0..n).map(|i| (cdf[i + 1] - cdf[i]) as f32).collect();
        let guide = guide_table(&cdf);
        Distribution1D {
            cdf,
            pmf,
            guide,
            total,
        }
    }

    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }

    /// Sum of the (clamped) weights.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Probability of item `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// Picks an item for `u` in [0,1); returns (index, pmf, u remapped to [0,1) within the item).
    pub fn sample(&self, u: f32) -> (usize, f32, f32) {
        let n = self.pmf.len();
        debug_assert!(n > 0, "sampling an empty distribution");
        let u64 = u as f64;
        // The item is the first i with cdf[i+1] > u (the last item if none). u lies in
        // interval k of the guide, [k / K, (k + 1) / K), so the item lies between the
        // items of the interval's ends; a binary search finishes between them.
        let intervals = self.guide.len() - 1;
        let k = ((u64 * intervals as f64) as usize).min(intervals - 1);
        let mut lo = self.guide[k] as usize;
        let mut len = self.guide[k + 1] as usize + 1 - lo;
        // Steps that choose without branching: which half holds u is a coin flip. The
        // interval [lo, lo + len) holds the item; a step keeps its upper part when item
        // lo + half − 1 ends at or below u, and otherwise a part at least as long as
        // the lower half, which holds it then.
        while len > 1 {
            let half = len / 2;
            lo = std::hint::select_unpredictable(self.cdf[lo + half] <= u64, lo + half, lo);
            len -= half;
        }
        // Skip zero-probability items that a u exactly on a CDF step could land on. The
        // probability is read as the CDF's step, which `pmf` holds too (the same
        // expression), so that no third array is read.
        let step = |i: usize| self.cdf[i + 1] - self.cdf[i];
        while lo + 1 < n && step(lo) as f32 == 0.0 {
            lo += 1;
        }
        let width = step(lo);
        let remapped = if width > 0.0 {
            (((u64 - self.cdf[lo]) / width) as f32).clamp(0.0, super::ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (lo, width as f32, remapped)
    }
}

/// `guide[k]`: the item that u = k / K falls in (the first whose CDF step ends above
/// it), for K the item count rounded up to a power of two; empty for no items.
fn guide_table(cdf: &[f64]) -> Vec<u32> {
    let n = cdf.len() - 1;
    if n == 0 {
        return Vec::new();
    }
    let intervals = n.next_power_of_two();
    let mut item = 0;
    (0..=intervals)
        .map(|k| {
            let u = k as f64 / intervals as f64;
            while item + 1 < n && cdf[item + 1] <= u {
                item += 1;
            }
            item as u32
        })
        .collect()
}

/// A piecewise-constant density over [0,1]² on a `width` x `height` grid of cells,
/// proportional to non-negative cell weights (row 0 at v = 0). Sampling picks a row by
/// the marginal distribution and a column by that row's conditional, then a uniform
/// point within the cell: the density is `width * height * weight / total`. All-zero
/// weights give the uniform density.
#[derive(Clone, Debug, Default)]
pub struct Distribution2D {
    width: usize,
    height: usize,
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `weights` row-major, `width * height` of them (both at least 1).
    pub fn new(weights: &[f32], width: usize, height: usize) -> Distribution2D {
        assert!(
            width > 0 && height > 0 && weights.len() == width * height,
            "{} weights for a {width}x{height} grid",
            weights.len()
        );
        let rows: Vec<Distribution1D> = weights
            .chunks_exact(width)
            .map(Distribution1D::new)
            .collect();
        let row_totals: Vec<f32> = rows.iter().map(|r| r.total() as f32).collect();
        Distribution2D {
            width,
            height,
            marginal: Distribution1D::new(&row_totals),
            rows,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Sum of all (clamped) weights; 0 when the density fell back to uniform.
    pub fn total(&self) -> f64 {
        self.marginal.total()
    }

    /// A point of [0,1)² for `u` in [0,1)², with its density per unit area.
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (y, pmf_y, ry) = self.marginal.sample(u.y);
        let (x, pmf_x, rx) = self.rows[y].sample(u.x);
        let p = Vec2::new(
            ((x as f32 + rx) / self.width as f32).min(super::ONE_MINUS_EPSILON),
            ((y as f32 + ry) / self.height as f32).min(super::ONE_MINUS_EPSILON),
        );
        (p, pmf_x * pmf_y * (self.width * self.height) as f32)
    }

    /// The cell holding `p` (clamped to the grid).
    pub fn cell(&self, p: Vec2) -> (usize, usize) {
        let x = ((p.x * self.width as f32).max(0.0) as usize).min(self.width - 1);
        let y = ((p.y * self.height as f32).max(0.0) as usize).min(self.height - 1);
        (x, y)
    }

    /// Density per unit area at `p`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        let (x, y) = self.cell(p);
        self.marginal.pmf(y) * self.rows[y].pmf(x) * (self.width * self.height) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_d_density_follows_weights_and_integrates_to_one() {
        let weights = [1.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0, 1.0, 1.0];
        let d = Distribution2D::new(&weights, 3, 3);
        let total: f32 = weights.iter().sum();
        let mut integral = 0.0;
        for y in 0..3 {
            for x in 0..3 {
                let p = Vec2::new((x as f32 + 0.5) / 3.0, (y as f32 + 0.5) / 3.0);
                let expected = 9.0 * weights[y * 3 + x] / total;
                assert!((d.pdf(p) - expected).abs() < 1e-5, "{x},{y}");
                integral += d.pdf(p) / 9.0;
            }
        }
        assert!((integral - 1.0).abs() < 1e-5);
        let n = 300;
        let mut counts = [0usize; 9];
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (p, pdf) = d.sample(u);
                assert!(pdf > 0.0 && pdf == d.pdf(p));
                let (x, y) = d.cell(p);
                counts[y * 3 + x] += 1;
            }
        }
        for (c, w) in counts.iter().zip(weights) {
            let f = *c as f32 / (n * n) as f32;
            assert!((f - w / total).abs() < 2e-3, "{f} vs {}", w / total);
        }
        let flat = Distribution2D::new(&[0.0; 4], 2, 2);
        assert_eq!(flat.total(), 0.0);
        assert_eq!(flat.pdf(Vec2::new(0.7, 0.2)), 1.0);
    }

    #[test]
    fn sampling_frequencies_follow_weights() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, 4.0]);
        assert_eq!(d.pmf(1), 0.0);
        let mut counts = [0usize; 4];
        let n = 80_000;
        for i in 0..n {
            let (k, p, r) = d.sample((i as f32 + 0.5) / n as f32);
            assert!(p > 0.0 && (0.0..1.0).contains(&r));
            counts[k] += 1;
        }
        assert_eq!(counts[1], 0);
        assert!((counts[0] as f32 / n as f32 - 0.125).abs() < 1e-3);
        assert!((counts[3] as f32 / n as f32 - 0.5).abs() < 1e-3);
    }

    /// The search finds the item a linear scan of the CDF finds, for every length from
    /// 1 to 70 (odd and even halves, powers of two and their neighbours), with runs of
    /// zero weights, and for u on the CDF's steps as well as between them.
    #[test]
    fn the_search_finds_the_first_item_ending_above_u() {
        let mut rng = crate::hash::Pcg32::new(77, 2);
        for n in 1..=70 {
            for round in 0..20 {
                let weights: Vec<f32> = (0..n)
                    .map(|_| match rng.next_u32() % 4 {
                        0 if round % 2 == 0 => 0.0,
                        1 => 0.25,
                        _ => rng.uniform(),
                    })
                    .collect();
                let d = Distribution1D::new(&weights);
                let steps = d
                    .cdf
                    .iter()
                    .map(|&c| (c as f32).min(crate::ONE_MINUS_EPSILON));
                let us: Vec<f32> = (0..50).map(|_| rng.uniform()).chain(steps).collect();
                for u in us {
                    let scan = (0..n).find(|&i| d.cdf[i + 1] > u as f64).unwrap_or(n - 1);
                    let mut expected = scan;
                    while expected + 1 < n && d.pmf[expected] == 0.0 {
                        expected += 1;
                    }
                    assert_eq!(d.sample(u).0, expected, "n {n}, u {u}, weights {weights:?}");
                }
            }
        }
    }

    #[test]
    fn zero_weights_fall_back_to_uniform() {
        let d = Distribution1D::new(&[0.0, 0.0]);
        assert_eq!(d.total(), 0.0);
        assert_eq!(d.pmf(0), 0.5);
        assert_eq!(d.sample(0.75).0, 1);
    }
}
