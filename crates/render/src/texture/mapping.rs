//! From a shading point to texture coordinates with their screen-space derivatives:
//! the (u, v) parameterisation, spherical, cylindrical and planar projections, and the
//! texture-space point of solid textures.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};
use radiant_scene::{Mapping2D, Mapping3D};

use super::TextureEvalContext;

/// 2D texture coordinates and how they change across one pixel (x and y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexCoord2D {
    pub st: Vec2,
    pub dsdx: f32,
    pub dsdy: f32,
    pub dtdx: f32,
    pub dtdy: f32,
}

/// A texture-space point with its derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexCoord3D {
    pub p: Vec3,
    pub dpdx: Vec3,
    pub dpdy: Vec3,
}

/// The difference of a periodic coordinate (period 1) taken the short way round, so that
/// a footprint across the seam of a sphere is small, not nearly one.
fn wrapped(d: f32) -> f32 {
    d - d.round()
}

pub fn map_2d(mapping: &Mapping2D, ctx: &TextureEvalContext) -> TexCoord2D {
    match mapping {
        Mapping2D::Uv { su, sv, du, dv } => TexCoord2D {
            st: Vec2::new(su * ctx.uv.x + du, sv * ctx.uv.y + dv),
            dsdx: su * ctx.dudx,
            dsdy: su * ctx.dudy,
            dtdx: sv * ctx.dvdx,
            dtdy: sv * ctx.dvdy,
        },
        Mapping2D::Spherical {
            texture_from_render,
        } => {
            // Angles are not linear in p: the derivatives are differences over the
            // footprint, the footprint being what they approximate.
            let st = |p: Vec3| {
                let d = texture_from_render.point(p).normalize_or_zero();
                let theta = d.z.clamp(-1.0, 1.0).acos();
                let phi = d.y.atan2(d.x).rem_euclid(TAU);
                Vec2::new(theta / PI, phi / TAU)
            };
            differenced(ctx, st, [false, true])
        }
        Mapping2D::Cylindrical {
            texture_from_render,
        } => {
            let st = |p: Vec3| {
                let q = texture_from_render.point(p);
                Vec2::new((PI + q.y.atan2(q.x)) / TAU, q.z)
            };
            differenced(ctx, st, [true, false])
        }
        Mapping2D::Planar {
            texture_from_render,
            vs,
            vt,
            ds,
            dt,
        } => {
            let q = texture_from_render.point(ctx.p);
            let (dx, dy) = (
                texture_from_render.vector(ctx.dpdx),
                texture_from_render.vector(ctx.dpdy),
            );
            TexCoord2D {
                st: Vec2::new(ds + q.dot(*vs), dt + q.dot(*vt)),
                dsdx: vs.dot(dx),
                dsdy: vs.dot(dy),
                dtdx: vt.dot(dx),
                dtdy: vt.dot(dy),
            }
        }
    }
}

fn differenced(
    ctx: &TextureEvalContext,
    st: impl Fn(Vec3) -> Vec2,
    periodic: [bool; 2],
) -> TexCoord2D {
    let c = st(ctx.p);
    let d = |dp: Vec3| {
        if dp == Vec3::ZERO {
            return Vec2::ZERO;
        }
        let e = st(ctx.p + dp) - c;
        Vec2::new(
            if periodic[0] { wrapped(e.x) } else { e.x },
            if periodic[1] { wrapped(e.y) } else { e.y },
        )
    };
    let (ddx, ddy) = (d(ctx.dpdx), d(ctx.dpdy));
    TexCoord2D {
        st: c,
        dsdx: ddx.x,
        dsdy: ddy.x,
        dtdx: ddx.y,
        dtdy: ddy.y,
    }
}

pub fn map_3d(mapping: &Mapping3D, ctx: &TextureEvalContext) -> TexCoord3D {
    let xf = &mapping.texture_from_render;
    TexCoord3D {
        p: xf.point(ctx.p),
        dpdx: xf.vector(ctx.dpdx),
        dpdy: xf.vector(ctx.dpdy),
    }
}
