//! Choosing a light: which one a receiver samples for next-event estimation, and which
//! one emits a photon.
//!
//! A closed set chosen by name, as pbrt-v4's `"string lightsampler"`. Samplers see the
//! receiver (a [`LightSampleContext`]), so that one which prefers the lights that
//! matter to it — a light tree (Conty Estevez & Kulla, "Importance Sampling of Many
//! Lights with Adaptive Tree Splitting", 2018) — fits the same calls. Emission has no
//! receiver: photons leave every light in proportion to its power, whatever the
//! sampler.

use super::{Light, LightSampleContext, LightTree, SceneSphere};
use radiant_math::Distribution1D;

/// The integrator parameter that names the light sampler (`"string lightsampler"`).
pub const LIGHT_SAMPLER_PARAM: &str = "lightsampler";

/// Names of the light samplers radiant has; the first is the default.
pub const LIGHT_SAMPLER_NAMES: [&str; 2] = ["power", "bvh"];

/// pbrt-v4's light samplers that radiant lacks: scenes naming them get the default.
const PBRT_ONLY_NAMES: [&str; 2] = ["uniform", "exhaustive"];

/// A light and the probability of having chosen it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledLight {
    pub index: usize,
    pub pmf: f32,
}

#[derive(Clone, Debug)]
pub enum LightSampler {
    /// In proportion to the lights' emitted power, the same for every receiver.
    Power { distribution: Distribution1D },
    /// By a light tree's estimate of each light's contribution at the receiver
    /// (pbrt-v4's `"bvh"`); photons still leave in proportion to power.
    Tree {
        tree: Box<LightTree>,
        emission: Distribution1D,
    },
}

/// A light sampler's name that is neither radiant's nor pbrt-v4's.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown light sampler \"{0}\" (radiant has: {names})", names = LIGHT_SAMPLER_NAMES.join(", "))]
pub struct UnknownLightSampler(pub String);

impl LightSampler {
    /// Chooses lights in proportion to their power (the average over the channels).
    pub fn power(lights: &[Light], scene: SceneSphere) -> LightSampler {
        let powers: Vec<f32> = lights.iter().map(|l| l.power(scene).average()).collect();
        LightSampler::Power {
            distribution: Distribution1D::new(&powers),
        }
    }

    /// Chooses lights by a light tree.
    pub fn tree(lights: &[Light], scene: SceneSphere) -> LightSampler {
        let LightSampler::Power { distribution } = LightSampler::power(lights, scene) else {
            unreachable!("the power sampler")
        };
        LightSampler::Tree {
            tree: Box::new(LightTree::new(lights, scene)),
            emission: distribution,
        }
    }

    /// The sampler called `name`, and whether it stands in for one of pbrt-v4's that
    /// radiant does not have (the caller warns).
    pub fn by_name(
        name: &str,
        lights: &[Light],
        scene: SceneSphere,
    ) -> Result<(LightSampler, bool), UnknownLightSampler> {
        match name {
            "power" => Ok((LightSampler::power(lights, scene), false)),
            "bvh" => Ok((LightSampler::tree(lights, scene), false)),
            other if PBRT_ONLY_NAMES.contains(&other) => {
                Ok((LightSampler::power(lights, scene), true))
            }
            other => Err(UnknownLightSampler(other.to_string())),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            LightSampler::Power { .. } => "power",
            LightSampler::Tree { .. } => "bvh",
        }
    }

    /// Picks a light for the receiver `ctx`; `None` when there are none.
    #[inline]
    pub fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        match self {
            LightSampler::Power { distribution } => sample_distribution(distribution, u),
            LightSampler::Tree { tree, .. } => tree.sample(ctx, u),
        }
    }

    /// Whether [`sample`](Self::sample) reads its number: not with one light or none,
    /// which is always the choice (or no choice).
    pub fn uses_choice_sample(&self) -> bool {
        let count = match self {
            LightSampler::Power { distribution } => distribution.len(),
            LightSampler::Tree { emission, .. } => emission.len(),
        };
        count > 1
    }

    /// Probability that `sample` from `ctx` picks light `index`.
    pub fn pmf(&self, ctx: &LightSampleContext, index: usize) -> f32 {
        match self {
            LightSampler::Power { distribution } => distribution.pmf(index),
            LightSampler::Tree { tree, .. } => tree.pmf(ctx, index),
        }
    }

    /// Picks the light that emits a photon, in proportion to power.
    pub fn sample_emission_light(&self, u: f32) -> Option<SampledLight> {
        match self {
            LightSampler::Power { distribution }
            | LightSampler::Tree {
                emission: distribution,
                ..
            } => sample_distribution(distribution, u),
        }
    }
}

fn sample_distribution(distribution: &Distribution1D, u: f32) -> Option<SampledLight> {
    let (index, pmf) = match distribution.len() {
        0 => return None,
        // One light (a single-emitter scene): no search, what the search would find.
        1 => (0, distribution.pmf(0)),
        _ => {
            let (index, pmf, _) = distribution.sample(u);
            (index, pmf)
        }
    };
    (pmf > 0.0).then_some(SampledLight { index, pmf })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::LightSampleContext;
    use glam::Vec3;
    use radiant_math::color::Rgb;

    fn point(intensity: f32) -> Light {
        Light::Point {
            position: Vec3::ZERO,
            intensity: Rgb::splat(intensity),
        }
    }

    const SCENE: SceneSphere = SceneSphere {
        center: Vec3::ZERO,
        radius: 1.0,
    };

    #[test]
    fn power_sampler_picks_lights_in_proportion_to_power_for_any_receiver() {
        let lights = [point(1.0), point(0.0), point(3.0)];
        let sampler = LightSampler::power(&lights, SCENE);
        let ctx = LightSampleContext::at_point(Vec3::ONE);
        let n = 40_000;
        let mut counts = [0u32; 3];
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let s = sampler.sample(&ctx, u).expect("lights exist");
            assert_eq!(s.pmf, sampler.pmf(&ctx, s.index));
            assert_eq!(Some(s), sampler.sample_emission_light(u));
            counts[s.index] += 1;
        }
        assert_eq!(counts, [10_000, 0, 30_000]);
        assert_eq!(sampler.pmf(&ctx, 2), 0.75);
    }

    #[test]
    fn no_lights_no_sample() {
        let sampler = LightSampler::power(&[], SCENE);
        let ctx = LightSampleContext::at_point(Vec3::ZERO);
        assert_eq!(sampler.sample(&ctx, 0.5), None);
        assert_eq!(sampler.sample_emission_light(0.5), None);
    }

    #[test]
    fn names_choose_samplers() {
        let lights = [point(1.0)];
        let (s, stand_in) = LightSampler::by_name("power", &lights, SCENE).unwrap();
        assert_eq!((s.name(), stand_in), ("power", false));
        let (s, stand_in) = LightSampler::by_name("bvh", &lights, SCENE).unwrap();
        assert_eq!((s.name(), stand_in), ("bvh", false));
        let (s, stand_in) = LightSampler::by_name("uniform", &lights, SCENE).unwrap();
        assert_eq!((s.name(), stand_in), ("power", true));
        let e = LightSampler::by_name("tree", &lights, SCENE).unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown light sampler \"tree\" (radiant has: power, bvh)"
        );
    }
}
