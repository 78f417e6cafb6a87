//! Separable convolution of single-channel planes with clamp-to-edge borders.
//!
//! Every FLIP filter is a Gaussian, a sum of two Gaussians, or a Gaussian derivative,
//! so each 2-D kernel is a product (or a sum of products) of 1-D kernels. Convolving
//! rows and then columns is exact for such kernels, and clamping coordinates per axis
//! equals clamping them in 2-D, so the result is the same as the direct 2-D filter.

use rayon::prelude::*;

/// A single-channel image, row-major, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Plane {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

impl Plane {
    pub fn zeros(width: usize, height: usize) -> Plane {
        Plane {
            width,
            height,
            data: vec![0.0; width * height],
        }
    }
}

/// A 1-D kernel of odd length 2·radius + 1, centred on `weights[radius]`.
#[derive(Clone, Debug)]
pub struct Kernel1D {
    pub weights: Vec<f32>,
}

impl Kernel1D {
    pub fn radius(&self) -> usize {
        self.weights.len() / 2
    }
}

/// Convolves every row of `src` with `kernel` into `dst` (clamp-to-edge). Each row is
/// first copied into a buffer padded with its edge values (one buffer per worker), so
/// the inner loop is a plain multiply-add over contiguous memory.
pub fn convolve_rows(src: &Plane, kernel: &Kernel1D, dst: &mut Plane) {
    debug_assert_eq!(src.data.len(), dst.data.len());
    let width = src.width;
    let radius = kernel.radius();
    dst.data
        .par_chunks_mut(width)
        .zip(src.data.par_chunks(width))
        .for_each_init(
            || vec![0.0f32; width + 2 * radius],
            |padded, (out, row)| {
                padded[..radius].fill(row[0]);
                padded[radius..radius + width].copy_from_slice(row);
                padded[radius + width..].fill(row[width - 1]);
                out.fill(0.0);
                for (t, &w) in kernel.weights.iter().enumerate() {
                    for (o, &v) in out.iter_mut().zip(&padded[t..t + width]) {
                        *o += w * v;
                    }
                }
            },
        );
}

/// Convolves every column of `src` with `kernel`; the result is scaled by `scale` and
/// either written to `dst` or, with `accumulate`, added to it. Works a whole output row
/// at a time so that the inner loop walks memory contiguously.
pub fn convolve_columns(
    src: &Plane,
    kernel: &Kernel1D,
    scale: f32,
    accumulate: bool,
    dst: &mut Plane,
) {
    debug_assert_eq!(src.data.len(), dst.data.len());
    let width = src.width;
    let radius = kernel.radius() as isize;
    let last = src.height as isize - 1;
    dst.data
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, out)| {
            if !accumulate {
                out.fill(0.0);
            }
            for (t, &w) in kernel.weights.iter().enumerate() {
                let sy = (y as isize + t as isize - radius).clamp(0, last) as usize;
                let row = &src.data[sy * width..(sy + 1) * width];
                let w = w * scale;
                for (o, &v) in out.iter_mut().zip(row) {
                    *o += w * v;
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direct_2d(src: &Plane, kx: &Kernel1D, ky: &Kernel1D) -> Plane {
        let (w, h) = (src.width as isize, src.height as isize);
        let (rx, ry) = (kx.radius() as isize, ky.radius() as isize);
        let mut out = Plane::zeros(src.width, src.height);
        for y in 0..h {
            for x in 0..w {
                let mut acc = 0.0;
                for j in -ry..=ry {
                    for i in -rx..=rx {
                        let sx = (x + i).clamp(0, w - 1);
                        let sy = (y + j).clamp(0, h - 1);
                        acc += kx.weights[(i + rx) as usize]
                            * ky.weights[(j + ry) as usize]
                            * src.data[(sy * w + sx) as usize];
                    }
                }
                out.data[(y * w + x) as usize] = acc;
            }
        }
        out
    }

    #[test]
    fn separable_equals_direct_2d_with_clamped_borders() {
        let (w, h) = (7, 5);
        let mut src = Plane::zeros(w, h);
        for (i, v) in src.data.iter_mut().enumerate() {
            *v = ((i * 37 % 11) as f32) * 0.1;
        }
        // Radius larger than the image to exercise clamping on both sides.
        let kx = Kernel1D {
            weights: vec![0.1, -0.2, 0.3, 0.5, 0.3, 0.2, 0.1, 0.05, -0.1],
        };
        let ky = Kernel1D {
            weights: vec![0.25, 0.5, 0.75, 0.5, 0.25, 0.1, 0.3],
        };
        let mut tmp = Plane::zeros(w, h);
        let mut out = Plane::zeros(w, h);
        convolve_rows(&src, &kx, &mut tmp);
        convolve_columns(&tmp, &ky, 1.0, false, &mut out);
        let expected = direct_2d(&src, &kx, &ky);
        for (a, b) in out.data.iter().zip(&expected.data) {
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
    }
}
