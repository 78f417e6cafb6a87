//! The cell grid over a domain's parameter rectangle.

use crate::chi2::domain::{Domain, DomainPoint};

/// Cells are row-major: `row * columns + column`.
pub(crate) struct Grid {
    pub domain: Domain,
    pub columns: usize,
    pub rows: usize,
    pub col_range: [f64; 2],
    pub row_range: [f64; 2],
    pub col_width: f64,
    pub row_width: f64,
}

impl Grid {
    pub fn new(domain: Domain, [columns, rows]: [usize; 2]) -> Grid {
        let (col_range, row_range) = domain.parameter_box();
        Grid {
            domain,
            columns,
            rows,
            col_range,
            row_range,
            col_width: (col_range[1] - col_range[0]) / columns as f64,
            row_width: (row_range[1] - row_range[0]) / rows as f64,
        }
    }

    /// The cell and its up to 8 neighbours; columns wrap around for the azimuthal
    /// parameterizations.
    pub fn neighborhood(&self, cell: usize) -> impl Iterator<Item = usize> + '_ {
        let (row, col) = (
            (cell / self.columns) as isize,
            (cell % self.columns) as isize,
        );
        let wraps = self.domain.wraps_columns();
        let (rows, columns) = (self.rows as isize, self.columns as isize);
        (-1..=1).flat_map(move |dr| {
            (-1..=1).filter_map(move |dc| {
                let r = row + dr;
                let mut c = col + dc;
                if wraps {
                    c = c.rem_euclid(columns);
                }
                ((0..rows).contains(&r) && (0..columns).contains(&c))
                    .then(|| (r * columns + c) as usize)
            })
        })
    }

    /// Row-major cell index of a point, or None when it is outside the domain.
    pub fn cell_of<P: DomainPoint>(&self, point: P) -> Option<usize> {
        let [c, r] = point.parameters(&self.domain)?;
        let index = |v: f64, start: f64, width: f64, count: usize| {
            (((v - start) / width) as usize).min(count - 1)
        };
        let col = index(c, self.col_range[0], self.col_width, self.columns);
        let row = index(r, self.row_range[0], self.row_width, self.rows);
        Some(row * self.columns + col)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};

    #[test]
    fn neighbourhoods_wrap_in_azimuth_only() {
        let sphere = Grid::new(Domain::Sphere, [8, 4]);
        let mut n: Vec<usize> = sphere.neighborhood(0).collect();
        n.sort();
        // Row 0, column 0: columns 7, 0, 1 of rows 0 and 1.
        assert_eq!(n, vec![0, 1, 7, 8, 9, 15]);
        let rect = Domain::Rectangle {
            min: Vec2::ZERO,
            max: Vec2::ONE,
        };
        let grid = Grid::new(rect, [8, 4]);
        let mut n: Vec<usize> = grid.neighborhood(0).collect();
        n.sort();
        assert_eq!(n, vec![0, 1, 8, 9]);
        assert_eq!(grid.neighborhood(8 + 3).count(), 9);
    }

    #[test]
    fn points_land_in_the_cell_containing_them() {
        let grid = Grid::new(Domain::Hemisphere, [4, 2]);
        // phi just below 2 pi, cos theta 0.75: last column, top row.
        let w = Vec3::new(0.6, -1e-3, 0.0).normalize() * (1.0f32 - 0.5625).sqrt()
            + Vec3::new(0.0, 0.0, 0.75);
        assert_eq!(grid.cell_of(w), Some(4 + 3));
        // The pole has azimuth 0: first column, top row.
        assert_eq!(grid.cell_of(Vec3::Z), Some(4));
        assert_eq!(grid.cell_of(-Vec3::Z), None);
    }
}
