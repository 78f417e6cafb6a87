//! Two BSDFs of thin sheets: a thin dielectric (a pane of glass of negligible
//! thickness) and Lambertian diffuse transmission (paper, leaves, lamp shades).
//!
//! Thin dielectric: light entering the sheet bounces between its two parallel faces;
//! summing the geometric series of the internal reflections (each face reflecting R and
//! transmitting T = 1 − R of the light at the angle of incidence) gives the total
//! reflectance R' = R + T² R / (1 − R²) and transmittance T' = 1 − R' (Born & Wolf,
//! §1.6 for the multiple-beam sum; pbrt-v4 book §9.5.3 for its use as a BSDF). The two
//! refractions of a parallel slab cancel, so the transmitted ray leaves along −wo and
//! the radiance is not rescaled by η².
//!
//! Diffuse transmission: f = reflectance/π for `wi` on the side of `wo`,
//! transmittance/π on the other side. Reciprocal, and energy conserving when
//! reflectance + transmittance ≤ 1 per channel.

use glam::{Vec2, Vec3};

use super::{BsdfSample, fresnel};
use radiant_math::color::Rgb;
use radiant_math::{INV_PI, sampling};

/// Total reflectance R' of a thin dielectric sheet at incidence cosine `cos` (either
/// side: the sheet is symmetric).
pub fn thin_dielectric_reflectance(cos: f32, eta: f32) -> f32 {
    let r = fresnel::dielectric(cos.abs(), eta);
    if r >= 1.0 {
        return 1.0;
    }
    let t = 1.0 - r;
    r + t * t * r / (1.0 - r * r)
}

/// Samples reflection with probability R' (mirror direction) or transmission with
/// probability T' = 1 − R' (straight through), so that f |cos| / pdf = 1 in both
/// cases: the sampling is exact.
pub fn thin_dielectric_sample(wo: Vec3, eta: f32, u: f32) -> BsdfSample {
    let r = thin_dielectric_reflectance(wo.z, eta);
    let cos = wo.z.abs();
    if u < r {
        BsdfSample {
            wi: Vec3::new(-wo.x, -wo.y, wo.z),
            f: Rgb::splat(r / cos),
            pdf: r,
            specular: true,
        }
    } else {
        let t = 1.0 - r;
        BsdfSample {
            wi: -wo,
            f: Rgb::splat(t / cos),
            pdf: t,
            specular: true,
        }
    }
}

/// The probabilities of choosing the reflection and the transmission lobe: their
/// largest channels, normalised (zero for a black material).
fn lobe_weights(reflectance: Rgb, transmittance: Rgb) -> (f32, f32) {
    let pr = reflectance.max_component().max(0.0);
    let pt = transmittance.max_component().max(0.0);
    let sum = pr + pt;
    if sum > 0.0 {
        (pr / sum, pt / sum)
    } else {
        (0.0, 0.0)
    }
}

pub fn diffuse_transmission_eval(reflectance: Rgb, transmittance: Rgb, wo: Vec3, wi: Vec3) -> Rgb {
    let c = wo.z * wi.z;
    if c > 0.0 {
        reflectance * INV_PI
    } else if c < 0.0 {
        transmittance * INV_PI
    } else {
        Rgb::BLACK
    }
}

pub fn diffuse_transmission_pdf(reflectance: Rgb, transmittance: Rgb, wo: Vec3, wi: Vec3) -> f32 {
    let (pr, pt) = lobe_weights(reflectance, transmittance);
    let c = wo.z * wi.z;
    let lobe = if c > 0.0 {
        pr
    } else if c < 0.0 {
        pt
    } else {
        return 0.0;
    };
    lobe * sampling::cosine_hemisphere_pdf(wi.z.abs())
}

/// Chooses the lobe by `u` in proportion to the lobes' largest channels, then a
/// cosine-distributed direction on that lobe's side.
pub fn diffuse_transmission_sample(
    reflectance: Rgb,
    transmittance: Rgb,
    wo: Vec3,
    u: f32,
    u2: Vec2,
) -> Option<BsdfSample> {
    let (pr, pt) = lobe_weights(reflectance, transmittance);
    if pr + pt <= 0.0 {
        return None;
    }
    let mut wi = sampling::cosine_hemisphere(u2);
    let (f, lobe) = if u < pr {
        // Same side as wo.
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        (reflectance, pr)
    } else {
        if wo.z > 0.0 {
            wi.z = -wi.z;
        }
        (transmittance, pt)
    };
    let pdf = lobe * sampling::cosine_hemisphere_pdf(wi.z.abs());
    (pdf > 0.0).then_some(BsdfSample {
        wi,
        f: f * INV_PI,
        pdf,
        specular: false,
    })
}
