//! Gauss–Legendre rules, used to integrate the pdf over each histogram cell.
//!
//! Gauss nodes lie strictly inside the interval, so a pdf that jumps exactly on a cell
//! edge (a hemisphere's horizon, a quadrant boundary, a pixel filter's support) is
//! integrated without error, where a closed rule such as Simpson's would charge the
//! edge value to both neighbours.

/// An n-point Gauss–Legendre rule on [-1, 1]: exact for polynomials of degree 2n - 1.
#[derive(Clone, Debug)]
pub struct GaussLegendre {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

impl GaussLegendre {
    /// Nodes are the roots of the Legendre polynomial P_n, found by Newton's method from
    /// Tricomi's estimate cos(pi (i - 1/4) / (n + 1/2)); P_n and P_n' come from Bonnet's
    /// recurrence (k+1) P_{k+1} = (2k+1) x P_k - k P_{k-1}. Weights are
    /// 2 / ((1 - x^2) P_n'(x)^2) (Abramowitz & Stegun 25.4.29).
    pub fn new(n: usize) -> GaussLegendre {
        assert!(n >= 1, "a Gauss–Legendre rule needs at least one node");
        let mut nodes = Vec::with_capacity(n);
        let mut weights = Vec::with_capacity(n);
        let nf = n as f64;
        for i in 1..=n {
            let mut x = (std::f64::consts::PI * (i as f64 - 0.25) / (nf + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                let (p, dp) = legendre_with_derivative(n, x);
                derivative = dp;
                let step = p / dp;
                x -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            let (_, dp) = legendre_with_derivative(n, x);
            if dp.is_finite() {
                derivative = dp;
            }
            nodes.push(x);
            weights.push(2.0 / ((1.0 - x * x) * derivative * derivative));
        }
        GaussLegendre { nodes, weights }
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
}

/// Integrates a function over parameter-space cells with a tensor-product
/// Gauss–Legendre rule, refining adaptively where the pdf is not smooth.
///
/// Each cell is integrated once whole and once as 2 x 2 sub-cells (2 x 1 for 1D
/// domains); where the two disagree by more than the tolerance, each sub-cell is
/// refined in turn with half the tolerance, up to `max_depth` levels. A jump of the
/// pdf across a cell (a cone's rim, a light's silhouette) is then resolved to
/// 2^-depth of the cell, while smooth cells cost one refinement.
pub(crate) struct CellIntegrator {
    pub col_rule: GaussLegendre,
    pub row_rule: GaussLegendre,
    /// False for 1D domains: only columns are split.
    pub split_rows: bool,
    pub max_depth: u32,
}

impl CellIntegrator {
    /// The fixed rule over [c0, c1] x [r0, r1], in parameter units.
    fn rule(&self, f: &mut impl FnMut([f64; 2]) -> f64, c: [f64; 2], r: [f64; 2]) -> f64 {
        let (hc, hr) = (0.5 * (c[1] - c[0]), 0.5 * (r[1] - r[0]));
        let mut sum = 0.0;
        for (&yr, &wr) in self.row_rule.nodes.iter().zip(&self.row_rule.weights) {
            let rv = r[0] + (yr + 1.0) * hr;
            for (&xc, &wc) in self.col_rule.nodes.iter().zip(&self.col_rule.weights) {
                sum += wr * wc * f([c[0] + (xc + 1.0) * hc, rv]);
            }
        }
        sum * hc * hr
    }

    /// ∫ f over the cell, to about `tolerance(coarse estimate)` absolute accuracy, and
    /// whether the cell was rough (needed refinement beyond the first check).
    ///
    /// With `split_levels` > 0 the cell is first cut into 2^levels x 2^levels pieces
    /// (each integrated adaptively with its tolerance scaled by 2^-levels, so that the
    /// worst-case sum stays within the cell's). Gauss nodes leave a band along each
    /// edge unseen (7 % of the width for 4 nodes, half that after one refinement), so
    /// a jump that only grazes a cell is missed; splitting narrows the band.
    pub fn integrate(
        &self,
        f: &mut impl FnMut([f64; 2]) -> f64,
        c: [f64; 2],
        r: [f64; 2],
        tolerance: &impl Fn(f64) -> f64,
        split_levels: u32,
    ) -> (f64, bool) {
        let pieces = 1usize << split_levels;
        let row_pieces = if self.split_rows { pieces } else { 1 };
        let scale = 0.5f64.powi(split_levels as i32);
        let (wc, wr) = (
            (c[1] - c[0]) / pieces as f64,
            (r[1] - r[0]) / row_pieces as f64,
        );
        let mut sum = 0.0;
        let mut rough = false;
        for j in 0..row_pieces {
            let rj = [r[0] + j as f64 * wr, r[0] + (j + 1) as f64 * wr];
            for i in 0..pieces {
                let ci = [c[0] + i as f64 * wc, c[0] + (i + 1) as f64 * wc];
                let coarse = self.rule(f, ci, rj);
                let tol = scale * tolerance(coarse);
                let (value, refined) = self.refine(f, ci, rj, coarse, tol, self.max_depth);
                sum += value;
                rough |= refined;
            }
        }
        (sum, rough)
    }

    /// Compares the rule on the cell with the rule on its four children and recurses
    /// into the children while they disagree; also returns whether it recursed.
    fn refine(
        &self,
        f: &mut impl FnMut([f64; 2]) -> f64,
        c: [f64; 2],
        r: [f64; 2],
        coarse: f64,
        tolerance: f64,
        depth: u32,
    ) -> (f64, bool) {
        let cm = 0.5 * (c[0] + c[1]);
        let rm = 0.5 * (r[0] + r[1]);
        let cols = [[c[0], cm], [cm, c[1]]];
        let rows = if self.split_rows {
            [[r[0], rm], [rm, r[1]]]
        } else {
            [r, r]
        };
        let row_count = if self.split_rows { 2 } else { 1 };
        let mut parts = [0.0f64; 4];
        let mut fine = 0.0;
        for (j, row) in rows.iter().take(row_count).enumerate() {
            for (i, col) in cols.iter().enumerate() {
                parts[2 * j + i] = self.rule(f, *col, *row);
                fine += parts[2 * j + i];
            }
        }
        if depth == 0 || (fine - coarse).abs() <= tolerance {
            return (fine, false);
        }
        let mut sum = 0.0;
        for (j, row) in rows.iter().take(row_count).enumerate() {
            for (i, col) in cols.iter().enumerate() {
                let part = parts[2 * j + i];
                sum += self
                    .refine(f, *col, *row, part, 0.5 * tolerance, depth - 1)
                    .0;
            }
        }
        (sum, true)
    }
}

/// (P_n(x), P_n'(x)) for |x| < 1.
fn legendre_with_derivative(n: usize, x: f64) -> (f64, f64) {
    let mut p_prev = 1.0;
    let mut p = x;
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 1..n {
        let kf = k as f64;
        let next = ((2.0 * kf + 1.0) * x * p - kf * p_prev) / (kf + 1.0);
        p_prev = p;
        p = next;
    }
    let dp = n as f64 * (x * p - p_prev) / (x * x - 1.0);
    (p, dp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_up_to_their_degree_exactly() {
        for n in 1..=12 {
            let rule = GaussLegendre::new(n);
            assert_eq!(rule.len(), n);
            for degree in 0..2 * n {
                let got: f64 = rule
                    .nodes
                    .iter()
                    .zip(&rule.weights)
                    .map(|(&x, &w)| w * x.powi(degree as i32))
                    .sum();
                let want = if degree % 2 == 1 {
                    0.0
                } else {
                    2.0 / (degree as f64 + 1.0)
                };
                assert!((got - want).abs() < 1e-13, "n {n} degree {degree}: {got}");
            }
            assert!(rule.nodes.iter().all(|x| x.abs() < 1.0));
        }
    }

    #[test]
    fn refinement_resolves_a_jump_inside_a_cell() {
        // Indicator of the disk of radius 0.3 around (0.5, 0.5) over the unit square.
        let mut f = |p: [f64; 2]| {
            let (dx, dy) = (p[0] - 0.5, p[1] - 0.5);
            if dx * dx + dy * dy < 0.09 { 1.0 } else { 0.0 }
        };
        let exact = std::f64::consts::PI * 0.09;
        let integrator = |max_depth| CellIntegrator {
            col_rule: GaussLegendre::new(5),
            row_rule: GaussLegendre::new(5),
            split_rows: true,
            max_depth,
        };
        let (fixed, adaptive) = (integrator(0), integrator(9));
        let unit = [0.0, 1.0];
        let coarse_error = (fixed.integrate(&mut f, unit, unit, &|_| 0.0, 0).0 - exact).abs();
        let fine_error = (adaptive.integrate(&mut f, unit, unit, &|_| 1e-4, 0).0 - exact).abs();
        assert!(coarse_error > 1e-3, "{coarse_error}");
        assert!(fine_error < 3e-4, "{fine_error}");
    }

    #[test]
    fn splitting_finds_a_feature_between_the_nodes() {
        // A small square between the nodes of a 4-point rule: invisible to the whole
        // cell and to its 2 x 2 refinement, found once the cell is split 16 x 16.
        let mut f = |p: [f64; 2]| {
            let inside = |v: f64| (0.2..0.24).contains(&v);
            if inside(p[0]) && inside(p[1]) {
                1.0
            } else {
                0.0
            }
        };
        let rule = CellIntegrator {
            col_rule: GaussLegendre::new(4),
            row_rule: GaussLegendre::new(4),
            split_rows: true,
            max_depth: 8,
        };
        let unit = [0.0, 1.0];
        assert_eq!(
            rule.integrate(&mut f, unit, unit, &|_| 1e-6, 0),
            (0.0, false)
        );
        let (split, rough) = rule.integrate(&mut f, unit, unit, &|_| 1e-6, 4);
        assert!(rough);
        assert!((split - 0.0016).abs() < 1e-4, "{split}");
    }

    #[test]
    fn rules_are_not_exact_beyond_their_degree() {
        // x^(2n) is the first monomial an n-point rule misses: the test above can fail.
        let rule = GaussLegendre::new(3);
        let got: f64 = rule
            .nodes
            .iter()
            .zip(&rule.weights)
            .map(|(&x, &w)| w * x.powi(6))
            .sum();
        assert!((got - 2.0 / 7.0).abs() > 1e-3);
    }
}
