//! Camera paths of the photon mapper: specular chains by ray tracing, then at the first
//! diffuse point direct light (next-event estimation), caustics (caustic map) and
//! indirect light (final gathering), or one of the visualisations.

use glam::Vec3;

use super::estimate::{
    ESTIMATED_EVALS, EstimatePoint, PhotonMap, PhotonSearch, radiance_estimate,
    radiance_estimate_sampled,
};
use super::kdtree::Neighbors;
use super::record::FIRST_DIFFUSE;
use super::settings::Visualize;
use super::{PhotonMaps, facing};
use crate::geometry::Ray;
use crate::integrator::direct::{ShadingPoint, sides_agree};
use crate::integrator::specular::{
    ChainVertex, CoatStep, chain_bounce, chain_end_direct, coat_step, glossy_direct,
    specular_bounce,
};
use crate::light::SceneSphere;
use crate::material::{BsdfPart, Material, TransportMode};
use crate::sampler::PixelSample;
use crate::world::World;
use radiant_math::INV_PI;
use radiant_math::color::Rgb;
use radiant_scene::SamplerKind;

/// A radiance estimate at one point. The BSDF is evaluated for every photon found or,
/// where its value is itself a random walk ([`Material::eval_is_estimated`]), for
/// [`ESTIMATED_EVALS`] of them chosen by `u_evals`. Evaluating a varnished floor's
/// walks for each of the 250 photons at a gather ray's endpoint was most of the photon
/// mapper's time, for a noise the walks have anyway.
struct MapQuery<'a> {
    maps: &'a PhotonMaps,
    at: &'a EstimatePoint,
    sampled: bool,
    u_evals: f32,
}

impl<'a> MapQuery<'a> {
    fn new(
        maps: &'a PhotonMaps,
        at: &'a EstimatePoint,
        material: &Material,
        u_evals: f32,
    ) -> MapQuery<'a> {
        MapQuery {
            maps,
            at,
            sampled: material.eval_is_estimated(),
            u_evals,
        }
    }

    /// Reflected radiance from the photons of `map` whose flags share nothing with
    /// `skip_flags`.
    fn estimate(
        &self,
        map: &PhotonMap,
        skip_flags: u8,
        nbrs: &mut Neighbors,
        f: impl Fn(Vec3) -> Rgb,
    ) -> Rgb {
        let search = PhotonSearch {
            skip_flags,
            ..self.maps.search()
        };
        if self.sampled {
            radiance_estimate_sampled(map, self.at, search, nbrs, ESTIMATED_EVALS, self.u_evals, f)
        } else {
            radiance_estimate(map, self.at, search, nbrs, f)
        }
    }
}

/// Per-thread buffers for lookups, so that camera paths do not allocate.
#[derive(Clone, Debug)]
pub struct EyeScratch {
    caustic: Neighbors,
    global: Neighbors,
    nearest: Neighbors,
}

impl EyeScratch {
    /// Buffers sized for the lookups `maps` makes.
    pub fn new(maps: &PhotonMaps) -> EyeScratch {
        EyeScratch {
            caustic: Neighbors::new(maps.settings.lookup as usize),
            global: Neighbors::new(maps.settings.global_lookup as usize),
            nearest: Neighbors::new(1),
        }
    }
}

/// Where the random numbers of the final-gather rays of one camera sample come from:
/// gather ray `j` is sample `j` of a stream named by `key`, so the rays of one camera
/// sample are stratified together.
#[derive(Clone, Copy, Debug)]
pub struct GatherStream {
    pub kind: SamplerKind,
    pub seed: u64,
    pub key: u64,
}

/// Everything a camera path needs besides its ray.
pub struct EyeContext<'a> {
    pub world: &'a World,
    pub maps: &'a PhotonMaps,
    pub scene: SceneSphere,
    /// Angle subtended by one pixel (for the photon dots of `visualize "photons"`).
    pub pixel_angle: f32,
}

/// Radiance along a camera ray, and the number of rays traced.
pub fn radiance(
    ctx: &EyeContext,
    mut ray: Ray,
    sampler: &mut PixelSample,
    gather: GatherStream,
    scratch: &mut EyeScratch,
) -> (Rgb, u32) {
    let world = ctx.world;
    let settings = &ctx.maps.settings;
    let mut l = Rgb::BLACK;
    let mut beta = Rgb::WHITE;
    let mut rays = 0u32;
    let mut travelled = 0.0f32;
    let mut prev = ChainVertex::camera(ray.o);
    for depth in 0..=settings.max_depth {
        rays += 1;
        let Some(hit) = world.intersect_with_footprint(&ray, f32::INFINITY, travelled) else {
            l += beta * prev.environment(world, ray.d);
            break;
        };
        travelled += hit.t * ray.d.length();
        let wo_world = -ray.d.normalize();
        let emitted = prev.emission(world, &hit, wo_world);
        let material = world.material_at(&hit, wo_world);
        let frame = World::shading_frame(&hit, &material);
        if material.passes_photon_paths() {
            // The camera sees emitters directly or through specular and rough-glass
            // chains only; at rough glass a light sample shares the work.
            l += beta * emitted;
            if depth == settings.max_depth {
                break;
            }
            if !material.is_specular() {
                let (direct, shadow_rays) =
                    glossy_direct(world, ctx.scene, &hit, material, wo_world, sampler);
                rays += shadow_rays;
                l += beta * direct;
            }
            let Some((wi, vertex)) =
                chain_bounce(&hit, &material, &frame, wo_world, sampler, &mut beta)
            else {
                break;
            };
            prev = vertex;
            ray = hit.spawn_ray(wi);
            continue;
        }
        let mut part = BsdfPart::Whole;
        if settings.visualize == Visualize::None {
            l += beta * emitted;
            let (direct, direct_rays) =
                chain_end_direct(world, ctx.scene, &hit, material, &frame, wo_world, sampler);
            rays += direct_rays;
            l += beta * direct;
            if let Some(layers) = material.narrow_coat() {
                match coat_step(&hit, layers, &frame, wo_world, sampler, &mut beta) {
                    None => break,
                    Some(CoatStep::Reflect(wi, vertex)) => {
                        if depth == settings.max_depth {
                            break;
                        }
                        prev = vertex;
                        ray = hit.spawn_ray(wi);
                        continue;
                    }
                    Some(CoatStep::Under) => part = BsdfPart::UnderCoat,
                }
            }
        }
        let at = EstimatePoint {
            p: hit.p,
            n: facing(hit.ng, wo_world),
            two_sided: material.transmits_diffusely(),
        };
        let wo = frame.to_local(wo_world);
        let bsdf =
            |wi: Vec3| material.eval_part(part, wo, frame.to_local(wi), TransportMode::Radiance);
        let maps = ctx.maps;
        let u_evals = sampler.get_1d_if(material.eval_is_estimated());
        let query = MapQuery::new(maps, &at, &material, u_evals);
        // Radiance reflected towards the viewer by the photons of one map near the point.
        let estimate =
            |map, skip_flags, neighbours: &mut _| query.estimate(map, skip_flags, neighbours, bsdf);
        let reflected = match settings.visualize {
            Visualize::None => {
                let at = ShadingPoint::new(&hit, material, wo_world);
                let caustic = estimate(&maps.caustic, 0, &mut scratch.caustic);
                let indirect = if settings.final_gather_samples > 0 {
                    let (gathered, gather_rays) = final_gather(ctx, &at, part, gather, scratch);
                    rays += gather_rays;
                    gathered
                } else {
                    estimate(&maps.global, 0, &mut scratch.global)
                };
                caustic + indirect
            }
            Visualize::Caustic => estimate(&maps.caustic, 0, &mut scratch.caustic),
            Visualize::Global => estimate(&maps.global, FIRST_DIFFUSE, &mut scratch.global),
            Visualize::Density => {
                l += beta * emitted;
                estimate(&maps.global, 0, &mut scratch.global)
                    + estimate(&maps.caustic, 0, &mut scratch.caustic)
            }
            Visualize::Photons => photon_dots(maps, &at, 0.75 * ctx.pixel_angle * travelled),
        };
        l += beta * reflected;
        break;
    }
    (l, rays)
}

/// Stored photons within `radius` of the point, each drawn in its normalised colour.
fn photon_dots(maps: &PhotonMaps, at: &EstimatePoint, radius: f32) -> Rgb {
    let mut sum = Rgb::BLACK;
    for map in [&maps.global, &maps.caustic] {
        map.tree().within(at.p, radius * radius, |_, ph, _| {
            if ph.normal().dot(at.n) > 0.7 {
                let c = map.power(ph);
                sum += c * (1.0 / c.max_component().max(1e-30));
            }
        });
    }
    sum
}

/// Indirect diffuse light at a camera path's diffuse point by final gathering: rays
/// sampled from `part` of the BSDF (without a narrow coat's reflection under it) follow
/// specular chains to a diffuse point y, where the light leaving y is next-event
/// estimation plus the precomputed irradiance (global and caustic maps) times the
/// diffuse reflectance. Emission reached by gather rays is not counted (next-event
/// estimation and the caustic map at the camera path's point hold those paths).
/// Returns the radiance and the number of rays traced.
fn final_gather(
    ctx: &EyeContext,
    at: &ShadingPoint,
    part: BsdfPart,
    gather: GatherStream,
    scratch: &mut EyeScratch,
) -> (Rgb, u32) {
    let (x, material, frame, wo, wo_world) = (at.hit, at.material, at.frame, at.wo, at.wo_world);
    let mut rays = 0u32;
    let world = ctx.world;
    let maps = ctx.maps;
    let settings = &maps.settings;
    let n = settings.final_gather_samples;
    let mut sum = Rgb::BLACK;
    for j in 0..n {
        let mut s = PixelSample::for_stream(gather.kind, gather.seed, gather.key, j);
        let u_lobe = s.get_1d_if(material.uses_lobe_sample());
        let u_dir = s.get_2d();
        let Some(bs) = material.sample_part(part, wo, u_lobe, u_dir, TransportMode::Radiance)
        else {
            continue;
        };
        let wi = frame.to_world(bs.wi);
        if !bs.specular && !sides_agree(x, wo_world, wi, wo, bs.wi) {
            continue;
        }
        let mut beta = bs.f * (bs.wi.z.abs() / bs.pdf);
        let mut ray = x.spawn_ray(wi);
        for _ in 0..settings.max_depth {
            rays += 1;
            let Some(y) = world.intersect(&ray, f32::INFINITY) else {
                break;
            };
            let wo_y_world = -ray.d.normalize();
            let mat_y = world.material_at(&y, wo_y_world);
            let frame_y = World::shading_frame(&y, &mat_y);
            let wo_y = frame_y.to_local(wo_y_world);
            if mat_y.passes_photon_paths() {
                let Some(wi) = specular_bounce(&mat_y, &frame_y, wo_y, &mut s, &mut beta) else {
                    break;
                };
                ray = y.spawn_ray(wi);
                continue;
            }
            // A light sample alone at a glossy y would weigh it by the lobe's peak
            // where the light falls in it: the same MIS as at the camera path's end.
            let (direct, direct_rays) =
                chain_end_direct(world, ctx.scene, &y, mat_y, &frame_y, wo_y_world, &mut s);
            rays += direct_rays;
            sum += beta * direct;
            // Under a narrow coat the photons are weighed without the coat's reflection,
            // which the gather ray follows instead (the direct light above took the
            // whole BSDF).
            let mut part_y = BsdfPart::Whole;
            if let Some(layers) = mat_y.narrow_coat() {
                match coat_step(&y, layers, &frame_y, wo_y_world, &mut s, &mut beta) {
                    None => break,
                    Some(CoatStep::Reflect(wi, _)) => {
                        ray = y.spawn_ray(wi);
                        continue;
                    }
                    Some(CoatStep::Under) => part_y = BsdfPart::UnderCoat,
                }
            }
            let at = EstimatePoint {
                p: y.p,
                n: facing(y.ng, wo_y_world),
                two_sided: mat_y.transmits_diffusely(),
            };
            let indirect = if let Material::Diffuse { albedo } = mat_y {
                gathered_irradiance(maps, &at, scratch) * albedo * INV_PI
            } else {
                // A glossy (or transmitting) surface reflects the photons' light by its
                // BSDF, not by an albedo: the two maps' radiance estimates with the BSDF
                // evaluated per photon (Jensen 2001, §7.5). An irradiance times the
                // diffuse albedo, zero for a rough metal, would drop all of it.
                let bsdf = |wi: Vec3| {
                    mat_y.eval_part(part_y, wo_y, frame_y.to_local(wi), TransportMode::Radiance)
                };
                let u_evals = s.get_1d_if(mat_y.eval_is_estimated());
                let query = MapQuery::new(maps, &at, &mat_y, u_evals);
                let estimate = |map, neighbours: &mut _| query.estimate(map, 0, neighbours, bsdf);
                estimate(&maps.global, &mut scratch.global)
                    + estimate(&maps.caustic, &mut scratch.caustic)
            };
            sum += beta * indirect;
            break;
        }
    }
    (sum * (1.0 / n.max(1) as f32), rays)
}

/// The irradiance a gather ray reads where it lands at `at`: that of the nearest
/// precomputed point, or, with none near, an estimate from both maps there.
pub fn gathered_irradiance(maps: &PhotonMaps, at: &EstimatePoint, scratch: &mut EyeScratch) -> Rgb {
    maps.irradiance
        .as_ref()
        .and_then(|c| c.lookup(at, maps.max_r2, &mut scratch.nearest))
        .unwrap_or_else(|| {
            let one = |_| Rgb::WHITE;
            let search = maps.search();
            radiance_estimate(&maps.global, at, search, &mut scratch.global, one)
                + radiance_estimate(&maps.caustic, at, search, &mut scratch.caustic, one)
        })
}
