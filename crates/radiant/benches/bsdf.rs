//! BSDF throughput per material: evaluations (`eval` and `pdf` of one direction
//! pair) and samples (`sample` of one direction) per second, one thread.
//!
//! `cargo bench --bench bsdf`; divan prints items/s for each material. The
//! inputs are fixed 4096 pairs of directions spread over both hemispheres (and
//! 4096 random-number triples), the same for every material, so the figures compare
//! the cost of the lobes, not of the input.

use divan::Bencher;
use divan::counter::ItemsCount;
use glam::{Vec2, Vec3};
use radiant::color::Rgb;
use radiant::math::hash::Pcg32;
use radiant::render::material::{Material, TransportMode};
use radiant::scene::{CoatDesc, ConductorDesc, MaterialDesc};

fn main() {
    divan::main();
}

const N: usize = 4096;

const MATERIALS: [&str; 12] = [
    "diffuse",
    "mirror",
    "conductor",
    "dielectric",
    "rough_conductor",
    "rough_dielectric",
    "thin_dielectric",
    "diffuse_transmission",
    "coated_diffuse_smooth",
    "coated_diffuse_rough",
    "coated_conductor",
    "coated_conductor_rough_coat",
];

fn copper() -> ConductorDesc {
    ConductorDesc::EtaK {
        eta: Rgb::new(0.200438, 0.924033, 1.10221),
        k: Rgb::new(3.91295, 2.45285, 2.14219),
    }
}

/// pbrt-v4's defaults for the slab (thickness 0.01, no medium, 10 events, 1 walk).
fn coat(alpha: f32) -> CoatDesc {
    CoatDesc {
        eta: 1.5,
        alpha_u: alpha,
        alpha_v: alpha,
        thickness: 0.01,
        albedo: Rgb::BLACK,
        g: 0.0,
        max_depth: 10,
        samples: 1,
    }
}

fn material(name: &str) -> Material {
    let grey = Rgb::new(0.5, 0.5, 0.5);
    let desc = match name {
        "diffuse" => MaterialDesc::Diffuse { reflectance: grey },
        "mirror" => MaterialDesc::Conductor(ConductorDesc::Reflectance(Rgb::new(0.9, 0.9, 0.9))),
        "conductor" => MaterialDesc::Conductor(copper()),
        "dielectric" => MaterialDesc::Dielectric { eta: 1.5 },
        "rough_conductor" => MaterialDesc::RoughConductor {
            conductor: copper(),
            alpha_u: 0.3,
            alpha_v: 0.3,
        },
        "rough_dielectric" => MaterialDesc::RoughDielectric {
            eta: 1.5,
            alpha_u: 0.3,
            alpha_v: 0.3,
        },
        "thin_dielectric" => MaterialDesc::ThinDielectric { eta: 1.5 },
        "diffuse_transmission" => MaterialDesc::DiffuseTransmission {
            reflectance: grey,
            transmittance: grey,
        },
        "coated_diffuse_smooth" => MaterialDesc::CoatedDiffuse {
            reflectance: grey,
            coat: coat(0.0),
        },
        "coated_diffuse_rough" => MaterialDesc::CoatedDiffuse {
            reflectance: grey,
            coat: coat(0.3),
        },
        "coated_conductor" => MaterialDesc::CoatedConductor {
            conductor: copper(),
            alpha_u: 0.2,
            alpha_v: 0.2,
            coat: coat(0.0),
        },
        "coated_conductor_rough_coat" => MaterialDesc::CoatedConductor {
            conductor: copper(),
            alpha_u: 0.2,
            alpha_v: 0.2,
            coat: coat(0.3),
        },
        other => panic!("unknown material {other}"),
    };
    Material::from_desc(&desc)
}

fn random_direction(rng: &mut Pcg32) -> Vec3 {
    let z = 2.0 * rng.uniform() - 1.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.uniform();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `wo` mostly above the surface (as camera paths see it), `wi` anywhere.
fn pairs() -> Vec<(Vec3, Vec3)> {
    let mut rng = Pcg32::new(7, 1);
    (0..N)
        .map(|i| {
            let mut wo = random_direction(&mut rng);
            if i % 4 != 0 {
                wo.z = wo.z.abs();
            }
            (wo, random_direction(&mut rng))
        })
        .collect()
}

#[divan::bench(args = MATERIALS, sample_count = 20)]
fn eval(bencher: Bencher, name: &str) {
    let m = material(name);
    let pairs = pairs();
    bencher.counter(ItemsCount::new(N)).bench(|| {
        let mut acc = 0.0f32;
        for &(wo, wi) in &pairs {
            let f = m.eval_mode(divan::black_box(wo), wi, TransportMode::Radiance);
            acc += f.g + m.pdf(wo, wi);
        }
        acc
    });
}

#[divan::bench(args = MATERIALS, sample_count = 20)]
fn sample(bencher: Bencher, name: &str) {
    let m = material(name);
    let pairs = pairs();
    let mut rng = Pcg32::new(7, 2);
    let us: Vec<(f32, Vec2)> = (0..N)
        .map(|_| (rng.uniform(), Vec2::new(rng.uniform(), rng.uniform())))
        .collect();
    bencher.counter(ItemsCount::new(N)).bench(|| {
        let mut acc = 0.0f32;
        for (&(wo, _), &(u1, u2)) in pairs.iter().zip(&us) {
            if let Some(bs) = m.sample(divan::black_box(wo), u1, u2, TransportMode::Radiance) {
                acc += bs.f.g * bs.pdf;
            }
        }
        acc
    });
}
