//! The image of a solution seen from the scene camera, through the same film, filter
//! and pass loop as the path tracer ([`Shading`] is a per-pixel estimator).
//!
//! A camera ray finds the patch it hits. Diffuse patches show `L = B / pi` (Lambertian
//! exitance to radiance), either interpolated from the vertices (Gouraud), or with a
//! final gather: emission, direct light by light sampling with a shadow ray, and one
//! bounce of `n` cosine-distributed rays that read the interpolated `(B - E) / pi` of
//! the patches they hit (Reichert, "A Two-Pass Radiosity Method Driven by Lights and
//! Viewer Position", MSc thesis, Cornell 1992; Lischinski, Tampieri & Greenberg 1993).
//! Patches with no diffuse albedo at all (glass, metals; reflectance 0 in the solve)
//! pass the ray on by their BSDF; every other patch, the approximated non-diffuse
//! materials included (diffuse transmission, mixes with a diffuse part), shows its
//! radiosity.

use glam::{DVec3, Vec3};

use super::display::{DisplayMesh, PatchTracer};
use crate::mesh::meshed_scene::RadiosityScene;
use crate::visibility::bvh::FaceVisibility;
use radiant_math::color::Rgb;
use radiant_math::{Frame, sampling};
use radiant_render::geometry::Ray;
use radiant_render::geometry::SurfacePoint;
use radiant_render::integrator::direct::environment;
use radiant_render::integrator::specular::specular_bounce;
use radiant_render::integrator::{PixelEstimator, PixelId};
use radiant_render::light::LightSampleContext;
use radiant_render::sampler::PixelSample;
use radiant_render::world::World;

/// True for the patches a camera ray stops at and reads the solution of: those whose
/// material (or one of a mix's) is Lambertian or has a diffuse albedo, which is what the
/// solve gave them; the rest are followed by their BSDF.
fn shown_by_radiosity(world: &World, material: u32) -> bool {
    world
        .material_weights(material)
        .iter()
        .any(|(m, w)| *w > 0.0 && (m.is_diffuse() || !m.diffuse_albedo().is_black()))
}

/// Specular bounces a camera path follows unless told otherwise.
const DEFAULT_SPECULAR_DEPTH: u32 = 8;

/// A solution prepared for shading camera rays.
pub struct Shading<'a> {
    scene: &'a RadiosityScene,
    world: &'a World,
    tracer: PatchTracer,
    occluders: FaceVisibility,
    mesh: DisplayMesh,
    /// Display radiosity per display vertex.
    vertex_radiosity: Vec<[f32; 3]>,
    final_gather: u32,
    specular_depth: u32,
    /// Per material entry: [`shown_by_radiosity`].
    shown: Vec<bool>,
}

impl<'a> Shading<'a> {
    /// Prepares the display of per-patch radiosities `display` (usually
    /// [`crate::solve::Solution::display_radiosity`]); `irradiance` marks the patches
    /// that received light, the only ones averaged into a vertex where a lit one is
    /// present (patches hidden inside solids, such as the floor under a block, would
    /// darken its edges).
    pub fn new(
        scene: &'a RadiosityScene,
        world: &'a World,
        display: &[[f64; 3]],
        irradiance: &[[f64; 3]],
        final_gather: u32,
    ) -> Shading<'a> {
        let mesh = DisplayMesh::new(scene);
        let set = &scene.patches;
        let lit = |i: usize| {
            let seen = irradiance[i].iter().any(|&h| h > 0.0)
                || set.patches[i].emission.iter().any(|&e| e > 0.0);
            if seen { 1.0 } else { 0.0 }
        };
        let vertex_radiosity = mesh
            .vertex_values(set, display, lit)
            .into_iter()
            .map(|v| v.map(|x| x as f32))
            .collect();
        Shading {
            scene,
            world,
            tracer: PatchTracer::new(scene),
            occluders: FaceVisibility::new(scene),
            mesh,
            vertex_radiosity,
            final_gather,
            specular_depth: DEFAULT_SPECULAR_DEPTH,
            shown: (0..world.materials.len() as u32)
                .map(|m| shown_by_radiosity(world, m))
                .collect(),
        }
    }

    /// Follows at most `depth` specular bounces per camera ray.
    pub fn with_specular_depth(mut self, depth: u32) -> Shading<'a> {
        self.specular_depth = depth;
        self
    }

    /// The display mesh (vertex positions, normals, corner map).
    pub fn mesh(&self) -> &DisplayMesh {
        &self.mesh
    }

    /// Display radiosity per display vertex.
    pub fn vertex_radiosity(&self) -> &[[f32; 3]] {
        &self.vertex_radiosity
    }

    /// Interpolated radiosity on patch `i` with corner weights `w`.
    fn interpolated(&self, i: usize, w: &[f64; 4]) -> Rgb {
        let n = self.scene.patches.patches[i].corner_count as usize;
        let mut sum = [0.0f32; 3];
        for (k, &weight) in w.iter().enumerate().take(n) {
            let v = self.vertex_radiosity[self.mesh.corner_vertex[i][k] as usize];
            for b in 0..3 {
                sum[b] += weight as f32 * v[b];
            }
        }
        Rgb::from_array(sum)
    }

    /// The interpolated vertex normal of patch `i` (smooth on tessellated curved
    /// surfaces, the flat normal elsewhere).
    fn shading_normal(&self, i: usize, w: &[f64; 4]) -> Vec3 {
        let n = self.scene.patches.patches[i].corner_count as usize;
        let mut sum = DVec3::ZERO;
        for (k, &weight) in w.iter().enumerate().take(n) {
            sum += weight * self.mesh.normals[self.mesh.corner_vertex[i][k] as usize];
        }
        let flat = self.scene.patches.patches[i].normal;
        let smooth = sum.normalize_or_zero();
        if smooth.dot(flat) > 0.0 {
            smooth.as_vec3()
        } else {
            flat.as_vec3()
        }
    }

    fn emission(&self, i: usize) -> Rgb {
        Rgb::from_array(self.scene.patches.patches[i].emission.map(|e| e as f32))
    }

    /// Radiance along a camera ray, and the number of rays traced.
    pub fn radiance(&self, mut ray: Ray, sampler: &mut PixelSample) -> (Rgb, u32) {
        let inv_pi = std::f32::consts::FRAC_1_PI;
        let mut beta = Rgb::WHITE;
        let mut l = Rgb::BLACK;
        let mut rays = 0u32;
        for _ in 0..=self.specular_depth {
            rays += 1;
            let Some(hit) = self.tracer.intersect(self.scene, &ray, f32::INFINITY) else {
                // Lights at infinity seen directly or through specular surfaces.
                l += beta * environment(self.world, ray.d);
                break;
            };
            // Specular surfaces are two-sided (a ray inside glass meets the back of the
            // sphere's patches); diffuse ones show only their front.
            let struck = self.scene.tag(hit.struck).material;
            if !self.shown[struck as usize] {
                let struck_material =
                    self.world
                        .resolve_material(struck, hit.p.as_vec3(), -ray.d.normalize());
                let i = hit.patch.unwrap_or(hit.struck);
                if hit.patch.is_some() {
                    l += beta * self.emission(i) * inv_pi;
                }
                let n = self.shading_normal(hit.struck, &hit.weights_struck);
                let frame = Frame::from_normal(n);
                let wo = frame.to_local(-ray.d.normalize());
                let Some(wi) = specular_bounce(&struck_material, &frame, wo, sampler, &mut beta)
                else {
                    break;
                };
                let ng = self.scene.patches.patches[hit.struck].normal.as_vec3();
                ray = self
                    .scene
                    .patches
                    .surface_point(hit.struck, hit.p, ng)
                    .spawn_ray(wi);
                continue;
            }
            let Some(i) = hit.patch else { break };
            let patch = &self.scene.patches.patches[i];
            let n = patch.normal.as_vec3();
            if self.final_gather == 0 {
                l += beta * self.interpolated(i, &hit.weights) * inv_pi;
                break;
            }
            let albedo = Rgb::from_array(patch.reflectance.map(|r| r as f32));
            let at = self.scene.patches.surface_point(i, hit.p, n);
            let (reflected, traced) = self.gather(&at, self.final_gather, true, sampler);
            rays += traced;
            l += beta * (self.emission(i) * inv_pi + albedo * reflected);
            break;
        }
        (l, rays)
    }

    /// `(1/pi) * (direct irradiance + indirect irradiance)` at `x` (normal `n`): the
    /// reflected radiance per unit albedo. Direct light by one light sample, indirect by
    /// `count` cosine-distributed rays reading `(B - E) / pi` where they hit. With
    /// `refine_near`, a hit closer than one patch edge (corners, contact shadows, where
    /// the interpolated radiosity of a nearby patch is least accurate and matters most)
    /// is shaded by a second, smaller gather there instead.
    fn gather(
        &self,
        at: &SurfacePoint,
        count: u32,
        refine_near: bool,
        sampler: &mut PixelSample,
    ) -> (Rgb, u32) {
        let inv_pi = std::f32::consts::FRAC_1_PI;
        let (p, n) = (at.p, at.n);
        let mut rays = 0;
        let mut direct = Rgb::BLACK;
        let u_light = sampler.get_1d();
        let u_point = sampler.get_2d();
        let ctx = LightSampleContext::on_surface(p, n);
        let sample = self
            .world
            .light_sampler
            .sample(&ctx, u_light)
            .and_then(|chosen| {
                let light = &self.world.lights[chosen.index];
                let ls = light.sample_li(&ctx, u_point, self.world.scene_sphere())?;
                Some((chosen.pmf, ls))
            });
        if let Some((pmf, ls)) = sample {
            let cos = n.dot(ls.wi);
            if cos > 0.0 && ls.pdf > 0.0 {
                rays += 1;
                let blocked = if ls.at_infinity {
                    self.occluders.occluded(&at.spawn_ray(ls.wi), f32::INFINITY)
                } else {
                    let (ray, t_max) = at.spawn_ray_to(&ls.p_light);
                    self.occluders.occluded(&ray, t_max)
                };
                if !blocked {
                    direct = ls.li * (cos / (pmf * ls.pdf));
                }
            }
        }
        let frame = Frame::from_normal(n);
        let mut indirect = Rgb::BLACK;
        let near = self.scene.max_edge as f32;
        for _ in 0..count {
            let w = frame.to_world(sampling::cosine_hemisphere(sampler.get_2d()));
            rays += 1;
            let ray = at.spawn_ray(w);
            let Some(hit) = self.tracer.intersect(self.scene, &ray, f32::INFINITY) else {
                continue;
            };
            let Some(j) = hit.patch else { continue };
            let patch = &self.scene.patches.patches[j];
            let diffuse = self.shown[self.scene.tag(j).material as usize];
            if refine_near && hit.t < near && diffuse {
                let facing = patch.normal.as_vec3();
                let (reflected, traced) = self.gather(
                    &self.scene.patches.surface_point(j, hit.p, facing),
                    (count / 4).max(1),
                    false,
                    sampler,
                );
                rays += traced;
                let albedo = Rgb::from_array(patch.reflectance.map(|r| r as f32));
                indirect += albedo * reflected * std::f32::consts::PI;
            } else {
                indirect += (self.interpolated(j, &hit.weights) - self.emission(j)).clamp_min(0.0);
            }
        }
        // Cosine sampling: f cos / pdf = albedo, so the gathered radiance is the mean.
        let indirect = indirect * (inv_pi / count.max(1) as f32);
        (direct * inv_pi + indirect, rays)
    }
}

impl PixelEstimator for Shading<'_> {
    type Scratch = ();

    fn scratch(&self) {}

    fn radiance(
        &self,
        ray: Ray,
        sampler: &mut PixelSample,
        _pixel: PixelId,
        _scratch: &mut (),
    ) -> (Rgb, u32) {
        Shading::radiance(self, ray, sampler)
    }
}
