//! A piecewise-constant 1D distribution, used for discrete choices such as picking a
//! light in proportion to its power or a triangle in proportion to its area.

/// Discrete distribution over `n` items with weights `w_i >= 0`. Sampling inverts the
/// CDF by binary search, so sampling is O(log n) and exactly reproducible.
#[derive(Clone, Debug, Default)]
pub struct Distribution1D {
    /// Normalised CDF with `cdf[0] = 0` and `cdf[n] = 1`.
    cdf: Vec<f64>,
    pmf: Vec<f32>,
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
        Distribution1D { cdf, pmf, total }
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
        // First index i with cdf[i+1] > u.
        let mut lo = 0usize;
        let mut hi = n - 1;
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.cdf[mid + 1] <= u64 {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        // Skip zero-probability items that a u exactly on a CDF step could land on.
        while lo + 1 < n && self.pmf[lo] == 0.0 {
            lo += 1;
        }
        let width = self.cdf[lo + 1] - self.cdf[lo];
        let remapped = if width > 0.0 {
            (((u64 - self.cdf[lo]) / width) as f32).clamp(0.0, super::ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (lo, self.pmf[lo], remapped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn zero_weights_fall_back_to_uniform() {
        let d = Distribution1D::new(&[0.0, 0.0]);
        assert_eq!(d.total(), 0.0);
        assert_eq!(d.pmf(0), 0.5);
        assert_eq!(d.sample(0.75).0, 1);
    }
}
