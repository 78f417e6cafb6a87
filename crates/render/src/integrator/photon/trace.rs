//! Photon tracing: rays leave the lights, chosen in proportion to their power, and
//! scatter by the same BSDFs as camera paths, in importance mode (Veach 1997, §5.2:
//! refraction does not scale importance by 1/η²) with Veach's adjoint correction for
//! shading normals (ibid., §5.3). Russian roulette keeps the photon's power roughly
//! constant: it survives with probability min(1, max component of f cos / pdf) and is
//! divided by it (Jensen 2001, §5.2, "absorption by Russian roulette").
//!
//! Every photon's random numbers are a pure function of (seed, pass, photon index):
//! photon `i` of a pass is sample `i` of one Owen-scrambled Sobol stream, so the photons
//! of a pass are stratified over light positions and directions. Passes run in
//! fixed-size chunks on rayon and their results are concatenated in chunk order, so
//! everything traced is identical at any thread count.

use glam::Vec3;
use rayon::prelude::*;

use super::projection::ProjectionMaps;
use crate::geometry::Ray;
use crate::material::{Material, TransportMode};
use crate::sampler::PixelSample;
use crate::world::{SurfaceHit, World};
use radiant_math::color::Rgb;
use radiant_math::hash::hash_u64s;
use radiant_scene::SamplerKind;

/// Photons per work item: large enough to amortise scheduling, small enough to balance.
pub const CHUNK: u64 = 4096;

/// Where the random numbers of one photon pass come from.
#[derive(Clone, Copy, Debug)]
pub struct PhotonStream {
    pub kind: SamplerKind,
    pub seed: u64,
    /// Names the pass (global map, caustic map, an SPPM iteration...).
    pub tag: u64,
}

impl PhotonStream {
    /// The stream of a pass named by the integers `pass`.
    pub fn new(kind: SamplerKind, seed: u64, pass: &[u64]) -> PhotonStream {
        PhotonStream {
            kind,
            seed,
            tag: hash_u64s(pass),
        }
    }

    /// The sampler of photon `index` (indices beyond u32 wrap into a new stream).
    pub fn sampler(&self, index: u64) -> PixelSample {
        PixelSample::for_stream(self.kind, self.seed, self.tag ^ (index >> 32), index as u32)
    }
}

/// A photon arriving at a non-specular surface.
#[derive(Clone, Copy, Debug)]
pub struct Landing<'a> {
    pub hit: &'a SurfaceHit,
    /// Unit direction towards where the photon came from.
    pub wi: Vec3,
    /// The photon's power (flux) on arrival.
    pub power: Rgb,
    /// Scattering events since the light (0: direct).
    pub bounces: u32,
    /// Every scattering event so far was specular.
    pub specular_chain: bool,
    /// The first scattering event (at the first hit) was specular.
    pub first_specular: bool,
    /// Earlier landings of this photon: 0 when every surface before this one lets
    /// photons through (`Material::passes_photon_paths`), the surfaces projection
    /// maps aim at.
    pub landings: u32,
}

/// Samples a photon: a light by power (or by the projection maps' power aimed at
/// specular objects), a ray leaving it, and the power the ray carries when `n_total`
/// photons share the light's flux.
pub fn emit(
    world: &World,
    projection: Option<&ProjectionMaps>,
    n_total: f64,
    sampler: &mut PixelSample,
) -> Option<(Ray, Rgb)> {
    if world.lights.is_empty() {
        return None;
    }
    let u_light = sampler.get_1d();
    let u_pos = sampler.get_2d();
    let u_dir = sampler.get_2d();
    let scene = world.scene_sphere();
    let (light, pmf, u_pos, u_dir, fraction) = match projection {
        None => {
            let chosen = world.light_sampler.sample_emission_light(u_light)?;
            (chosen.index, chosen.pmf, u_pos, u_dir, 1.0)
        }
        Some(pm) => {
            let (l, pmf, u_cell) = pm.distribution().sample(u_light);
            let (u_pos, u_dir) = pm.remap(l, u_cell, u_pos, u_dir)?;
            (l, pmf, u_pos, u_dir, pm.fraction(l))
        }
    };
    if pmf <= 0.0 {
        return None;
    }
    let e = world.lights[light].sample_le(u_pos, u_dir, scene)?;
    let power = e.power * (fraction / (pmf as f64 * n_total) as f32);
    (!power.is_black()).then_some((e.ray, power))
}

/// Follows one photon through the scene for at most `max_depth` scattering events.
/// `land` is called at every non-specular hit; it returns false to end the path there.
/// Returns the number of rays traced.
pub fn trace_photon(
    world: &World,
    mut ray: Ray,
    mut power: Rgb,
    max_depth: u32,
    sampler: &mut PixelSample,
    mut land: impl FnMut(&Landing) -> bool,
) -> u32 {
    let mut specular_chain = true;
    let mut first_specular = false;
    let mut landings = 0u32;
    let mut rays = 0u32;
    crate::stats::add(crate::stats::Counter::PhotonPaths, 1);
    for bounces in 0..max_depth {
        rays += 1;
        let Some(hit) = world.intersect(&ray, f32::INFINITY) else {
            break;
        };
        // Importance transport: the BSDF's "outgoing" direction points back along the
        // photon's path, towards the light.
        let wo_world = -ray.d.normalize();
        let material: Material = world.material_at(&hit, wo_world);
        if !material.passes_photon_paths() {
            let landing = Landing {
                hit: &hit,
                wi: wo_world,
                power,
                bounces,
                specular_chain,
                first_specular,
                landings,
            };
            if !land(&landing) {
                break;
            }
            landings += 1;
        }
        let frame = World::shading_frame(&hit, &material);
        let wo = frame.to_local(wo_world);
        let u_lobe = sampler.get_1d_if(material.uses_lobe_sample());
        let u_dir = sampler.get_2d();
        let u_rr = sampler.get_1d();
        let Some(bs) = material.sample(wo, u_lobe, u_dir, TransportMode::Importance) else {
            break;
        };
        let wi_world = frame.to_world(bs.wi);
        let (wo_ng, wi_ng) = (wo_world.dot(hit.ng), wi_world.dot(hit.ng));
        if !bs.specular && (wo_ng * wi_ng > 0.0) != (wo.z * bs.wi.z > 0.0) {
            break;
        }
        let mut weight = bs.f * (bs.wi.z.abs() / bs.pdf);
        // Adjoint BSDF with shading normals: |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|).
        let denom = wo_ng.abs() * bs.wi.z.abs();
        if denom > 0.0 {
            weight *= (wo.z.abs() * wi_ng.abs()) / denom;
        }
        let q = weight.max_component().min(1.0);
        if q.is_nan() || q <= 0.0 || u_rr >= q {
            break;
        }
        power *= weight * (1.0 / q);
        // Rough glass counts as specular here: photons through it are caustics, which
        // camera paths (passing through it too) find only in the caustic map.
        let specular = bs.specular || material.passes_photon_paths();
        specular_chain &= specular;
        if bounces == 0 {
            first_specular = specular;
        }
        ray = hit.spawn_ray(wi_world);
    }
    crate::stats::add(crate::stats::Counter::PhotonRays, rays as u64);
    rays
}

/// One photon pass: photons `0..photons` of `stream`, each emitted by [`emit`] as one
/// of `emitted_of` (through `projection` when given) and traced to `max_depth`.
pub struct PhotonPass<'a> {
    pub world: &'a World,
    pub stream: PhotonStream,
    pub photons: u64,
    pub emitted_of: f64,
    pub projection: Option<&'a ProjectionMaps>,
    pub max_depth: u32,
}

impl PhotonPass<'_> {
    /// Traces the pass in parallel chunks of [`CHUNK`] photons whose outputs are
    /// concatenated in order, so the result does not depend on the threads. `land` sees
    /// every landing with its chunk's output and says whether the photon goes on (as in
    /// [`trace_photon`]); a chunk that starts once `cancelled()` holds traces nothing,
    /// and a cancelled pass returns no outputs (nothing is rendered from them): the
    /// chunks are not concatenated — at 10^8 photons a copy of gigabytes — but freed
    /// off the caller's thread.
    /// Returns the outputs and the number of rays traced.
    pub fn trace<T: Send + 'static>(
        &self,
        cancelled: impl Fn() -> bool + Sync,
        land: impl Fn(&Landing, &mut Vec<T>) -> bool + Sync,
    ) -> (Vec<T>, u64) {
        let chunks: Vec<(Vec<T>, u64)> = (0..self.photons.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut out = Vec::new();
                let mut rays = 0u64;
                if cancelled() {
                    return (out, rays);
                }
                for i in c * CHUNK..((c + 1) * CHUNK).min(self.photons) {
                    let mut sampler = self.stream.sampler(i);
                    let Some((ray, power)) =
                        emit(self.world, self.projection, self.emitted_of, &mut sampler)
                    else {
                        continue;
                    };
                    rays +=
                        trace_photon(self.world, ray, power, self.max_depth, &mut sampler, |l| {
                            land(l, &mut out)
                        }) as u64;
                }
                (out, rays)
            })
            .collect();
        if cancelled() {
            let rays = chunks.iter().map(|c| c.1).sum();
            let bytes = chunks.iter().map(|c| c.0.len()).sum::<usize>() * size_of::<T>();
            super::kdtree::release_sized(chunks, bytes);
            return (Vec::new(), rays);
        }
        let mut out = Vec::with_capacity(chunks.iter().map(|c| c.0.len()).sum());
        let mut rays = 0;
        for (chunk, chunk_rays) in chunks {
            out.extend(chunk);
            rays += chunk_rays;
        }
        (out, rays)
    }
}
