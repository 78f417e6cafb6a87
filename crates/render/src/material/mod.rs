//! Materials and their BSDFs, evaluated in the local shading frame (normal = +z).
//!
//! The set is closed — Lambertian diffuse, perfect mirror, smooth conductor, smooth
//! dielectric, rough (microfacet) conductor and dielectric, thin dielectric, diffuse
//! transmission — so it is one enum with `match`. (pbrt-v4's `mix` is not a BSDF but a
//! choice between two materials per hit; the world resolves it, see
//! `World::material_at`.) All are two-sided: a diffuse surface reflects on both sides, a dielectric
//! knows which side it is entered from.

pub mod fresnel;
pub mod layered;
pub mod microfacet;
pub mod rough;
pub mod thin;

pub use layered::{CoatPart, Layered};
pub use microfacet::TrowbridgeReitz;
pub use rough::ConductorFresnel;

use glam::{Vec2, Vec3};

use radiant_math::color::Rgb;
use radiant_math::{INV_PI, sampling};
use radiant_scene::{ConductorDesc, MaterialDesc};

/// What a path carries: radiance (camera paths) or importance (light/photon paths).
/// Refraction scales radiance by 1/eta^2 but not importance (Veach 1997, §5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    Radiance,
    Importance,
}

/// Microfacet roughness below which a lobe is too narrow for a photon density estimate
/// (see [`Material::passes_photon_paths`] and [`Material::narrow_coat`]). At α = 0.2 the
/// Trowbridge–Reitz peak 1 / (π α²) is 25 times the Lambertian 1 / π. Chosen by SPPM's
/// error on the real scenes (relMSE at 16 iterations against pbrt-v4, threshold 0.1 →
/// 0.2 → 0.3): a gold of α = 0.1 seen in a varnish made the fireflies of Bitterli's
/// dining-room (0.177 → 0.096 → 0.098), a coat of α = 0.14 those of pbrt-v4's
/// killeroo-coated-gold (0.286 → 0.037 → 0.037); killeroo-simple, whose coats of 0.16
/// and 0.39 straddle the threshold, stays at 0.0016 to 0.0017.
pub const NARROW_LOBE_ALPHA: f32 = 0.2;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian: f = albedo / pi.
    Diffuse { albedo: Rgb },
    /// Perfect specular reflector with a fixed reflectance (no Fresnel).
    Mirror { reflectance: Rgb },
    /// Smooth conductor with Fresnel reflectance from complex index eta + i k.
    Conductor { eta: Rgb, k: Rgb },
    /// Smooth dielectric, index `eta` inside relative to outside (normal side).
    Dielectric { eta: f32 },
    /// Microfacet conductor (Trowbridge–Reitz), never effectively smooth.
    RoughConductor {
        fresnel: ConductorFresnel,
        distribution: TrowbridgeReitz,
    },
    /// Microfacet dielectric (Trowbridge–Reitz), `eta` as for `Dielectric`.
    RoughDielectric {
        eta: f32,
        distribution: TrowbridgeReitz,
    },
    /// A thin dielectric sheet (pbrt-v4's `thindielectric`): a delta BSDF that
    /// reflects with the sheet's total reflectance R' over its internal bounces and
    /// transmits straight through (no refraction, no η² scaling).
    ThinDielectric { eta: f32 },
    /// Lambertian reflection (`reflectance`/π on the side of `wo`) and Lambertian
    /// transmission (`transmittance`/π on the other side).
    DiffuseTransmission {
        reflectance: Rgb,
        transmittance: Rgb,
    },
    /// A dielectric coat over a Lambertian base (`layers.base` is
    /// `layered::Base::Diffuse`), evaluated stochastically.
    CoatedDiffuse { layers: Layered },
    /// A dielectric coat over a conductor (`layered::Base::Conductor`).
    CoatedConductor { layers: Layered },
    /// No surface: paths continue straight through.
    Interface,
}

/// The part of a BSDF that a photon estimate weighs with (see
/// [`Material::narrow_coat`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BsdfPart {
    #[default]
    Whole,
    /// Without a coat's direct reflection: the light that enters the layers and leaves
    /// them again. The whole BSDF of an uncoated material.
    UnderCoat,
}

/// A sampled direction with its BSDF value and pdf. For specular lobes `pdf` is the
/// discrete probability of the lobe and `f` carries a matching 1/|cos| factor, so that
/// `f |cos| / pdf` is the path weight in every case.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub f: Rgb,
    pub pdf: f32,
    pub specular: bool,
}

/// `desc` as an RGB renderer must take it to agree with spectral transport where a
/// reflectance enters non-linearly: a coated diffuse base by
/// [`layered::spectrally_matched_base`]; every other material as it is. For materials
/// given by constants (textured ones are evaluated per hit, uncorrected).
pub fn spectrally_matched(desc: &MaterialDesc) -> MaterialDesc {
    match desc {
        MaterialDesc::CoatedDiffuse { reflectance, coat } => MaterialDesc::CoatedDiffuse {
            reflectance: layered::spectrally_matched_base(*reflectance, coat.eta),
            coat: *coat,
        },
        d => d.clone(),
    }
}

impl Material {
    pub fn from_desc(desc: &MaterialDesc) -> Material {
        match desc {
            MaterialDesc::Diffuse { reflectance } => Material::Diffuse {
                albedo: reflectance.map(|c| c.clamp(0.0, 1.0)),
            },
            MaterialDesc::Dielectric { eta } => Material::Dielectric { eta: *eta },
            MaterialDesc::Conductor(ConductorDesc::Reflectance(r)) => Material::Mirror {
                reflectance: r.map(|c| c.clamp(0.0, 1.0)),
            },
            MaterialDesc::Conductor(ConductorDesc::EtaK { eta, k }) => {
                Material::Conductor { eta: *eta, k: *k }
            }
            MaterialDesc::RoughDielectric {
                eta,
                alpha_u,
                alpha_v,
            } => {
                let distribution = TrowbridgeReitz::new(*alpha_u, *alpha_v);
                if distribution.effectively_smooth() {
                    Material::Dielectric { eta: *eta }
                } else {
                    Material::RoughDielectric {
                        eta: *eta,
                        distribution,
                    }
                }
            }
            MaterialDesc::RoughConductor {
                conductor,
                alpha_u,
                alpha_v,
            } => {
                let distribution = TrowbridgeReitz::new(*alpha_u, *alpha_v);
                if distribution.effectively_smooth() {
                    return Material::from_desc(&MaterialDesc::Conductor(conductor.clone()));
                }
                let fresnel = match conductor {
                    ConductorDesc::Reflectance(r) => ConductorFresnel::from_reflectance(*r),
                    ConductorDesc::EtaK { eta, k } => {
                        ConductorFresnel::Complex { eta: *eta, k: *k }
                    }
                };
                Material::RoughConductor {
                    fresnel,
                    distribution,
                }
            }
            MaterialDesc::ThinDielectric { eta } => Material::ThinDielectric { eta: *eta },
            MaterialDesc::DiffuseTransmission {
                reflectance,
                transmittance,
            } => Material::DiffuseTransmission {
                reflectance: reflectance.map(|c| c.clamp(0.0, 1.0)),
                transmittance: transmittance.map(|c| c.clamp(0.0, 1.0)),
            },
            MaterialDesc::CoatedDiffuse { reflectance, coat } => Material::CoatedDiffuse {
                layers: layered::coated_diffuse(*reflectance, coat),
            },
            MaterialDesc::CoatedConductor {
                conductor,
                alpha_u,
                alpha_v,
                coat,
            } => Material::CoatedConductor {
                layers: layered::coated_conductor(conductor, *alpha_u, *alpha_v, coat),
            },
            MaterialDesc::Interface => Material::Interface,
            // The world resolves a mix to one of its two materials per hit; its own
            // table entry is never shaded.
            MaterialDesc::Mix { .. } => Material::Interface,
            // Without the textures: each texture read as a mid value (the world
            // evaluates them per hit instead).
            MaterialDesc::Textured(t) => crate::texture::concrete_material(
                t,
                |p| p.constant().unwrap_or(0.0),
                |p| p.constant().unwrap_or(Rgb::splat(0.5)),
            ),
        }
    }

    /// True when [`Material::sample`] reads its lobe-choice number `u1`. Callers that
    /// draw it from a sampler can skip computing it otherwise (the dimension is still
    /// consumed, so the numbers that follow do not depend on the material).
    pub fn uses_lobe_sample(&self) -> bool {
        match self {
            Material::Dielectric { .. }
            | Material::RoughDielectric { .. }
            | Material::ThinDielectric { .. }
            | Material::DiffuseTransmission { .. }
            | Material::CoatedDiffuse { .. }
            | Material::CoatedConductor { .. } => true,
            Material::Diffuse { .. }
            | Material::Mirror { .. }
            | Material::Conductor { .. }
            | Material::RoughConductor { .. }
            | Material::Interface => false,
        }
    }

    /// True when the BSDF is a Dirac distribution (no evaluation, only sampling).
    pub fn is_specular(&self) -> bool {
        if let Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers } = self {
            return layers.is_delta();
        }
        !matches!(
            self,
            Material::Diffuse { .. }
                | Material::RoughConductor { .. }
                | Material::RoughDielectric { .. }
                | Material::DiffuseTransmission { .. }
        )
    }

    /// True when the microfacet roughness differs along the two tangent axes, so that
    /// the shading frame must follow the surface's ∂p/∂u.
    pub fn is_anisotropic(&self) -> bool {
        match self {
            Material::RoughConductor { distribution, .. }
            | Material::RoughDielectric { distribution, .. } => {
                distribution.alpha_x != distribution.alpha_y
            }
            Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers } => {
                layers.is_anisotropic()
            }
            _ => false,
        }
    }

    /// True where the photon integrators (photon map, SPPM) treat the surface like a
    /// specular one: camera paths continue through it by sampling its BSDF and photons
    /// are not stored on it. That is every delta BSDF, the rough dielectric, whose
    /// transmitted light a density estimate on the reflecting side could not gather,
    /// and conductors too smooth for one ([`NARROW_LOBE_ALPHA`]): the estimate weighs
    /// each photon by the BSDF, about 1 / (π α²) at the lobe's peak, so a few photons
    /// near the mirror direction made fireflies (pbrt-v4's killeroo-gold, α = 0.045:
    /// SPPM's relMSE ten times the path tracer's). Highly glossy reflection is left to
    /// ray tracing, as Jensen does ("Realistic Image Synthesis Using Photon Mapping",
    /// 2001, ch. 9). Broader conductors keep photons and visible points, the BSDF
    /// evaluated in the estimate (as in pbrt-v4's SPPM).
    /// A coated surface is passed on when its coat and its base are both that narrow;
    /// see [`Material::narrow_coat`] for a narrow coat over a broad base.
    pub fn passes_photon_paths(&self) -> bool {
        match self {
            Material::RoughDielectric { .. } => true,
            Material::RoughConductor { distribution, .. } => {
                distribution.alpha_x.max(distribution.alpha_y) < NARROW_LOBE_ALPHA
            }
            Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers } => {
                layers.is_delta() || (layers.coat_is_narrow() && layers.base_is_narrow())
            }
            _ => self.is_specular(),
        }
    }

    /// The layers of a surface whose coat is too narrow for a density estimate over a
    /// base that is not (a varnish over a diffuse base): the photon integrators take
    /// its two parts apart ([`Layered::choose_coat_part`]). The coat's reflection goes
    /// on with the camera path, as a polished metal's does; the light under the coat
    /// is gathered from the photons by [`BsdfPart::UnderCoat`]. Gathered with
    /// the whole BSDF, the coat's peak of about 1 / (π α²) turned the few photons that
    /// arrive near its mirror direction into fireflies (Bitterli's coffee, α = 0.001).
    pub fn narrow_coat(&self) -> Option<&Layered> {
        match self {
            Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers }
                if layers.coat_is_narrow() && !self.passes_photon_paths() =>
            {
                Some(layers)
            }
            _ => None,
        }
    }

    /// The BSDF's value is a Monte Carlo estimate (random walks between layers; Guo,
    /// Hašan & Zhao 2018), and dear: photon estimates that would evaluate it for every
    /// photon near a point evaluate it for a sample of them.
    pub fn eval_is_estimated(&self) -> bool {
        matches!(
            self,
            Material::CoatedDiffuse { .. } | Material::CoatedConductor { .. }
        )
    }

    /// [`eval_mode`](Self::eval_mode) of one part of the BSDF.
    pub fn eval_part(&self, part: BsdfPart, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        match (part, self) {
            (
                BsdfPart::UnderCoat,
                Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers },
            ) => layers.eval_under_coat(wo, wi, mode),
            _ => self.eval_mode(wo, wi, mode),
        }
    }

    /// [`sample`](Self::sample) of one part of the BSDF: under a coat, `None` where the
    /// coat reflects.
    pub fn sample_part(
        &self,
        part: BsdfPart,
        wo: Vec3,
        u1: f32,
        u2: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        match (part, self) {
            (
                BsdfPart::UnderCoat,
                Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers },
            ) => layers.sample_under_coat(wo, u1, u2, mode),
            _ => self.sample(wo, u1, u2, mode),
        }
    }

    /// True where a non-delta BSDF transmits: density estimates there take photons
    /// from both sides of the surface.
    pub fn transmits_diffusely(&self) -> bool {
        matches!(self, Material::DiffuseTransmission { .. })
    }

    /// True for the Lambertian material only: what radiosity can mesh and solve.
    pub fn is_diffuse(&self) -> bool {
        matches!(self, Material::Diffuse { .. })
    }

    /// The relative index of a (smooth or rough) dielectric, for tracking the η²
    /// scaling of refracted radiance.
    pub fn dielectric_eta(&self) -> Option<f32> {
        match *self {
            Material::Dielectric { eta } | Material::RoughDielectric { eta, .. } => Some(eta),
            _ => None,
        }
    }

    /// The diffuse reflectance (zero for purely specular materials); radiosity uses
    /// only this part.
    pub fn diffuse_albedo(&self) -> Rgb {
        match self {
            Material::Diffuse { albedo } => *albedo,
            Material::DiffuseTransmission { reflectance, .. } => *reflectance,
            Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers } => {
                layers.diffuse_albedo()
            }
            _ => Rgb::BLACK,
        }
    }

    /// BSDF value for local directions `wo` (towards the viewer) and `wi` (towards the
    /// light), in radiance transport. Specular lobes evaluate to zero.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.eval_mode(wo, wi, TransportMode::Radiance)
    }

    /// [`eval`](Self::eval) for either transport mode (they differ only in the η²
    /// factor of rough transmission).
    pub fn eval_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        match self {
            Material::Diffuse { albedo } if wo.z * wi.z > 0.0 => *albedo * INV_PI,
            Material::RoughConductor {
                fresnel,
                distribution,
            } => rough::conductor_eval(distribution, fresnel, wo, wi),
            Material::RoughDielectric { eta, distribution } => {
                Rgb::splat(rough::dielectric_eval(distribution, *eta, wo, wi, mode))
            }
            Material::DiffuseTransmission {
                reflectance,
                transmittance,
            } => thin::diffuse_transmission_eval(*reflectance, *transmittance, wo, wi),
            Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers } => {
                layers.eval(wo, wi, mode)
            }
            _ => Rgb::BLACK,
        }
    }

    /// Solid-angle pdf with which `sample` picks `wi` (zero for specular lobes).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Material::Diffuse { .. } if wo.z * wi.z > 0.0 => {
                sampling::cosine_hemisphere_pdf(wi.z.abs())
            }
            Material::RoughConductor { distribution, .. } => {
                rough::conductor_pdf(distribution, wo, wi)
            }
            Material::RoughDielectric { eta, distribution } => {
                rough::dielectric_pdf(distribution, *eta, wo, wi)
            }
            Material::DiffuseTransmission {
                reflectance,
                transmittance,
            } => thin::diffuse_transmission_pdf(*reflectance, *transmittance, wo, wi),
            Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers } => {
                layers.pdf(wo, wi)
            }
            _ => 0.0,
        }
    }

    /// Samples an incident direction for outgoing `wo` from a lobe-choice number `u1`
    /// and a 2D number `u2`.
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        match *self {
            Material::Diffuse { albedo } => {
                let mut wi = sampling::cosine_hemisphere(u2);
                if wo.z < 0.0 {
                    wi.z = -wi.z;
                }
                let pdf = sampling::cosine_hemisphere_pdf(wi.z.abs());
                (pdf > 0.0).then_some(BsdfSample {
                    wi,
                    f: albedo * INV_PI,
                    pdf,
                    specular: false,
                })
            }
            Material::Mirror { reflectance } => Some(specular_reflection(wo, reflectance, 1.0)),
            Material::Conductor { eta, k } => Some(specular_reflection(
                wo,
                fresnel::conductor(wo.z, eta, k),
                1.0,
            )),
            Material::Dielectric { eta } => Some(sample_dielectric(wo, eta, u1, mode)),
            Material::RoughConductor {
                fresnel,
                distribution,
            } => rough::conductor_sample(&distribution, &fresnel, wo, u2),
            Material::RoughDielectric { eta, distribution } => {
                rough::dielectric_sample(&distribution, eta, wo, u1, u2, mode)
            }
            Material::ThinDielectric { eta } => Some(thin::thin_dielectric_sample(wo, eta, u1)),
            Material::DiffuseTransmission {
                reflectance,
                transmittance,
            } => thin::diffuse_transmission_sample(reflectance, transmittance, wo, u1, u2),
            Material::CoatedDiffuse { layers } | Material::CoatedConductor { layers } => {
                layers.sample(wo, u1, u2, mode)
            }
            Material::Interface => Some(BsdfSample {
                wi: -wo,
                f: Rgb::splat(1.0 / wo.z.abs()),
                pdf: 1.0,
                specular: true,
            }),
        }
    }
}

fn specular_reflection(wo: Vec3, reflectance: Rgb, pdf: f32) -> BsdfSample {
    let wi = Vec3::new(-wo.x, -wo.y, wo.z);
    BsdfSample {
        wi,
        f: reflectance * (pdf / wi.z.abs()),
        pdf,
        specular: true,
    }
}

/// Smooth dielectric: reflect with probability R (Fresnel), refract otherwise.
fn sample_dielectric(wo: Vec3, eta: f32, u: f32, mode: TransportMode) -> BsdfSample {
    let r = fresnel::dielectric(wo.z, eta);
    if u < r {
        return specular_reflection(wo, Rgb::WHITE, r);
    }
    let t = 1.0 - r;
    // Relative index of the side entered over the side left.
    let (n, eta_rel) = if wo.z > 0.0 {
        (Vec3::Z, eta)
    } else {
        (-Vec3::Z, 1.0 / eta)
    };
    let wi = fresnel::refract(wo, n, eta_rel)
        .expect("total internal reflection has R = 1 and never reaches refraction");
    let mut f = t / wi.z.abs();
    if mode == TransportMode::Radiance {
        f /= eta_rel * eta_rel;
    }
    BsdfSample {
        wi,
        f: Rgb::splat(f),
        pdf: t,
        specular: true,
    }
}

#[cfg(test)]
mod tests;
