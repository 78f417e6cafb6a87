//! Microfacet BSDFs on the Trowbridge–Reitz distribution: a rough conductor
//! (reflection only) and a rough dielectric (reflection and transmission), after
//! Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through
//! Rough Surfaces", with height-correlated Smith masking–shadowing and sampling of
//! visible normals (see [`microfacet`](super::microfacet)).
//!
//! Local frame: macro normal +z; for the dielectric +z is the outside and `eta` the
//! index inside over outside. Transmission uses the generalized half vector
//! m ∝ wo + η' wi, η' the index on the side of `wi` over that of `wo` (Walter et al.
//! eq. 16), and the Jacobian |wi·m| / (wi·m + wo·m / η')² of the half-vector map.
//! In radiance transport the transmitted BSDF carries 1/η'² (radiance is compressed
//! into the denser medium); importance does not (Veach 1997, §5.2).

use glam::{Vec2, Vec3};

use super::fresnel;
use super::microfacet::{TrowbridgeReitz, reflect};
use super::{BsdfSample, TransportMode};
use radiant_math::color::Rgb;

/// The Fresnel term of a rough conductor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConductorFresnel {
    /// Complex index eta + i k per channel (relative to the outside).
    Complex { eta: Rgb, k: Rgb },
    /// A reflectance independent of angle (F = 1 makes the white-furnace case).
    Constant(Rgb),
}

impl ConductorFresnel {
    pub fn eval(&self, cos: f32) -> Rgb {
        match *self {
            ConductorFresnel::Complex { eta, k } => fresnel::conductor(cos, eta, k),
            ConductorFresnel::Constant(r) => r,
        }
    }

    /// pbrt-v4's reading of a conductor's `reflectance` r: a metal with eta = 1 and
    /// k = 2 sqrt(r) / sqrt(1 - r), whose normal-incidence reflectance
    /// ((eta-1)² + k²) / ((eta+1)² + k²) is exactly r, rising to 1 at grazing angles.
    pub fn from_reflectance(r: Rgb) -> ConductorFresnel {
        let k = |r: f32| {
            let r = r.clamp(0.0, 1.0 - 1e-6);
            2.0 * r.sqrt() / (1.0 - r).sqrt()
        };
        ConductorFresnel::Complex {
            eta: Rgb::WHITE,
            k: Rgb::new(k(r.r), k(r.g), k(r.b)),
        }
    }
}

/// Mirrors a pair of directions below the surface to above it: the distribution is
/// symmetric under w -> -w, so two-sided reflection is the same lobe.
fn upper(wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
    if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) }
}

pub fn conductor_eval(d: &TrowbridgeReitz, fr: &ConductorFresnel, wo: Vec3, wi: Vec3) -> Rgb {
    if wo.z * wi.z <= 0.0 {
        return Rgb::BLACK;
    }
    let (wo, wi) = upper(wo, wi);
    let Some(m) = (wo + wi).try_normalize() else {
        return Rgb::BLACK;
    };
    let c = d.d(m) * d.g(wo, wi) / (4.0 * wo.z * wi.z);
    fr.eval(wo.dot(m)) * c
}

pub fn conductor_pdf(d: &TrowbridgeReitz, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z * wi.z <= 0.0 {
        return 0.0;
    }
    let (wo, wi) = upper(wo, wi);
    let Some(m) = (wo + wi).try_normalize() else {
        return 0.0;
    };
    // Reflection about m: dwi = 4 |wo·m| dm.
    d.d_visible(wo, m) / (4.0 * wo.dot(m))
}

pub fn conductor_sample(
    d: &TrowbridgeReitz,
    fr: &ConductorFresnel,
    wo: Vec3,
    u: Vec2,
) -> Option<BsdfSample> {
    let flip = wo.z < 0.0;
    let wo_u = if flip { -wo } else { wo };
    let m = d.sample_visible(wo_u, u);
    let wi_u = reflect(wo_u, m);
    if wi_u.z <= 0.0 {
        return None;
    }
    let wo_m = wo_u.dot(m);
    let pdf = d.d_visible(wo_u, m) / (4.0 * wo_m);
    if pdf.is_nan() || pdf <= 0.0 {
        return None;
    }
    let f = fr.eval(wo_m) * (d.d(m) * d.g(wo_u, wi_u) / (4.0 * wo_u.z * wi_u.z));
    Some(BsdfSample {
        wi: if flip { -wi_u } else { wi_u },
        f,
        pdf,
        specular: false,
    })
}

/// The generalized half vector of a dielectric pair, facing +z, with the relative
/// index η' (side of `wi` over side of `wo`; 1 for reflection). `None` for degenerate
/// pairs and for microfacets seen from behind by either direction.
fn dielectric_half(eta: f32, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, bool)> {
    let (co, ci) = (wo.z, wi.z);
    if co == 0.0 || ci == 0.0 {
        return None;
    }
    let reflection = co * ci > 0.0;
    let etap = match (reflection, co > 0.0) {
        (true, _) => 1.0,
        (false, true) => eta,
        (false, false) => 1.0 / eta,
    };
    let m = (wo + etap * wi).try_normalize()?;
    let m = if m.z < 0.0 { -m } else { m };
    if m.dot(wi) * ci <= 0.0 || m.dot(wo) * co <= 0.0 {
        return None;
    }
    Some((m, etap, reflection))
}

pub fn dielectric_eval(
    d: &TrowbridgeReitz,
    eta: f32,
    wo: Vec3,
    wi: Vec3,
    mode: TransportMode,
) -> f32 {
    let Some((m, etap, reflection)) = dielectric_half(eta, wo, wi) else {
        return 0.0;
    };
    let (wo_m, wi_m) = (wo.dot(m), wi.dot(m));
    let r = fresnel::dielectric(wo_m, eta);
    let dg = d.d(m) * d.g(wo, wi);
    if reflection {
        return dg * r / (4.0 * wo.z * wi.z).abs();
    }
    let s = wi_m + wo_m / etap;
    let mut f = dg * (1.0 - r) * (wi_m * wo_m / (s * s * wi.z * wo.z)).abs();
    if mode == TransportMode::Radiance {
        f /= etap * etap;
    }
    f
}

pub fn dielectric_pdf(d: &TrowbridgeReitz, eta: f32, wo: Vec3, wi: Vec3) -> f32 {
    let Some((m, etap, reflection)) = dielectric_half(eta, wo, wi) else {
        return 0.0;
    };
    let (wo_m, wi_m) = (wo.dot(m), wi.dot(m));
    let r = fresnel::dielectric(wo_m, eta);
    let dv = d.d_visible(wo, m);
    if reflection {
        dv * r / (4.0 * wo_m.abs())
    } else {
        let s = wi_m + wo_m / etap;
        dv * (1.0 - r) * wi_m.abs() / (s * s)
    }
}

/// Samples a visible microfacet normal, then reflection with probability R (Fresnel
/// at that microfacet) or refraction through it.
pub fn dielectric_sample(
    d: &TrowbridgeReitz,
    eta: f32,
    wo: Vec3,
    u_lobe: f32,
    u: Vec2,
    mode: TransportMode,
) -> Option<BsdfSample> {
    let m = d.sample_visible(wo, u);
    let wo_m = wo.dot(m);
    let r = fresnel::dielectric(wo_m, eta);
    let dv = d.d_visible(wo, m);
    let sample = if u_lobe < r {
        let wi = reflect(wo, m);
        if wi.z * wo.z <= 0.0 {
            return None;
        }
        BsdfSample {
            wi,
            f: Rgb::splat(d.d(m) * d.g(wo, wi) * r / (4.0 * wo.z * wi.z).abs()),
            pdf: dv * r / (4.0 * wo_m.abs()),
            specular: false,
        }
    } else {
        let etap = if wo.z > 0.0 { eta } else { 1.0 / eta };
        let n = if wo_m > 0.0 { m } else { -m };
        let wi = fresnel::refract(wo, n, etap)?;
        if wi.z * wo.z >= 0.0 {
            return None;
        }
        let wi_m = wi.dot(m);
        let s = wi_m + wo_m / etap;
        BsdfSample {
            wi,
            f: Rgb::splat(refracted_value(d, m, wo, wi, 1.0 - r, etap, mode)),
            pdf: dv * (1.0 - r) * wi_m.abs() / (s * s),
            specular: false,
        }
    };
    (sample.pdf > 0.0 && sample.pdf.is_finite()).then_some(sample)
}

/// The BSDF's transmitted value from `wo` to `wi`, where `wi` is `wo` refracted through
/// the microfacet `m` (facing +z) with relative index `etap`, and `t` is 1 − F at
/// wo·m: the sampler knows m and need not find it again as the generalized half vector
/// of the pair, as [`dielectric_eval`] must.
#[inline(always)]
pub(super) fn refracted_value(
    d: &TrowbridgeReitz,
    m: Vec3,
    wo: Vec3,
    wi: Vec3,
    t: f32,
    etap: f32,
    mode: TransportMode,
) -> f32 {
    let (wo_m, wi_m) = (wo.dot(m), wi.dot(m));
    let s = wi_m + wo_m / etap;
    let f = d.d(m) * d.g(wo, wi) * t * (wi_m * wo_m / (s * s * wi.z * wo.z)).abs();
    if mode == TransportMode::Radiance {
        f / (etap * etap)
    } else {
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;
    use radiant_math::sampling::uniform_sphere;

    /// The value from the sampled microfacet is the value `dielectric_eval` finds from
    /// the pair of directions alone, from either side and in both transport modes, to
    /// rounding.
    #[test]
    fn the_refracted_value_from_its_microfacet_is_the_evaluated_one() {
        let mut rng = Pcg32::new(17, 5);
        let mut checked = 0;
        for (alpha_x, alpha_y) in [(0.05, 0.05), (0.3, 0.3), (0.8, 0.2)] {
            let d = TrowbridgeReitz::new(alpha_x, alpha_y);
            for eta in [1.33f32, 1.5, 2.4] {
                for _ in 0..2000 {
                    let wo = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
                    if wo.z.abs() < 0.05 {
                        continue;
                    }
                    let m = d.sample_visible(wo, Vec2::new(rng.uniform(), rng.uniform()));
                    let etap = if wo.z > 0.0 { eta } else { 1.0 / eta };
                    let wo_m = wo.dot(m);
                    let n = if wo_m > 0.0 { m } else { -m };
                    let Some(wi) = fresnel::refract(wo, n, etap) else {
                        continue;
                    };
                    if wi.z * wo.z >= 0.0 || wi.z.abs() < 0.05 {
                        continue;
                    }
                    let t = 1.0 - fresnel::dielectric(wo_m, eta);
                    for mode in [TransportMode::Radiance, TransportMode::Importance] {
                        let from_m = refracted_value(&d, m, wo, wi, t, etap, mode);
                        let evaluated = dielectric_eval(&d, eta, wo, wi, mode);
                        assert!(
                            (from_m - evaluated).abs() <= 1e-3 * evaluated.abs() + 1e-6,
                            "alpha ({alpha_x}, {alpha_y}) eta {eta} wo {wo} wi {wi}: \
                             {from_m} against {evaluated}"
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
    }
}
