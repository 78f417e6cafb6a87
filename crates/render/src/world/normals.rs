//! Shading normals tilted by a material's bump map or normal map.
//!
//! Both change only the shading normal `ns` of a hit: the geometric normal, which
//! places rays leaving the surface and decides which side a direction is on, stays
//! that of the shape. The tilted normal is turned to the geometric normal's side.
//!
//! - Bump mapping (Blinn 1978, "Simulation of wrinkled surfaces"): the surface is
//!   displaced along its shading normal by a height h(u, v); the displaced surface's
//!   tangents are ∂p/∂u + ∂h/∂u n and ∂p/∂v + ∂h/∂v n (the term h ∂n/∂u, small for
//!   small heights, is left out), and their cross product is the new normal. The
//!   derivatives of h are forward differences over half the pixel footprint in (u, v)
//!   where the hit has one, else over 0.0005 (pbrt-v4's step for points without ray
//!   differentials).
//! - Normal maps: the image's RGB in [0, 1] is a unit vector 2 RGB − 1 in the frame
//!   (∂p/∂u, n × ∂p/∂u, n) of the unperturbed surface, read bilinearly at (u, 1 − v)
//!   with the image repeated.
//!
//! The tangents the height is measured along are those pbrt-v4 shades with: the
//! shape's ∂p/∂u and ∂p/∂v where the shading normal is the geometric one, and for
//! interpolated normals ∂p/∂u made perpendicular to `ns` with n × ∂p/∂u as the second
//! (so that bump strength matches pbrt-v4's on smooth meshes).

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::SurfaceHit;
use crate::texture::image::{Level, read_linear};
use crate::texture::{TextureEvalContext, TextureSet, filter};
use radiant_math::Frame;
use radiant_scene::{
    ColorEncoding, SceneDesc, SceneError, ShadingNormalDesc, TexturedParam, WrapMode,
};

/// Finite-difference step in (u, v) for points without a footprint.
const DEFAULT_STEP: f32 = 0.0005;

/// A material's shading-normal perturbation, ready to evaluate.
#[derive(Clone, Debug)]
pub enum ShadingNormal {
    /// Height from this float texture.
    Bump {
        displacement: u32,
    },
    NormalMap(Arc<Level>),
}

/// The perturbation of each material id (empty when no material has one), images
/// read once per file.
pub(crate) fn build_shading_normals(
    desc: &SceneDesc,
) -> Result<Vec<Option<ShadingNormal>>, SceneError> {
    let mut images: HashMap<PathBuf, Arc<Level>> = HashMap::new();
    let mut out = Vec::with_capacity(desc.shading_normals.len());
    for n in &desc.shading_normals {
        out.push(match n {
            None => None,
            Some(ShadingNormalDesc::Bump { displacement }) => Some(ShadingNormal::Bump {
                displacement: *displacement,
            }),
            Some(ShadingNormalDesc::NormalMap { filename }) => {
                let level = match images.get(filename) {
                    Some(l) => l.clone(),
                    None => {
                        let l =
                            Arc::new(read_linear(filename, Some(ColorEncoding::Linear)).map_err(
                                |e| SceneError::file(filename, format!("normal map: {e}")),
                            )?);
                        images.insert(filename.clone(), l.clone());
                        l
                    }
                };
                Some(ShadingNormal::NormalMap(level))
            }
        });
    }
    if out.iter().all(Option::is_none) {
        out.clear();
    }
    Ok(out)
}

/// The tangents that heights and normal-map frames are measured along (see the
/// module notes); `None` where the surface has no (u, v) parameterisation.
fn shading_tangents(hit: &SurfaceHit) -> Option<(Vec3, Vec3)> {
    if hit.dpdu == Vec3::ZERO {
        return None;
    }
    if hit.ns == hit.ng && hit.dpdv != Vec3::ZERO {
        return Some((hit.dpdu, hit.dpdv));
    }
    let t = hit.ns.cross(hit.dpdu);
    if t.length_squared() == 0.0 || !t.is_finite() {
        return None;
    }
    Some((t.cross(hit.ns), t))
}

/// Applies `normal` to `hit.ns`; leaves the hit as it was where the result would be
/// degenerate.
pub(crate) fn perturb(hit: &mut SurfaceHit, normal: &ShadingNormal, textures: &TextureSet) {
    let n = match normal {
        ShadingNormal::Bump { displacement } => bumped_normal(hit, *displacement, textures),
        ShadingNormal::NormalMap(level) => mapped_normal(hit, level),
    };
    if let Some(mut n) = n {
        if n.dot(hit.ng) < 0.0 {
            n = -n;
        }
        hit.ns = n;
    }
}

fn bumped_normal(hit: &SurfaceHit, displacement: u32, textures: &TextureSet) -> Option<Vec3> {
    let (ss, ts) = shading_tangents(hit)?;
    let ctx = TextureEvalContext::from_hit(hit);
    let step = |a: f32, b: f32| {
        let s = 0.5 * (a.abs() + b.abs());
        if s > 0.0 && s.is_finite() {
            s
        } else {
            DEFAULT_STEP
        }
    };
    let du = step(ctx.dudx, ctx.dudy);
    let dv = step(ctx.dvdx, ctx.dvdy);
    let height = |c: &TextureEvalContext| textures.float(TexturedParam::Texture(displacement), c);
    let h = height(&ctx);
    let shifted = |dp: Vec3, duv: Vec2| TextureEvalContext {
        p: ctx.p + dp,
        uv: ctx.uv + duv,
        ..ctx
    };
    let h_u = height(&shifted(du * ss, Vec2::new(du, 0.0)));
    let h_v = height(&shifted(dv * ts, Vec2::new(0.0, dv)));
    let dpdu = ss + hit.ns * ((h_u - h) / du);
    let dpdv = ts + hit.ns * ((h_v - h) / dv);
    let n = dpdu.cross(dpdv).normalize_or_zero();
    (n != Vec3::ZERO && n.is_finite()).then_some(n)
}

fn mapped_normal(hit: &SurfaceHit, level: &Level) -> Option<Vec3> {
    let st = Vec2::new(hit.uv.x, 1.0 - hit.uv.y);
    let c = filter::bilinear(level, st, WrapMode::Repeat);
    let local = (Vec3::new(c.r, c.g, c.b) * 2.0 - Vec3::ONE).normalize_or_zero();
    if local == Vec3::ZERO || !local.is_finite() {
        return None;
    }
    if local == Vec3::Z {
        // The unperturbed normal, kept to the bit.
        return Some(hit.ns);
    }
    let frame = Frame::from_normal_tangent(hit.ns, hit.dpdu);
    let n = frame.to_world(local).normalize_or_zero();
    (n != Vec3::ZERO && n.is_finite()).then_some(n)
}
