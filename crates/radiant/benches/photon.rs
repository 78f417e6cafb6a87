//! Photon mapping throughput: tracing, kd-tree build and queries, one SPPM iteration.
//!
//! `cargo bench --bench photon`; `radiant bench` prints the same figures in one table.

use divan::Bencher;
use glam::Vec3;
use radiant::Session;
use radiant::math::hash::Pcg32;
use radiant::render::integrator::photon::bench::trace_photons;
use radiant::render::integrator::photon::{KdTree, Neighbors, Photon};
use radiant::render::world::World;
use radiant::render::{Overrides, Progress};
use radiant::scene::builtin::cornell_caustics;

fn main() {
    divan::main();
}

fn world() -> World {
    World::build(&cornell_caustics()).expect("scene").0
}

/// A million photons as they land in cornell-caustics.
fn million_photons() -> Vec<Photon> {
    let raw = trace_photons(&world(), 1_000_000, 100);
    let scale = 1.0
        / raw
            .iter()
            .map(|r| r.power.max_component())
            .fold(1e-30, f32::max);
    raw.iter()
        .cycle()
        .take(1_000_000)
        .map(|r| Photon::encode(r, scale))
        .collect()
}

/// 100 000 photon paths of the global pass (divide by the time for photons/s).
#[divan::bench(sample_count = 5)]
fn trace_100k_photons(bencher: Bencher) {
    let world = world();
    bencher.bench(|| trace_photons(&world, 100_000, 100).len());
}

#[divan::bench(sample_count = 5)]
fn kdtree_build_1m(bencher: Bencher) {
    let photons = million_photons();
    bencher
        .with_inputs(|| photons.clone())
        .bench_values(|p| KdTree::build(p).len());
}

/// 10 000 queries of the 100 nearest photons within 25 mm (one thread).
#[divan::bench(sample_count = 5)]
fn knn_10k_queries_k100(bencher: Bencher) {
    let tree = KdTree::build(million_photons());
    let mut rng = Pcg32::new(1, 1);
    let points: Vec<Vec3> = (0..10_000)
        .map(|_| {
            let ph = tree.get(rng.next_u32() % tree.len() as u32);
            ph.position() + Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5
        })
        .collect();
    let mut nbrs = Neighbors::new(100);
    bencher.bench_local(|| {
        let mut n = 0;
        for &p in &points {
            tree.nearest(p, 625.0, &mut nbrs);
            n += nbrs.len();
        }
        n
    });
}

/// One SPPM iteration of cornell-caustics at 256 × 256 (65 536 photons).
#[divan::bench(sample_count = 5)]
fn sppm_iteration_256(bencher: Bencher) {
    let mut desc = cornell_caustics();
    desc.integrator.name = "sppm".into();
    let session = Session::new(
        &desc,
        &Overrides {
            spp: Some(1),
            ..Default::default()
        },
    )
    .expect("scene");
    bencher.bench(|| session.render(&Progress::default()).spp_done);
}
