//! The ray-throughput benchmark: a displaced sphere of about a million triangles inside
//! the Cornell box walls, seen from the Cornell camera. Measures camera rays (closest hit,
//! coherent), diffuse bounce rays from the camera hits (closest hit, incoherent) and
//! shadow rays towards the ceiling light (any hit), on all rayon threads.

use super::displaced_sphere::{cornell_box_walls, displaced_sphere};
use super::{MeshHit, TriangleBvh};
use crate::geometry::SurfacePoint;
use crate::geometry::ray::barycentric_error;
use crate::geometry::{Ray, triangle::triangle_normal};
use radiant_math::hash::{hash_u64s, u32_to_unit_f32};
use radiant_math::sampling::cosine_hemisphere;
use radiant_math::{Frame, Vec2, Vec3};
use rayon::prelude::*;
use std::fmt;
use std::time::Instant;

/// Parameters of [`ray_benchmark`].
#[derive(Clone, Copy, Debug)]
pub struct RayBenchConfig {
    /// Geodesic subdivision: the sphere has 20 k² triangles (224 → 1,003,520).
    pub subdivision: u32,
    /// Camera rays: one per pixel of an `image_size`² image.
    pub image_size: u32,
    /// Each ray batch is traced this many times; the fastest run is reported.
    pub repetitions: u32,
    pub seed: u64,
}

impl Default for RayBenchConfig {
    fn default() -> Self {
        RayBenchConfig {
            subdivision: 224,
            image_size: 1024,
            repetitions: 5,
            seed: 1,
        }
    }
}

/// What [`ray_benchmark`] measured. Throughputs are rays per second of wall-clock time on
/// all rayon threads (the headline figure), and rays per CPU-second of tracing (per-core
/// speed, robust to other processes competing for the cores; `None` off Linux).
#[derive(Clone, Copy, Debug)]
pub struct RayBenchFigures {
    /// Triangles in the scene (sphere and walls).
    pub triangles: usize,
    /// Rayon threads used.
    pub threads: usize,
    /// Wall-clock time of `TriangleBvh::build`.
    pub build_seconds: f64,
    /// Wide nodes in the tree.
    pub nodes: usize,
    /// 4-triangle SIMD blocks in the leaves.
    pub blocks: usize,
    pub camera_rays: usize,
    /// Fraction of camera rays that hit anything.
    pub camera_hit_fraction: f64,
    pub camera_mrays_per_s: f64,
    pub camera_mrays_per_cpu_s: Option<f64>,
    /// One cosine-distributed bounce ray per camera hit.
    pub diffuse_rays: usize,
    pub diffuse_hit_fraction: f64,
    pub diffuse_mrays_per_s: f64,
    pub diffuse_mrays_per_cpu_s: Option<f64>,
    /// One ray per camera hit towards a random point of the ceiling light.
    pub shadow_rays: usize,
    pub shadow_occluded_fraction: f64,
    pub shadow_mrays_per_s: f64,
    pub shadow_mrays_per_cpu_s: Option<f64>,
}

impl fmt::Display for RayBenchFigures {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "scene: {} triangles; BVH build {:.3} s ({} nodes, {} 4-triangle blocks); {} threads",
            self.triangles, self.build_seconds, self.nodes, self.blocks, self.threads
        )?;
        let per_cpu = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.2}"));
        let rows = [
            (
                "camera ",
                self.camera_rays,
                self.camera_hit_fraction,
                "hit",
                self.camera_mrays_per_s,
                self.camera_mrays_per_cpu_s,
            ),
            (
                "diffuse",
                self.diffuse_rays,
                self.diffuse_hit_fraction,
                "hit",
                self.diffuse_mrays_per_s,
                self.diffuse_mrays_per_cpu_s,
            ),
            (
                "shadow ",
                self.shadow_rays,
                self.shadow_occluded_fraction,
                "occluded",
                self.shadow_mrays_per_s,
                self.shadow_mrays_per_cpu_s,
            ),
        ];
        for (i, (name, n, frac, what, wall, cpu)) in rows.into_iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(
                f,
                "{name} rays: {n:>8} ({:5.1}% {what:<8}) {wall:6.2} Mrays/s  ({} Mrays per CPU-second)",
                100.0 * frac,
                per_cpu(cpu)
            )?;
        }
        Ok(())
    }
}

/// Cornell camera: eye (278, 273, −800) looking along +z, vertical fov 2 atan(12.5/35).
/// Pixels are visited in 8×8 tiles, as a renderer's tiles would.
fn camera_rays(size: u32) -> Vec<Ray> {
    let eye = Vec3::new(278.0, 273.0, -800.0);
    let tan_half = 12.5 / 35.0;
    let mut rays = Vec::with_capacity((size * size) as usize);
    for ty in (0..size).step_by(8) {
        for tx in (0..size).step_by(8) {
            for y in ty..(ty + 8).min(size) {
                for x in tx..(tx + 8).min(size) {
                    let sx = (2.0 * (x as f32 + 0.5) / size as f32 - 1.0) * tan_half;
                    let sy = (1.0 - 2.0 * (y as f32 + 0.5) / size as f32) * tan_half;
                    // World +x is on the image's left (camera looks along +z, +y up).
                    rays.push(Ray::new(eye, Vec3::new(-sx, sy, 1.0).normalize()));
                }
            }
        }
    }
    rays
}

fn uniform2(seed: u64, index: u64, dim: u64) -> Vec2 {
    let h = hash_u64s(&[seed, index, dim]);
    Vec2::new(u32_to_unit_f32(h as u32), u32_to_unit_f32((h >> 32) as u32))
}

/// CPU time consumed so far by all threads of this process, in seconds (Linux: the sum of
/// the first fields of /proc/self/task/*/schedstat, in ns). `None` where unavailable.
fn process_cpu_seconds() -> Option<f64> {
    let mut ns = 0u64;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let text = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        ns += text.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(ns as f64 * 1e-9)
}

/// Wall and CPU seconds of one traced batch.
#[derive(Clone, Copy)]
struct Timing {
    wall: f64,
    cpu: Option<f64>,
}

/// Traces `rays` with `trace` on all threads, `repetitions` times; returns the results of
/// the last run and the fastest run's timing. CPU time is summed over the process's
/// threads, so rays per CPU-second measures per-core speed even when other processes
/// compete for the cores (wall-clock throughput then drops, CPU-second throughput not).
fn timed<T: Send + Copy + Default>(
    rays: &[(Ray, f32)],
    repetitions: u32,
    trace: impl Fn(&Ray, f32) -> T + Sync,
) -> (Vec<T>, Timing) {
    let mut out = vec![T::default(); rays.len()];
    let mut best = Timing {
        wall: f64::INFINITY,
        cpu: None,
    };
    for _ in 0..repetitions.max(1) {
        let cpu_before = process_cpu_seconds();
        let start = Instant::now();
        out.par_chunks_mut(1024)
            .zip(rays.par_chunks(1024))
            .for_each(|(o, r)| {
                for (slot, (ray, t_max)) in o.iter_mut().zip(r) {
                    *slot = trace(ray, *t_max);
                }
            });
        let wall = start.elapsed().as_secs_f64();
        let cpu = match (cpu_before, process_cpu_seconds()) {
            (Some(b), Some(a)) => Some(a - b),
            _ => None,
        };
        best.wall = best.wall.min(wall);
        best.cpu = match (best.cpu, cpu) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
    }
    (out, best)
}

/// Builds the benchmark scene and its BVH and measures ray throughput (see module docs).
pub fn ray_benchmark(config: &RayBenchConfig) -> RayBenchFigures {
    let mut mesh = displaced_sphere(
        config.subdivision,
        Vec3::new(278.0, 210.0, 280.0),
        150.0,
        0.08,
        config.seed,
    );
    for tri in cornell_box_walls() {
        let base = mesh.vertices.len() as u32;
        mesh.vertices.extend(tri);
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    let start = Instant::now();
    let bvh = TriangleBvh::build(&mesh.vertices, &mesh.triangles);
    let build_seconds = start.elapsed().as_secs_f64();
    let (nodes, blocks) = bvh.size();

    let reps = config.repetitions;
    let cam: Vec<(Ray, f32)> = camera_rays(config.image_size)
        .into_iter()
        .map(|r| (r, f32::INFINITY))
        .collect();
    let (cam_hits, cam_time) = timed(&cam, reps, |r, t| bvh.intersect(r, t));

    // Surface points of the camera hits, with the geometric normal facing the camera.
    let surface: Vec<SurfacePoint> = cam
        .iter()
        .zip(&cam_hits)
        .filter_map(|((ray, _), hit): (&(Ray, f32), &Option<MeshHit>)| {
            let h = (*hit)?;
            let p = mesh.triangles[h.prim as usize].map(|i| mesh.vertices[i as usize]);
            let point = h.b[0] * p[0] + h.b[1] * p[1] + h.b[2] * p[2];
            let n = triangle_normal(p[0], p[1], p[2]);
            Some(SurfacePoint::new(
                point,
                barycentric_error(h.b, p),
                if n.dot(ray.d) > 0.0 { -n } else { n },
            ))
        })
        .collect();

    let diffuse: Vec<(Ray, f32)> = surface
        .iter()
        .enumerate()
        .map(|(i, sp)| {
            let d = Frame::from_normal(sp.n).to_world(cosine_hemisphere(uniform2(
                config.seed,
                i as u64,
                0,
            )));
            (sp.spawn_ray(d), f32::INFINITY)
        })
        .collect();
    let (diffuse_hits, diffuse_time) = timed(&diffuse, reps, |r, t| bvh.intersect(r, t).is_some());

    let shadow: Vec<(Ray, f32)> = surface
        .iter()
        .enumerate()
        .map(|(i, sp)| {
            let u = uniform2(config.seed, i as u64, 1);
            let target = Vec3::new(213.0 + 130.0 * u.x, 548.7, 227.0 + 105.0 * u.y);
            // Stop just short of the light, which is not part of the occluding geometry.
            sp.spawn_ray_to(&SurfacePoint::free(target))
        })
        .collect();
    let (occluded, shadow_time) = timed(&shadow, reps, |r, t| bvh.occluded(r, t));

    let frac = |n: usize, d: usize| n as f64 / d.max(1) as f64;
    let count = |v: &[bool]| v.iter().filter(|&&b| b).count();
    RayBenchFigures {
        triangles: mesh.triangles.len(),
        threads: rayon::current_num_threads(),
        build_seconds,
        nodes,
        blocks,
        camera_rays: cam.len(),
        camera_hit_fraction: frac(surface.len(), cam.len()),
        camera_mrays_per_s: cam.len() as f64 / cam_time.wall / 1e6,
        camera_mrays_per_cpu_s: cam_time.cpu.map(|c| cam.len() as f64 / c / 1e6),
        diffuse_rays: diffuse.len(),
        diffuse_hit_fraction: frac(count(&diffuse_hits), diffuse.len()),
        diffuse_mrays_per_s: diffuse.len() as f64 / diffuse_time.wall / 1e6,
        diffuse_mrays_per_cpu_s: diffuse_time.cpu.map(|c| diffuse.len() as f64 / c / 1e6),
        shadow_rays: shadow.len(),
        shadow_occluded_fraction: frac(count(&occluded), shadow.len()),
        shadow_mrays_per_s: shadow.len() as f64 / shadow_time.wall / 1e6,
        shadow_mrays_per_cpu_s: shadow_time.cpu.map(|c| shadow.len() as f64 / c / 1e6),
    }
}
