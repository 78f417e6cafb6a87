//! Throughput figures of the photon mappers, for `radiant bench` and `benches/photon.rs`
//! (timings live here, never in tests): photons traced per second, the kd-tree build
//! of a million photons, k-nearest queries per second, and the time of one SPPM
//! iteration at 256 × 256 — all on cornell-caustics.

use std::fmt;
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use super::estimate::PhotonMap;
use super::kdtree::{KdTree, Neighbors};
use super::record::{Photon, RawPhoton};
use super::trace::{PhotonPass, PhotonStream};
use crate::context::{Overrides, RenderContext};
use crate::integrator::{Integrator, SppmIntegrator, SppmSettings};
use crate::world::World;
use radiant_math::hash::Pcg32;
use radiant_scene::SamplerKind;
use radiant_scene::builtin::cornell_caustics;

/// Measured figures (wall-clock, on the current rayon pool).
#[derive(Clone, Copy, Debug, Default)]
pub struct PhotonBenchFigures {
    pub threads: usize,
    /// Photon paths traced (emitted) and the diffuse hits they made.
    pub photons: u64,
    pub landings: u64,
    pub trace_seconds: f64,
    /// Photons in the timed kd-tree build and its time.
    pub tree_photons: usize,
    pub build_seconds: f64,
    /// k of the nearest-neighbour queries, number of queries, time.
    pub k: usize,
    pub queries: usize,
    pub query_seconds: f64,
    /// Seconds per SPPM iteration at 256 × 256 (65 536 photons per iteration).
    pub sppm_iteration_seconds: f64,
}

impl fmt::Display for PhotonBenchFigures {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "photon tracing: {} photons ({} diffuse hits) in {:.3} s: {:.2} M photons/s on {} threads",
            self.photons,
            self.landings,
            self.trace_seconds,
            self.photons as f64 / self.trace_seconds / 1e6,
            self.threads
        )?;
        writeln!(
            f,
            "kd-tree build: {} photons in {:.3} s",
            self.tree_photons, self.build_seconds
        )?;
        writeln!(
            f,
            "k-nearest queries (k = {}): {} in {:.3} s: {:.3} M queries/s",
            self.k,
            self.queries,
            self.query_seconds,
            self.queries as f64 / self.query_seconds / 1e6
        )?;
        write!(
            f,
            "SPPM iteration, cornell-caustics 256x256, 65536 photons: {:.3} s",
            self.sppm_iteration_seconds
        )
    }
}

/// Traces `n` photons of the global pass of `world` and returns their diffuse hits.
pub fn trace_photons(world: &World, n: u64, max_depth: u32) -> Vec<RawPhoton> {
    PhotonPass {
        world,
        stream: PhotonStream::new(SamplerKind::Sobol, 1, &[0xbe4c]),
        photons: n,
        emitted_of: n as f64,
        projection: None,
        max_depth,
    }
    .trace(
        || false,
        |l, out| {
            out.push(RawPhoton {
                p: l.hit.p,
                power: l.power,
                wi: l.wi,
                n: l.hit.ng,
                bounces: l.bounces.min(255) as u8,
                flags: 0,
            });
            true
        },
    )
    .0
}

/// Runs every measurement; `quick` shrinks the workloads.
pub fn photon_benchmark(quick: bool) -> PhotonBenchFigures {
    let desc = cornell_caustics();
    let (world, _) = World::build(&desc).expect("the canonical scene builds");
    let n = if quick { 200_000 } else { 1_000_000 };
    let t = Instant::now();
    let raw = trace_photons(&world, n, 100);
    let trace_seconds = t.elapsed().as_secs_f64();
    let landings = raw.len() as u64;

    // A million photons as they lie in the scene (repeat the traced ones if short).
    let tree_n = if quick { 200_000 } else { 1_000_000 };
    let scale = 1.0
        / raw
            .iter()
            .map(|r| r.power.max_component())
            .fold(1e-30, f32::max);
    let photons: Vec<Photon> = raw
        .iter()
        .cycle()
        .take(tree_n)
        .map(|r| Photon::encode(r, scale))
        .collect();
    let t = Instant::now();
    let tree = KdTree::build(photons);
    let build_seconds = t.elapsed().as_secs_f64();

    let map = PhotonMap::build(raw);
    let k = 100;
    let queries = if quick { 20_000 } else { 100_000 };
    let mut rng = Pcg32::new(7, 7);
    let points: Vec<Vec3> = (0..queries)
        .map(|_| {
            let ph = map.photons()[(rng.next_u32() as usize) % map.len()];
            ph.position() + Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5
        })
        .collect();
    let t = Instant::now();
    let found: usize = points
        .par_chunks(1024)
        .map(|chunk| {
            let mut nbrs = Neighbors::new(k);
            chunk
                .iter()
                .map(|&p| {
                    tree.nearest(p, 25.0 * 25.0, &mut nbrs);
                    nbrs.len()
                })
                .sum::<usize>()
        })
        .sum();
    let query_seconds = t.elapsed().as_secs_f64();
    assert!(found > 0);

    let iterations = if quick { 2 } else { 8 };
    let (ctx, _) = RenderContext::new(
        &desc,
        &Overrides {
            spp: Some(iterations),
            ..Default::default()
        },
    )
    .expect("the canonical scene builds");
    let sppm = SppmIntegrator {
        settings: SppmSettings::default(),
    };
    let t = Instant::now();
    sppm.render_unobserved(&ctx);
    let sppm_iteration_seconds = t.elapsed().as_secs_f64() / iterations as f64;

    PhotonBenchFigures {
        threads: rayon::current_num_threads(),
        photons: n,
        landings,
        trace_seconds,
        tree_photons: tree_n,
        build_seconds,
        k,
        queries,
        query_seconds,
        sppm_iteration_seconds,
    }
}
