//! Affine and projective transforms with their inverses. Names say the frames:
//! `render_from_object`, `camera_from_world`.

use glam::{Mat4, Vec3, Vec4};

/// A 4x4 transform and its inverse, kept together so normals and inverse mappings
/// never need a fresh matrix inversion on a hot path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub m: Mat4,
    pub inv: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        m: Mat4::IDENTITY,
        inv: Mat4::IDENTITY,
    };

    /// Wraps a matrix, or `None` when it is singular (or not finite).
    pub fn from_matrix(m: Mat4) -> Option<Transform> {
        // Invert in f64: scene files often chain many near-degenerate transforms.
        let d = m.as_dmat4();
        let det = d.determinant();
        if !det.is_finite() || det.abs() < 1e-300 || !m.is_finite() {
            return None;
        }
        let inv = d.inverse().as_mat4();
        inv.is_finite().then_some(Transform { m, inv })
    }

    /// Wraps any finite matrix: a singular one gets a not-a-number inverse (what
    /// pbrt-v4 does), so that whatever maps through the inverse finds nothing, while
    /// geometry mapped forwards collapses. [`Transform::is_invertible`] tells them apart.
    pub fn from_matrix_or_singular(m: Mat4) -> Transform {
        Transform::from_matrix(m).unwrap_or(Transform { m, inv: Mat4::NAN })
    }

    /// False for a singular transform (or one composed with a singular one).
    pub fn is_invertible(&self) -> bool {
        self.inv.is_finite()
    }

    pub fn translate(d: Vec3) -> Transform {
        Transform {
            m: Mat4::from_translation(d),
            inv: Mat4::from_translation(-d),
        }
    }

    /// Scale; `None` when a factor is zero.
    pub fn scale(s: Vec3) -> Option<Transform> {
        Transform::from_matrix(Mat4::from_scale(s))
    }

    /// Rotation by `degrees` about `axis` (right-handed, as pbrt's `Rotate`).
    pub fn rotate(degrees: f32, axis: Vec3) -> Option<Transform> {
        let axis = axis.normalize_or_zero();
        if axis == Vec3::ZERO {
            return None;
        }
        let m = Mat4::from_axis_angle(axis, degrees.to_radians());
        Some(Transform {
            m,
            inv: m.transpose(),
        })
    }

    /// pbrt's `LookAt`: the camera-from-world transform for a camera at `eye` looking at
    /// `look` with `up`. pbrt's camera space is left-handed (+x right, +y up, +z forward),
    /// so a scene is seen mirrored relative to a right-handed (Mitsuba) camera unless the
    /// file adds `Scale -1 1 1`. Returns `None` for degenerate input.
    pub fn look_at(eye: Vec3, look: Vec3, up: Vec3) -> Option<Transform> {
        let dir = (look - eye).normalize_or_zero();
        let up = up.normalize_or_zero();
        let right = up.cross(dir).normalize_or_zero();
        if dir == Vec3::ZERO || right == Vec3::ZERO {
            return None;
        }
        let new_up = dir.cross(right);
        let world_from_camera = Mat4::from_cols(
            right.extend(0.0),
            new_up.extend(0.0),
            dir.extend(0.0),
            eye.extend(1.0),
        );
        Transform::from_matrix(world_from_camera).map(|t| t.inverse())
    }

    pub fn inverse(&self) -> Transform {
        Transform {
            m: self.inv,
            inv: self.m,
        }
    }

    /// `self ∘ other`: applies `other` first.
    pub fn compose(&self, other: &Transform) -> Transform {
        Transform {
            m: self.m * other.m,
            inv: other.inv * self.inv,
        }
    }

    pub fn is_identity(&self) -> bool {
        self.m == Mat4::IDENTITY
    }

    pub fn point(&self, p: Vec3) -> Vec3 {
        let r = self.m * Vec4::new(p.x, p.y, p.z, 1.0);
        if r.w == 1.0 {
            r.truncate()
        } else {
            r.truncate() / r.w
        }
    }

    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }

    /// Normals transform by the inverse transpose.
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.inv.transpose().transform_vector3(n)
    }

    /// True when the transform flips orientation (negative determinant of the linear part).
    pub fn swaps_handedness(&self) -> bool {
        glam::Mat3::from_mat4(self.m).determinant() < 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_maps_eye_to_origin_and_target_to_plus_z() {
        let t = Transform::look_at(
            Vec3::new(278.0, 273.0, -800.0),
            Vec3::new(278.0, 273.0, 0.0),
            Vec3::Y,
        )
        .unwrap();
        assert!(t.point(Vec3::new(278.0, 273.0, -800.0)).length() < 1e-3);
        let p = t.point(Vec3::new(278.0, 273.0, 0.0));
        assert!((p - Vec3::new(0.0, 0.0, 800.0)).length() < 1e-3);
        // pbrt convention: world +x stays camera +x for this view.
        let q = t.vector(Vec3::X);
        assert!((q - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn normals_stay_perpendicular_under_nonuniform_scale() {
        let t = Transform::scale(Vec3::new(2.0, 1.0, 0.5)).unwrap();
        let tangent = Vec3::new(1.0, 1.0, 0.0);
        let n = Vec3::new(1.0, -1.0, 0.0);
        assert!(t.vector(tangent).dot(t.normal(n)).abs() < 1e-6);
    }

    #[test]
    fn singular_matrices_are_refused() {
        assert!(Transform::scale(Vec3::new(1.0, 0.0, 1.0)).is_none());
        assert!(Transform::from_matrix(Mat4::from_cols_array(&[f32::NAN; 16])).is_none());
    }
}
