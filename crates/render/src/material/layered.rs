//! Layered BSDFs: a dielectric coat (smooth or Trowbridge–Reitz) over an opaque base
//! (Lambertian, or a smooth or rough conductor), with a slab of homogeneous medium
//! between them (extinction 1 per unit thickness, single-scattering `albedo`,
//! Henyey–Greenstein phase function with asymmetry `g`). These are pbrt-v4's
//! `coateddiffuse` and `coatedconductor` (Pharr, Jakob & Humphreys, *Physically Based
//! Rendering*, 4th ed., §14.3, for the parameters' meaning).
//!
//! The slab is infinitely wide and its interfaces parallel, so the lateral position of
//! a path inside it does not matter: only directions and depth do. Guo, Hašan & Zhao
//! 2018, "Position-free Monte Carlo simulation for arbitrary layered BSDFs" (ACM TOG
//! 37(6)), evaluate such a BSDF by a random walk in depth and direction, connecting
//! every vertex of the walk to the fixed exit direction by next-event estimation
//! through the coat, combined with the walk's own chance of leaving in that direction
//! by multiple importance sampling (power heuristic). Everything here is built on that
//! idea:
//!
//! - [`Layered::sample`] walks from `wo`: the coat reflects or refracts (its own
//!   sampler), the medium scatters after an exponential free flight, the base reflects,
//!   until the walk leaves through the coat or `max_depth` events have passed (then it
//!   yields no sample: the truncation is the only loss beyond absorption). Its weight
//!   f |cos| / pdf is the product of the events' weights, exact for that path.
//! - [`Layered::eval`] is an unbiased estimate of the BSDF that this truncated walk
//!   transports: the coat's direct reflection plus `samples` walks with next-event
//!   estimation, averaged.
//! - [`Layered::pdf`] is an unbiased estimate of the density with which `sample`
//!   returns a direction: the same walk with every event's value f |cos| replaced by
//!   its sampling density, so that the sampled directions follow it in expectation
//!   (the chi-square tests rely on this).
//!
//! The random numbers of `eval` and `pdf` come from a generator seeded by a hash of
//! (wo, wi), those of `sample` from (wo, u1, u2): the same query gives the same value
//! on every thread, and `sample` reports the pdf that `pdf` gives for its direction,
//! so the path tracer's MIS weights of the two strategies still sum to one.
//!
//! Conventions: local frame with the coat's outside at +z; both sides are coated
//! (a pair below the surface is mirrored above it); the base is opaque, so a pair on
//! opposite sides has f = 0. Inside the slab `w` is the direction of propagation.

use glam::{Vec2, Vec3};

use super::fresnel;
use super::microfacet::{TrowbridgeReitz, reflect};
use super::rough::{self, ConductorFresnel};
use super::{BsdfSample, NARROW_LOBE_ALPHA, TransportMode};
use radiant_math::color::Rgb;
use radiant_math::hash::{Pcg32, hash_u64s};
use radiant_math::sampling::{self, power_heuristic};
use radiant_math::{Frame, INV_PI};
use radiant_scene::reflectance_spectrum::SmoothReflectance;
use radiant_scene::{CoatDesc, ConductorDesc};

/// The dielectric coat: relative index `eta` (coat over outside) and its microfacet
/// distribution, `None` when smooth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coat {
    pub eta: f32,
    pub distribution: Option<TrowbridgeReitz>,
}

/// The opaque base under the coat.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Base {
    Diffuse {
        reflectance: Rgb,
    },
    /// A conductor whose Fresnel term is relative to the coat's medium;
    /// `distribution` `None` for a smooth one.
    Conductor {
        fresnel: ConductorFresnel,
        distribution: Option<TrowbridgeReitz>,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layered {
    pub coat: Coat,
    pub base: Base,
    /// Slab thickness in units of the medium's mean free path (extinction 1).
    pub thickness: f32,
    /// Single-scattering albedo of the medium; zero: it only absorbs.
    pub albedo: Rgb,
    /// Henyey–Greenstein asymmetry in (-1, 1).
    pub g: f32,
    /// Scattering events a walk may take inside the slab.
    pub max_depth: u16,
    /// Walks averaged per `eval` and `pdf`.
    pub samples: u16,
}

/// The part of a coated surface a camera path goes on with
/// ([`Layered::choose_coat_part`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoatPart {
    /// The coat's own reflection into `wi` (local frame); `weight` is f |cos| / pdf
    /// over the choice's probability.
    Reflection { wi: Vec3, weight: f32 },
    /// The light under the coat ([`Layered::eval_under_coat`]), weighted by one over
    /// the choice's probability.
    Under { weight: f32 },
}

/// What a walk estimates: the BSDF value for a transport mode, or the density of
/// [`Layered::sample`]'s directions.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Quantity {
    Value(TransportMode),
    Density,
}

/// Generator streams of the three uses, so that they never share numbers.
const EVAL_STREAM: u64 = 0x1a7e_5ed0;
const PDF_STREAM: u64 = 0x1a7e_5ed1;
const SAMPLE_STREAM: u64 = 0x1a7e_5ed2;

fn adjoint(mode: TransportMode) -> TransportMode {
    match mode {
        TransportMode::Radiance => TransportMode::Importance,
        TransportMode::Importance => TransportMode::Radiance,
    }
}

fn generator(a: Vec3, b: Vec3, stream: u64) -> Pcg32 {
    let bits = |v: Vec3| {
        [
            (v.x.to_bits() as u64) | ((v.y.to_bits() as u64) << 32),
            v.z.to_bits() as u64,
        ]
    };
    let [a0, a1] = bits(a);
    let [b0, b1] = bits(b);
    Pcg32::new(hash_u64s(&[a0, a1, b0, b1]), stream)
}

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

fn mirror(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// Transmittance of a straight flight through depth `dz` along `w` (extinction 1).
fn transmittance(dz: f32, w: Vec3) -> f32 {
    if w.z == 0.0 {
        return 0.0;
    }
    (-(dz / w.z).abs()).exp()
}

/// Henyey–Greenstein phase function of the angle between the propagation directions
/// before and after scattering (Henyey & Greenstein 1941).
fn henyey_greenstein(g: f32, cos: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) * INV_PI / (4.0 * d * d.max(1e-12).sqrt())
}

/// Samples a new propagation direction around `w` by inverting the HG cumulative
/// distribution in cos θ; returns it with its density.
fn sample_henyey_greenstein(g: f32, w: Vec3, u: Vec2) -> (Vec3, f32) {
    let cos = if g.abs() < 1e-3 {
        1.0 - 2.0 * u.x
    } else {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
        (1.0 + g * g - s * s) / (2.0 * g)
    }
    .clamp(-1.0, 1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u.y;
    let local = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
    let out = Frame::from_normal(w).to_world(local).normalize();
    (out, henyey_greenstein(g, cos))
}

/// A transmission through the coat sampled with its microfacet (or smooth) refraction
/// alone, the Fresnel choice left out.
#[derive(Clone, Copy, Debug)]
struct Transmission {
    /// The refracted direction (away from the coat, on the other side).
    w: Vec3,
    /// Density of this restricted sampler (1 for a smooth coat, where it is a delta).
    pdf: f32,
    /// f / pdf, no cosine (a smooth coat's f carries 1/|cos|).
    f_over_pdf: f32,
    /// 1 - F: the chance that the coat's own sampler refracts here.
    transmit: f32,
    /// Index on the side of `w` over the side sampled from.
    etap: f32,
}

/// A reflection off the coat sampled with the microfacet (or mirror) alone.
#[derive(Clone, Copy, Debug)]
struct Reflection {
    w: Vec3,
    /// f |cos| / pdf of this restricted sampler.
    weight: f32,
    /// F: the chance that the coat's own sampler reflects here.
    reflect: f32,
}

impl Coat {
    fn radiance_scale(etap: f32, mode: TransportMode) -> f32 {
        match mode {
            TransportMode::Radiance => 1.0 / (etap * etap),
            TransportMode::Importance => 1.0,
        }
    }

    /// The coat's own sampler (reflection with probability F, else refraction):
    /// direction, weight f |cos| / pdf, pdf, and whether it was a delta.
    fn sample(
        &self,
        a: Vec3,
        u1: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<(Vec3, f32, f32, bool)> {
        match &self.distribution {
            None => {
                let r = fresnel::dielectric(a.z, self.eta);
                if u1 < r {
                    return Some((mirror(a), 1.0, r, true));
                }
                let (n, etap) = if a.z > 0.0 {
                    (Vec3::Z, self.eta)
                } else {
                    (-Vec3::Z, 1.0 / self.eta)
                };
                let b = fresnel::refract(a, n, etap)?;
                Some((b, Self::radiance_scale(etap, mode), 1.0 - r, true))
            }
            Some(d) => {
                let bs = rough::dielectric_sample(d, self.eta, a, u1, u, mode)?;
                let weight = bs.f.g * bs.wi.z.abs() / bs.pdf;
                weight.is_finite().then_some((bs.wi, weight, bs.pdf, false))
            }
        }
    }

    /// Refraction through the coat from `a`, the Fresnel choice left out.
    fn transmit(&self, a: Vec3, u: Vec2, mode: TransportMode) -> Option<Transmission> {
        let etap = if a.z > 0.0 { self.eta } else { 1.0 / self.eta };
        match &self.distribution {
            None => {
                let r = fresnel::dielectric(a.z, self.eta);
                let n = if a.z > 0.0 { Vec3::Z } else { -Vec3::Z };
                let w = fresnel::refract(a, n, etap)?;
                let t = 1.0 - r;
                (t > 0.0 && w.z != 0.0).then(|| Transmission {
                    w,
                    pdf: 1.0,
                    f_over_pdf: t * Self::radiance_scale(etap, mode) / w.z.abs(),
                    transmit: t,
                    etap,
                })
            }
            Some(d) => {
                let m = d.sample_visible(a, u);
                let a_m = a.dot(m);
                let n = if a_m > 0.0 { m } else { -m };
                let w = fresnel::refract(a, n, etap)?;
                if w.z * a.z >= 0.0 {
                    return None;
                }
                let w_m = w.dot(m);
                let s = w_m + a_m / etap;
                let pdf = d.d_visible(a, m) * w_m.abs() / (s * s);
                let t = 1.0 - fresnel::dielectric(a_m, self.eta);
                let f = rough::refracted_value(d, m, a, w, t, etap, mode);
                (pdf > 0.0 && pdf.is_finite() && f.is_finite()).then(|| Transmission {
                    w,
                    pdf,
                    f_over_pdf: f / pdf,
                    transmit: t,
                    etap,
                })
            }
        }
    }

    /// Light leaving the layer through the coat from inside along `a` (pointing down,
    /// as the BSDF's argument) towards `wi` outside: the coat's value from `a` to `wi`
    /// (for `Quantity::Density`, its own sampler's density), and the density with
    /// which [`transmit`](Self::transmit) from `wi` refracts into `a`, for the MIS
    /// weight. Both refract through the same microfacet, the generalized half vector
    /// of the pair (Walter et al. 2007, eq. 16), found once; zero for a smooth coat.
    fn exit_through(&self, a: Vec3, wi: Vec3, q: Quantity) -> (f32, f32) {
        let Some(d) = &self.distribution else {
            return (0.0, 0.0);
        };
        if a.z * wi.z >= 0.0 {
            // Not a refraction: what the coat reflects, and nothing `transmit` makes.
            let value = match q {
                Quantity::Value(mode) => rough::dielectric_eval(d, self.eta, a, wi, mode),
                Quantity::Density => rough::dielectric_pdf(d, self.eta, a, wi),
            };
            return (value, 0.0);
        }
        // Relative indices seen from each side: `wi`'s (for `transmit` from it) and
        // `a`'s (for the coat's value from it).
        let etap = if wi.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let etap_a = if a.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let Some(m) = (wi + etap * a).try_normalize() else {
            return (0.0, 0.0);
        };
        let m = if m.z < 0.0 { -m } else { m };
        let (wi_m, a_m) = (wi.dot(m), a.dot(m));
        if wi_m * wi.z <= 0.0 || a_m * a.z <= 0.0 {
            return (0.0, 0.0);
        }
        let s = a_m + wi_m / etap;
        let transmit_pdf = d.d_visible(wi, m) * a_m.abs() / (s * s);
        let t = 1.0 - fresnel::dielectric(a_m, self.eta);
        let value = match q {
            Quantity::Value(mode) => rough::refracted_value(d, m, a, wi, t, etap_a, mode),
            Quantity::Density => {
                let s_a = wi_m + a_m / etap_a;
                d.d_visible(a, m) * t * wi_m.abs() / (s_a * s_a)
            }
        };
        (value, transmit_pdf)
    }

    /// Reflection off the coat from `a`, the Fresnel choice left out.
    fn reflect(&self, a: Vec3, u: Vec2) -> Option<Reflection> {
        match &self.distribution {
            None => {
                let r = fresnel::dielectric(a.z, self.eta);
                Some(Reflection {
                    w: mirror(a),
                    weight: r,
                    reflect: r,
                })
            }
            Some(d) => {
                let m = d.sample_visible(a, u);
                let w = reflect(a, m);
                if w.z * a.z <= 0.0 {
                    return None;
                }
                let r = fresnel::dielectric(a.dot(m), self.eta);
                // f |cos| / pdf with pdf = D_a(m) / (4 |a·m|): F G2 / G1(a).
                let weight = r * d.g(a, w) / d.g1(a);
                weight.is_finite().then_some(Reflection {
                    w,
                    weight,
                    reflect: r,
                })
            }
        }
    }

    /// The coat's BSDF value (zero for a smooth coat).
    fn f(&self, a: Vec3, b: Vec3, mode: TransportMode) -> f32 {
        self.distribution
            .as_ref()
            .map_or(0.0, |d| rough::dielectric_eval(d, self.eta, a, b, mode))
    }

    /// The density of the coat's own sampler (zero for a smooth coat).
    fn pdf(&self, a: Vec3, b: Vec3) -> f32 {
        self.distribution
            .as_ref()
            .map_or(0.0, |d| rough::dielectric_pdf(d, self.eta, a, b))
    }
}

impl Base {
    fn is_delta(&self) -> bool {
        matches!(
            self,
            Base::Conductor {
                distribution: None,
                ..
            }
        )
    }

    /// Samples the base from `a` (z > 0): direction, weight f |cos| / pdf, pdf.
    fn sample(&self, a: Vec3, u: Vec2) -> Option<(Vec3, Rgb, f32)> {
        match self {
            Base::Diffuse { reflectance } => {
                let w = sampling::cosine_hemisphere(u);
                let pdf = sampling::cosine_hemisphere_pdf(w.z);
                (pdf > 0.0).then_some((w, *reflectance, pdf))
            }
            Base::Conductor {
                fresnel,
                distribution: None,
            } => Some((mirror(a), fresnel.eval(a.z), 1.0)),
            Base::Conductor {
                fresnel,
                distribution: Some(d),
            } => {
                let bs = rough::conductor_sample(d, fresnel, a, u)?;
                let weight = bs.f * (bs.wi.z.abs() / bs.pdf);
                weight.is_finite().then_some((bs.wi, weight, bs.pdf))
            }
        }
    }

    fn f(&self, a: Vec3, b: Vec3) -> Rgb {
        match self {
            Base::Diffuse { reflectance } if a.z > 0.0 && b.z > 0.0 => *reflectance * INV_PI,
            Base::Conductor {
                fresnel,
                distribution: Some(d),
            } => rough::conductor_eval(d, fresnel, a, b),
            _ => Rgb::BLACK,
        }
    }

    fn pdf(&self, a: Vec3, b: Vec3) -> f32 {
        match self {
            Base::Diffuse { .. } if a.z > 0.0 && b.z > 0.0 => sampling::cosine_hemisphere_pdf(b.z),
            Base::Conductor {
                distribution: Some(d),
                ..
            } => rough::conductor_pdf(d, a, b),
            _ => 0.0,
        }
    }
}

impl Layered {
    fn has_medium(&self) -> bool {
        self.albedo.max_component() > 0.0
    }

    /// True when the coat's or the base's roughness differs along the two tangent axes.
    pub fn is_anisotropic(&self) -> bool {
        let anisotropic = |d: &Option<TrowbridgeReitz>| d.is_some_and(|d| d.alpha_x != d.alpha_y);
        let base = match &self.base {
            Base::Diffuse { .. } => false,
            Base::Conductor { distribution, .. } => anisotropic(distribution),
        };
        anisotropic(&self.coat.distribution) || base
    }

    /// True when every path through the layers is a delta: a smooth coat over a
    /// smooth conductor (parallel mirrors reflect only into the mirror direction).
    pub fn is_delta(&self) -> bool {
        self.coat.distribution.is_none() && self.base.is_delta()
    }

    /// True when the coat's lobe is too narrow for a photon density estimate: smooth,
    /// or rough below [`NARROW_LOBE_ALPHA`].
    pub fn coat_is_narrow(&self) -> bool {
        self.coat
            .distribution
            .is_none_or(|d| d.alpha_x.max(d.alpha_y) < NARROW_LOBE_ALPHA)
    }

    /// True when the base's lobe is a delta or too narrow for a density estimate.
    pub fn base_is_narrow(&self) -> bool {
        match &self.base {
            Base::Diffuse { .. } => false,
            Base::Conductor { distribution, .. } => {
                distribution.is_none_or(|d| d.alpha_x.max(d.alpha_y) < NARROW_LOBE_ALPHA)
            }
        }
    }

    /// BSDF value, estimated by `samples` walks (see the module notes).
    pub fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        Rgb::splat(self.coat.f(wo, wi, mode)) + self.eval_walks(wo, wi, mode)
    }

    /// The BSDF without the coat's direct reflection: the light that enters the
    /// layers and leaves them again.
    pub fn eval_under_coat(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        self.eval_walks(wo, wi, mode)
    }

    /// The walks' part of [`eval`](Self::eval), both directions above.
    fn eval_walks(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        if self.is_delta() || self.samples == 0 {
            return Rgb::BLACK;
        }
        let mut rng = generator(wo, wi, EVAL_STREAM);
        let mut sum = Rgb::BLACK;
        for _ in 0..self.samples {
            sum += self.walk(wo, wi, Quantity::Value(mode), &mut rng);
        }
        sum / self.samples as f32
    }

    /// Chooses between the coat's direct reflection and the light under it for a
    /// camera path arriving from `wo`: the reflection with probability F(cos θo), the
    /// smooth coat's Fresnel reflectance (the share of the light the coat reflects),
    /// its direction sampled from the coat alone with `u`. The weights are divided by
    /// the choice's probability, so that either part's estimate stays unbiased.
    pub fn choose_coat_part(&self, wo: Vec3, u1: f32, u: Vec2) -> Option<CoatPart> {
        if wo.z == 0.0 {
            return None;
        }
        let flip = wo.z < 0.0;
        let wo = if flip { -wo } else { wo };
        let p = fresnel::dielectric(wo.z, self.coat.eta).clamp(0.0, 1.0);
        if u1 >= p {
            return (p < 1.0).then(|| CoatPart::Under {
                weight: 1.0 / (1.0 - p),
            });
        }
        let r = self.coat.reflect(wo, u)?;
        let weight = r.weight / p;
        weight.is_finite().then(|| CoatPart::Reflection {
            wi: if flip { -r.w } else { r.w },
            weight,
        })
    }

    /// Density of [`sample`](Self::sample)'s non-delta directions, estimated by
    /// `samples` walks.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let mut p = self.coat.pdf(wo, wi);
        if !self.is_delta() && self.samples > 0 {
            let mut rng = generator(wo, wi, PDF_STREAM);
            let mut sum = 0.0;
            for _ in 0..self.samples {
                sum += self.walk(wo, wi, Quantity::Density, &mut rng).g;
            }
            p += sum / self.samples as f32;
        }
        p
    }

    /// One walk's estimate of the value or density at (wo, wi), both above.
    ///
    /// The walk enters by refraction at the coat (the coat's direct reflection is
    /// added by the caller) and, at every event inside, connects to the exit: through
    /// a direction `up` fixed per walk, refracted from `wi` by the coat's adjoint, and
    /// through the direction the event samples next where that one would leave
    /// through a rough coat; the two are weighted by the power heuristic. Event k of
    /// this walk leaves at event k + 1 of `sample`'s, so it stops one event earlier.
    ///
    /// For the density every event's f |cos| becomes its sampler's density (the
    /// coat's Fresnel choices become probabilities F and 1 - F); absorption, the
    /// medium's albedo and the transport mode's η² do not apply, since `sample` does
    /// not choose by them.
    fn walk(&self, wo: Vec3, wi: Vec3, q: Quantity, rng: &mut Pcg32) -> Rgb {
        let coat = &self.coat;
        let (mode, density) = match q {
            Quantity::Value(mode) => (mode, false),
            Quantity::Density => (TransportMode::Radiance, true),
        };
        let rough_coat = coat.distribution.is_some();
        let medium = self.has_medium();
        let Some(enter) = coat.transmit(wo, u2(rng), mode) else {
            return Rgb::BLACK;
        };
        let Some(exit) = coat.transmit(wi, u2(rng), adjoint(mode)) else {
            return Rgb::BLACK;
        };
        // The exit's weight per unit of what arrives along `up`. Value: by the
        // adjoint, f(exit.w -> wi) / pdf = f_adjoint(wi -> exit.w) / pdf. Density:
        // the coat's chance density of refracting into wi from exit.w, over the
        // density of exit.w; for a smooth coat the ratio of the two deltas is the
        // Jacobian of refraction, dω/dωi = n_i² cos θi / (n² cos θ) (the étendue
        // n² cos θ dω is conserved).
        let exit_weight = if !density {
            exit.f_over_pdf
        } else if let Some(d) = &coat.distribution {
            rough::dielectric_pdf(d, coat.eta, exit.w, wi) / exit.pdf
        } else {
            let t_out = 1.0 - fresnel::dielectric(exit.w.z, coat.eta);
            t_out * wi.z.abs() / (exit.etap * exit.etap * exit.w.z.abs())
        };
        // A straight flight between the interfaces: absorbed light is lost to the
        // value, and with a scattering medium the flight without collision is also
        // what `sample` does with that probability.
        let flight = |dz: f32, w: Vec3| -> f32 {
            if density && !medium {
                1.0
            } else {
                transmittance(dz, w)
            }
        };
        let up = -exit.w;
        let thickness = self.thickness;
        let mut beta = Rgb::splat(if density {
            enter.transmit
        } else {
            enter.f_over_pdf * enter.w.z.abs()
        });
        let mut w = enter.w;
        let mut z = thickness;
        let mut sum = Rgb::BLACK;
        for depth in 0..self.max_depth.saturating_sub(1) {
            // Russian roulette on a faint walk (unbiased: the survivors are reweighted).
            if depth > 3 {
                let m = beta.max_component();
                if m < 0.25 {
                    let q = (1.0 - m).max(0.0);
                    if rng.uniform() < q {
                        break;
                    }
                    beta /= 1.0 - q;
                }
            }
            if beta.is_black() {
                break;
            }
            if medium {
                // Free flight with extinction 1, measured along the depth axis.
                let dz = -(1.0 - rng.uniform()).ln() * w.z.abs();
                let zs = if w.z > 0.0 { z + dz } else { z - dz };
                if zs > 0.0 && zs < thickness {
                    if !density {
                        beta *= self.albedo;
                    }
                    let to_top = thickness - zs;
                    let phase = henyey_greenstein(self.g, w.dot(up));
                    let wt = if rough_coat {
                        power_heuristic(exit.pdf, phase)
                    } else {
                        1.0
                    };
                    sum += beta * (phase * transmittance(to_top, up) * wt * exit_weight);
                    let (next, phase_pdf) = sample_henyey_greenstein(self.g, w, u2(rng));
                    w = next;
                    z = zs;
                    if rough_coat && w.z > 0.0 {
                        let (value, transmit_pdf) = coat.exit_through(-w, wi, q);
                        let wt = power_heuristic(phase_pdf, transmit_pdf);
                        sum += beta * (transmittance(to_top, w) * value * wt);
                    }
                    continue;
                }
            } else if !density {
                beta *= transmittance(thickness, w);
            }
            z = if w.z > 0.0 { thickness } else { 0.0 };
            if z == 0.0 {
                let a = -w;
                if !self.base.is_delta() {
                    let p_base = self.base.pdf(a, up);
                    let fb = if density {
                        Rgb::splat(p_base)
                    } else {
                        self.base.f(a, up) * up.z.abs()
                    };
                    let wt = if rough_coat {
                        power_heuristic(exit.pdf, p_base)
                    } else {
                        1.0
                    };
                    sum += beta * fb * (flight(thickness, up) * wt * exit_weight);
                }
                let Some((next, weight, pdf)) = self.base.sample(a, u2(rng)) else {
                    break;
                };
                if !density {
                    beta *= weight;
                }
                w = next;
                if rough_coat {
                    let (value, transmit_pdf) = coat.exit_through(-w, wi, q);
                    let wt = if self.base.is_delta() {
                        1.0
                    } else {
                        power_heuristic(pdf, transmit_pdf)
                    };
                    sum += beta * (flight(thickness, w) * value * wt);
                }
            } else {
                let Some(r) = coat.reflect(-w, u2(rng)) else {
                    break;
                };
                beta *= if density { r.reflect } else { r.weight };
                w = r.w;
            }
        }
        sum
    }

    /// Samples `wi` by a random walk through the layers (see the module notes).
    pub fn sample(&self, wo: Vec3, u1: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        self.sample_walk(wo, u1, u, mode, true)
    }

    /// [`sample`](Self::sample) with the coat's direct reflection left out: `None`
    /// where the coat reflects, so that the weights of the other samples estimate the
    /// part of the light under the coat ([`eval_under_coat`](Self::eval_under_coat)).
    pub fn sample_under_coat(
        &self,
        wo: Vec3,
        u1: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        self.sample_walk(wo, u1, u, mode, false)
    }

    fn sample_walk(
        &self,
        wo: Vec3,
        u1: f32,
        u: Vec2,
        mode: TransportMode,
        with_coat_reflection: bool,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let flip = wo.z < 0.0;
        let wo = if flip { -wo } else { wo };
        let (mut w, weight, _, mut all_delta) = self.coat.sample(wo, u1, u, mode)?;
        if w.z > 0.0 && !with_coat_reflection {
            return None;
        }
        let mut beta = Rgb::splat(weight);
        let finish = |wi: Vec3, beta: Rgb, all_delta: bool| -> Option<BsdfSample> {
            let cos = wi.z.abs();
            if cos == 0.0 || !beta.is_finite() {
                return None;
            }
            let (f, pdf) = if all_delta {
                (beta / cos, 1.0)
            } else {
                let pdf = self.pdf(wo, wi);
                if !(pdf > 0.0 && pdf.is_finite()) {
                    return None;
                }
                (beta * (pdf / cos), pdf)
            };
            Some(BsdfSample {
                wi: if flip { -wi } else { wi },
                f,
                pdf,
                specular: all_delta,
            })
        };
        if w.z > 0.0 {
            return finish(w, beta, all_delta);
        }
        let mut rng = generator(wo, Vec3::new(u1, u.x, u.y), SAMPLE_STREAM);
        let medium = self.has_medium();
        let thickness = self.thickness;
        let mut z = thickness;
        for _ in 0..self.max_depth {
            if medium {
                let dz = -(1.0 - rng.uniform()).ln() * w.z.abs();
                let zs = if w.z > 0.0 { z + dz } else { z - dz };
                if zs > 0.0 && zs < thickness {
                    beta *= self.albedo;
                    w = sample_henyey_greenstein(self.g, w, u2(&mut rng)).0;
                    z = zs;
                    all_delta = false;
                    continue;
                }
            } else {
                beta *= transmittance(thickness, w);
            }
            z = if w.z > 0.0 { thickness } else { 0.0 };
            if z == 0.0 {
                let (next, weight, _) = self.base.sample(-w, u2(&mut rng))?;
                beta *= weight;
                all_delta &= self.base.is_delta();
                w = next;
            } else {
                let u1 = rng.uniform();
                let (next, weight, _, delta) = self.coat.sample(-w, u1, u2(&mut rng), mode)?;
                beta *= weight;
                all_delta &= delta;
                if next.z > 0.0 {
                    return finish(next, beta, all_delta);
                }
                w = next;
            }
        }
        None
    }

    /// An approximation of the diffuse reflectance for radiosity and the photon
    /// mapper's final gather: for a Lambertian base of reflectance ρ under a smooth
    /// coat, the light that enters at normal incidence (1 - F(0)) and leaves after
    /// any number of diffuse bounces, ρ (1 - F(0)) (1 - r_i) / (1 - ρ r_i), where
    /// r_i is the coat's hemispherical reflectance from inside (the closed form of
    /// the infinite series of internal reflections; Kelemen & Szirmay-Kalos 2001
    /// use the same series for their coated model). The coat's roughness, the
    /// medium and the depth truncation are left out; a conductor base is glossy and
    /// has no diffuse part.
    pub fn diffuse_albedo(&self) -> Rgb {
        let Base::Diffuse { reflectance } = self.base else {
            return Rgb::BLACK;
        };
        let t0 = 1.0 - fresnel::dielectric(1.0, self.coat.eta);
        let r_i = internal_reflectance(self.coat.eta);
        reflectance.map(|rho| rho * t0 * (1.0 - r_i) / (1.0 - rho * r_i))
    }
}

/// The RGB base reflectance under a coat of index `eta` whose light leaves with the
/// colour a spectral renderer gives it. Light under a coat meets the base again and
/// again (internal reflectance r_i): a Lambertian base of spectrum R(λ) sends out
/// R / (1 − R r_i) at each wavelength, and the colour of that is not the same
/// expression of the RGB — for pbrt-v4's smooth spectrum of a saturated orange
/// (1, 0.38, 0.013) the red that leaves is 20 % below the RGB series'. The reflectance
/// returned is the one whose RGB series equals the colour of the spectral one (for the
/// smooth spectrum of Jakob & Hanika 2019 that pbrt-v4 uses, see
/// [`radiant_scene::reflectance_spectrum`]). Greys, and colours no smooth spectrum
/// reaches, are returned as they are. A closed form of the smooth coat: roughness and the medium between are
/// left out of the correction.
pub fn spectrally_matched_base(reflectance: Rgb, eta: f32) -> Rgb {
    let rgb = reflectance.to_array().map(|c| c as f64);
    if (rgb[0] - rgb[1]).abs() < 1e-6 && (rgb[1] - rgb[2]).abs() < 1e-6 {
        return reflectance;
    }
    let Some(spectrum) = SmoothReflectance::fit(rgb) else {
        return reflectance;
    };
    let r_i = internal_reflectance(eta) as f64;
    let series = spectrum.project(|r| r / (1.0 - r * r_i));
    // Inverse of t = r / (1 − r r_i).
    let base = series.map(|t| {
        let t = t.max(0.0);
        (t / (1.0 + t * r_i)).clamp(0.0, 1.0) as f32
    });
    Rgb::from_array(base)
}

/// Hemispherical (cosine-weighted) reflectance of a smooth interface seen from inside
/// a medium of relative index `eta`: ∫ F(−μ) 2μ dμ = ∫ F(−√x) dx over x = μ² in [0, 1],
/// by the midpoint rule (F varies smoothly in x except at the critical angle, where
/// 256 nodes leave an error below 1e-4).
pub fn internal_reflectance(eta: f32) -> f32 {
    const N: usize = 256;
    (0..N)
        .map(|i| fresnel::dielectric(-((i as f32 + 0.5) / N as f32).sqrt(), eta))
        .sum::<f32>()
        / N as f32
}

/// A microfacet distribution, or `None` where it is too narrow to be anything but
/// smooth (the threshold of the single-interface materials).
fn distribution(alpha_u: f32, alpha_v: f32) -> Option<TrowbridgeReitz> {
    let d = TrowbridgeReitz::new(alpha_u, alpha_v);
    (!d.effectively_smooth()).then_some(d)
}

fn from_coat(coat: &CoatDesc, base: Base) -> Layered {
    Layered {
        coat: Coat {
            eta: coat.eta,
            distribution: distribution(coat.alpha_u, coat.alpha_v),
        },
        base,
        // Far below any scene's thickness: the slab stays a slab in f32.
        thickness: coat.thickness.max(1e-7),
        albedo: coat.albedo.map(|c| c.clamp(0.0, 1.0)),
        g: coat.g.clamp(-0.999, 0.999),
        max_depth: coat.max_depth.clamp(1, u16::MAX as u32) as u16,
        samples: coat.samples.clamp(1, u16::MAX as u32) as u16,
    }
}

/// pbrt-v4's `coateddiffuse`.
pub fn coated_diffuse(reflectance: Rgb, coat: &CoatDesc) -> Layered {
    from_coat(
        coat,
        Base::Diffuse {
            reflectance: reflectance.map(|c| c.clamp(0.0, 1.0)),
        },
    )
}

/// pbrt-v4's `coatedconductor`. The conductor lies in the coat's medium, so its
/// Fresnel term takes the index relative to the coat, (eta + i k) / eta_coat; a
/// `reflectance` is first turned into the index of [`ConductorFresnel::from_reflectance`]
/// (as pbrt-v4 reads both).
pub fn coated_conductor(
    conductor: &ConductorDesc,
    alpha_u: f32,
    alpha_v: f32,
    coat: &CoatDesc,
) -> Layered {
    let (eta, k) = match conductor {
        ConductorDesc::EtaK { eta, k } => (*eta, *k),
        ConductorDesc::Reflectance(r) => match ConductorFresnel::from_reflectance(*r) {
            ConductorFresnel::Complex { eta, k } => (eta, k),
            ConductorFresnel::Constant(_) => unreachable!("from_reflectance gives an index"),
        },
    };
    let inv = 1.0 / coat.eta;
    from_coat(
        coat,
        Base::Conductor {
            fresnel: ConductorFresnel::Complex {
                eta: eta * inv,
                k: k * inv,
            },
            distribution: distribution(alpha_u, alpha_v),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;
    use radiant_math::sampling::uniform_sphere;

    /// The exit's two numbers are what the coat's value and density give for the pair
    /// from `a`, and what its density from `wi` gives without the Fresnel choice, to
    /// rounding: from both sides, in both quantities and transport modes.
    #[test]
    fn the_exit_through_the_coat_is_its_value_and_the_transmit_density() {
        let mut rng = Pcg32::new(23, 1);
        let mut direction = || uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        let close = |x: f32, y: f32| (x - y).abs() <= 1e-3 * x.abs().max(y.abs()) + 1e-6;
        let mut refracting = 0;
        for (alpha_x, alpha_y, eta) in [(0.1, 0.1, 1.5), (0.4, 0.15, 1.33), (0.7, 0.7, 2.0)] {
            let d = TrowbridgeReitz::new(alpha_x, alpha_y);
            let coat = Coat {
                eta,
                distribution: Some(d),
            };
            for _ in 0..4000 {
                let (a, wi) = (direction(), direction());
                if a.z.abs() < 0.05 || wi.z.abs() < 0.05 {
                    continue;
                }
                for q in [
                    Quantity::Value(TransportMode::Radiance),
                    Quantity::Value(TransportMode::Importance),
                    Quantity::Density,
                ] {
                    let (value, transmit_pdf) = coat.exit_through(a, wi, q);
                    let expected = match q {
                        Quantity::Value(mode) => rough::dielectric_eval(&d, eta, a, wi, mode),
                        Quantity::Density => rough::dielectric_pdf(&d, eta, a, wi),
                    };
                    assert!(close(value, expected), "{q:?} {a} {wi}: {value} {expected}");
                    if a.z * wi.z >= 0.0 {
                        assert_eq!(transmit_pdf, 0.0);
                        continue;
                    }
                    // The coat's own density from wi, less its choice to refract (1 − F
                    // at the shared microfacet).
                    let etap = if wi.z > 0.0 { eta } else { 1.0 / eta };
                    let m = (wi + etap * a).normalize();
                    let m = if m.z < 0.0 { -m } else { m };
                    let refract = 1.0 - fresnel::dielectric(wi.dot(m), eta);
                    let from_wi = rough::dielectric_pdf(&d, eta, wi, a);
                    if refract > 1e-3 {
                        assert!(
                            close(transmit_pdf * refract, from_wi),
                            "{a} {wi}: {transmit_pdf} × {refract} against {from_wi}"
                        );
                        refracting += (from_wi > 0.0) as u32;
                    }
                }
            }
        }
        assert!(refracting > 3000, "{refracting}");
    }
}
