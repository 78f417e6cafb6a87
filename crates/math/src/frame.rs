//! Orthonormal frames for shading: local z is the normal.

use glam::Vec3;

/// An orthonormal basis (s, t, n). `to_local` maps world directions into the frame
/// where the normal is +z, so that cos(theta) is simply `v.z`.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Builds a frame around a unit normal without branches on the axis, using the
    /// construction of Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017).
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// A frame whose normal is `n` and whose first axis is `s` projected orthogonal to `n`.
    pub fn from_normal_tangent(n: Vec3, s: Vec3) -> Frame {
        let s = (s - n * n.dot(s)).normalize_or_zero();
        if s == Vec3::ZERO {
            return Frame::from_normal(n);
        }
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }

    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_for_all_octants() {
        for &n in &[
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.5, 0.81).normalize(),
            Vec3::new(-1e-7, 1e-7, -1.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(
                f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5
            );
            let v = Vec3::new(0.2, 0.7, -0.4);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }
}
