//! The dense form-factor matrix, row-major: row `i` holds `F_ij`, the fraction of the
//! energy leaving patch `i` that arrives at patch `j`.
//!
//! Stored as `f64` (what the factor computations produce) or `f32` (half the memory:
//! 400 MB at 10^4 patches); solvers read either and accumulate in `f64`.

use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum MatrixError {
    #[error("{values} values do not form a {n} x {n} matrix")]
    Shape { n: usize, values: usize },
}

/// A dense `n x n` form-factor matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct FormFactorMatrix<T> {
    n: usize,
    values: Vec<T>,
}

impl<T: Copy + Into<f64>> FormFactorMatrix<T> {
    /// Wraps row-major values.
    pub fn from_row_major(n: usize, values: Vec<T>) -> Result<Self, MatrixError> {
        if values.len() != n * n {
            return Err(MatrixError::Shape {
                n,
                values: values.len(),
            });
        }
        Ok(FormFactorMatrix { n, values })
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True for a 0 x 0 matrix.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// `F_ij`.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.values[i * self.n + j].into()
    }

    /// Row `i`: `F_ij` for all `j`.
    #[inline]
    pub fn row(&self, i: usize) -> &[T] {
        &self.values[i * self.n..(i + 1) * self.n]
    }

    /// All values, row-major.
    pub fn values(&self) -> &[T] {
        &self.values
    }
}

impl FormFactorMatrix<f64> {
    /// Builds a matrix from nested rows (as read from a data file).
    pub fn from_rows(rows: &[Vec<f64>]) -> Result<Self, MatrixError> {
        let n = rows.len();
        let values: Vec<f64> = rows.iter().flatten().copied().collect();
        if rows.iter().any(|r| r.len() != n) {
            return Err(MatrixError::Shape {
                n,
                values: values.len(),
            });
        }
        FormFactorMatrix::from_row_major(n, values)
    }

    /// A single-precision copy.
    pub fn to_f32(&self) -> FormFactorMatrix<f32> {
        FormFactorMatrix {
            n: self.n,
            values: self.values.iter().map(|&v| v as f32).collect(),
        }
    }
}
