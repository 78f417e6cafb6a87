//! Fresnel reflectance of smooth interfaces for unpolarised light.

use glam::Vec3;
use radiant_math::color::Rgb;

/// Reflectance of a dielectric interface. `cos_i` is the cosine of the incident
/// direction with the normal (negative when arriving from inside), `eta` the index
/// inside relative to outside. Total internal reflection gives 1.
pub fn dielectric(cos_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Reflectance of a conductor with complex index `eta + i k` (relative to the outside
/// medium), per channel; the exact unpolarised formula for a complex index (Born & Wolf,
/// *Principles of Optics*, §14.2).
pub fn conductor(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    let c = cos_i.abs().min(1.0);
    let channel = |n: f32, k: f32| -> f32 {
        let c2 = c * c;
        let s2 = 1.0 - c2;
        let n2 = n * n;
        let k2 = k * k;
        let t0 = n2 - k2 - s2;
        let a2b2 = (t0 * t0 + 4.0 * n2 * k2).max(0.0).sqrt();
        let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
        let t1 = a2b2 + c2;
        let t2 = 2.0 * c * a;
        let rs = (t1 - t2) / (t1 + t2);
        let t3 = c2 * a2b2 + s2 * s2;
        let t4 = t2 * s2;
        let rp = rs * (t3 - t4) / (t3 + t4);
        (0.5 * (rp + rs)).clamp(0.0, 1.0)
    };
    Rgb::new(
        channel(eta.r, k.r),
        channel(eta.g, k.g),
        channel(eta.b, k.b),
    )
}

/// Refracts `wi` (pointing away from the surface, on the side of `n`) through an
/// interface with relative index `eta` (transmitted side over incident side).
/// Returns `None` on total internal reflection.
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = n.dot(wi);
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(-wi / eta + (cos_i / eta - cos_t) * n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_limits() {
        // Normal incidence: ((n-1)/(n+1))^2 = 0.04 for n = 1.5.
        assert!((dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        // Grazing incidence reflects everything.
        assert!(dielectric(1e-6, 1.5) > 0.999);
        // Beyond the critical angle from inside (sin > 1/1.5): total internal reflection.
        assert_eq!(dielectric(-0.5, 1.5), 1.0);
    }

    #[test]
    fn conductor_with_zero_k_equals_dielectric() {
        for &c in &[1.0, 0.7, 0.3, 0.05] {
            let r = conductor(c, Rgb::splat(1.5), Rgb::BLACK);
            assert!((r.r - dielectric(c, 1.5)).abs() < 1e-5, "cos {c}");
        }
        // Normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2).
        let r = conductor(1.0, Rgb::splat(0.2), Rgb::splat(3.0));
        let e = (0.64 + 9.0) / (1.44 + 9.0);
        assert!((r.g - e).abs() < 1e-5);
    }

    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3::Z;
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let wt = refract(wi, n, 1.5).unwrap();
        assert!((wt.length() - 1.0).abs() < 1e-5);
        assert!((0.6 - 1.5 * wt.x.abs()).abs() < 1e-5 && wt.z < 0.0);
        assert!(refract(Vec3::new(0.8, 0.0, 0.6), n, 1.0 / 1.5).is_none());
    }
}
