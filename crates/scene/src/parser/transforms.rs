//! Transform directives. Each post-multiplies the CTM (CTM = CTM · T), so the directive
//! written last applies to the object first; `Transform` replaces the CTM.
//!
//! - `Translate x y z`, `Scale x y z`, `Rotate degrees x y z` (right-handed about the
//!   axis), `LookAt eye target up` (pbrt's left-handed camera frame: +x right, +y up,
//!   +z forward).
//! - `Transform [16]` / `ConcatTransform [16]`: the matrix written column by column
//!   (pbrt transposes the row-major reading), i.e. the last four numbers hold the
//!   translation.
//! - `CoordinateSystem "name"` saves the CTM; `CoordSysTransform "name"` restores it.
//!   `Camera` defines "camera" (world-from-camera), `WorldBegin` defines "world".
//! - `ActiveTransform StartTime|EndTime|All`, `TransformTimes t0 t1`: radiant renders
//!   the start time only; end-time transforms are ignored.

use glam::{Mat4, Vec3};

use super::Parser;
use crate::error::{FileLoc, SceneError};
use crate::token::{Token, TokenKind};
use radiant_math::Transform;

fn vec3(v: &[f32]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

impl Parser {
    pub(super) fn transform_directive(
        &mut self,
        name: &str,
        loc: &FileLoc,
    ) -> Result<(), SceneError> {
        let singular = |what: &str| SceneError::at(loc, format!("{name}: {what}"));
        let t = match name {
            "Identity" => return self.set_ctm(Transform::IDENTITY),
            "Translate" => Transform::translate(vec3(&self.numbers(3, name)?)),
            "Scale" => {
                let s = vec3(&self.numbers(3, name)?);
                match Transform::scale(s) {
                    Some(t) => t,
                    None if s.is_finite() => {
                        self.warn_singular(name, loc);
                        Transform::from_matrix_or_singular(Mat4::from_scale(s))
                    }
                    None => return Err(singular("the scale factors must be finite")),
                }
            }
            "Rotate" => {
                let v = self.numbers(4, name)?;
                Transform::rotate(v[0], vec3(&v[1..]))
                    .ok_or_else(|| singular("the rotation axis is zero"))?
            }
            "LookAt" => {
                let v = self.numbers(9, name)?;
                Transform::look_at(vec3(&v[0..3]), vec3(&v[3..6]), vec3(&v[6..9])).ok_or_else(|| {
                    singular("degenerate view: eye equals target, or up is parallel to the view direction")
                })?
            }
            "Transform" | "ConcatTransform" => {
                let v = self.numbers(16, name)?;
                let mut cols = [0.0f32; 16];
                cols.copy_from_slice(&v);
                let m = Mat4::from_cols_array(&cols);
                if !m.is_finite() {
                    return Err(singular("the matrix must be finite"));
                }
                let t = match Transform::from_matrix(m) {
                    Some(t) => t,
                    None => {
                        self.warn_singular(name, loc);
                        Transform::from_matrix_or_singular(m)
                    }
                };
                if name == "Transform" {
                    return self.set_ctm(t);
                }
                t
            }
            "CoordinateSystem" => {
                let (cs, _) = self.string_arg(name)?;
                self.named_coord_systems.insert(cs, self.gs.ctm);
                return Ok(());
            }
            "CoordSysTransform" => {
                let (cs, at) = self.string_arg(name)?;
                match self.named_coord_systems.get(&cs).copied() {
                    Some(t) => return self.set_ctm(t),
                    None => {
                        self.warn(
                            &at,
                            format!(
                                "CoordSysTransform: unknown coordinate system \"{cs}\"; ignored"
                            ),
                        );
                        return Ok(());
                    }
                }
            }
            "TransformTimes" => {
                self.numbers(2, name)?;
                self.warn_once(
                    "motion",
                    loc,
                    "motion blur is not supported; the scene is rendered at its start time",
                );
                return Ok(());
            }
            "ActiveTransform" => return self.active_transform(loc),
            _ => unreachable!("dispatched only for transform directives"),
        };
        if self.gs.start_time_active {
            self.gs.ctm = self.gs.ctm.compose(&t);
        }
        Ok(())
    }

    /// pbrt-v4 accepts singular transforms: shapes under them collapse and contribute
    /// nothing; only a camera or texture that needs the inverse refuses them.
    fn warn_singular(&mut self, name: &str, loc: &FileLoc) {
        self.warn(
            loc,
            format!("{name}: the transform is singular; accepted as pbrt-v4 does (quadrics and object instances under it are left out, meshes are flattened)"),
        );
    }

    fn set_ctm(&mut self, t: Transform) -> Result<(), SceneError> {
        if self.gs.start_time_active {
            self.gs.ctm = t;
        }
        Ok(())
    }

    fn active_transform(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        match self.next()? {
            Some(Token {
                kind: TokenKind::Word(w),
                loc: at,
            }) => {
                self.gs.start_time_active = match w.as_str() {
                    "StartTime" | "All" => true,
                    "EndTime" => false,
                    _ => {
                        return Err(SceneError::at(
                            &at,
                            format!(
                                "ActiveTransform: expected StartTime, EndTime or All, found '{w}'"
                            ),
                        ));
                    }
                };
                if w != "All" {
                    self.warn_once(
                        "motion",
                        loc,
                        "motion blur is not supported; the scene is rendered at its start time",
                    );
                }
                Ok(())
            }
            other => Err(self.unexpected(
                other.as_ref(),
                "StartTime, EndTime or All",
                "ActiveTransform",
            )),
        }
    }
}
