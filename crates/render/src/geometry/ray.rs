//! Rays.

use glam::Vec3;

/// A ray `o + t d`. `d` need not be normalised; hit distances are in units of `|d|`.
/// The valid interval `[0, t_max)` is passed to queries separately.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Ray {
        Ray { o, d }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// Offsets a ray origin off a surface along the geometric normal, on the side of `w`,
/// by an amount that scales with the magnitude of the coordinates so that self-
/// intersection is avoided at any scene scale (in the spirit of Wächter & Binder,
/// "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems 2019).
pub fn offset_origin(p: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let n = if ng.dot(w) < 0.0 { -ng } else { ng };
    let of_i = [
        (INT_SCALE * n.x) as i32,
        (INT_SCALE * n.y) as i32,
        (INT_SCALE * n.z) as i32,
    ];
    let bump = |c: f32, o: i32| -> f32 {
        let bits = c.to_bits() as i32;
        let moved = if c < 0.0 { bits - o } else { bits + o };
        f32::from_bits(moved as u32)
    };
    let p_i = Vec3::new(bump(p.x, of_i[0]), bump(p.y, of_i[1]), bump(p.z, of_i[2]));
    Vec3::new(
        if p.x.abs() < ORIGIN {
            p.x + FLOAT_SCALE * n.x
        } else {
            p_i.x
        },
        if p.y.abs() < ORIGIN {
            p.y + FLOAT_SCALE * n.y
        } else {
            p_i.y
        },
        if p.z.abs() < ORIGIN {
            p.z + FLOAT_SCALE * n.z
        } else {
            p_i.z
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_side_of_w() {
        for &p in &[
            Vec3::ZERO,
            Vec3::new(500.0, -3.0, 1e-3),
            Vec3::new(-1e4, 2e4, 7.0),
        ] {
            let n = Vec3::new(0.3, 0.9, -0.3).normalize();
            let up = offset_origin(p, n, n);
            let down = offset_origin(p, n, -n);
            assert!((up - p).dot(n) > 0.0);
            assert!((down - p).dot(n) < 0.0);
            // At most a few hundred ulps: tiny relative to the coordinates.
            assert!((up - p).length() < 1e-4 * p.length() + 1e-3);
        }
    }
}
