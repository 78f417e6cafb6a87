//! The light tree (`"string lightsampler" "bvh"`) on a scene made for it: 10,000 small
//! emissive triangles, each its own light, scattered low over a large floor seen from
//! above. Choosing among them by power ignores where the receiver is, so nearly every
//! light sample goes to a light far away; the tree's choice follows proximity and
//! orientation. It must change only the noise: tile means agree with a long render by
//! power sampling, and the variance at equal samples is several times lower.

use std::fmt::Write;

use radiant::image::Image;
use radiant::image::tiles::{TileCriterion, TileStats, compare_tiles};
use radiant::math::hash::Pcg32;
use radiant::scene::SceneDesc;

mod common;

const LIGHTS: usize = 10_000;
const RES: u32 = 64;

fn scene(sampler: &str) -> SceneDesc {
    let mut s = String::new();
    writeln!(
        s,
        "Integrator \"path\" \"integer maxdepth\" [ 1 ] \"string lightsampler\" \"{sampler}\"\n\
         LookAt 0 24 0  0 0 0  0 0 1\n\
         Camera \"perspective\" \"float fov\" [ 45 ]\n\
         Film \"rgb\" \"integer xresolution\" [ {RES} ] \"integer yresolution\" [ {RES} ]\n\
         WorldBegin\n\
         Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n\
         Shape \"trianglemesh\" \"point3 P\" [ -10 0 -10  10 0 -10  10 0 10  -10 0 10 ] \
         \"integer indices\" [ 0 1 2  0 2 3 ]"
    )
    .unwrap();
    let mut rng = Pcg32::new(7, 3);
    for _ in 0..LIGHTS {
        let (x, z) = (rng.uniform() * 19.0 - 9.5, rng.uniform() * 19.0 - 9.5);
        let y = 0.2 + 0.8 * rng.uniform();
        let l = [
            8.0 + 64.0 * rng.uniform(),
            8.0 + 64.0 * rng.uniform(),
            8.0 + 64.0 * rng.uniform(),
        ];
        writeln!(
            s,
            "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ {} {} {} ]\n\
             Shape \"trianglemesh\" \"point3 P\" [ {x} {y} {z}  {} {y} {z}  {x} {y} {} ] \
             \"integer indices\" [ 0 1 2 ]\nAttributeEnd",
            l[0],
            l[1],
            l[2],
            x + 0.02,
            z + 0.02
        )
        .unwrap();
    }
    radiant::scene::parse_str(&s, "many-lights.pbrt", std::path::Path::new(".")).expect("scene")
}

/// Mean over pixels and channels of the variance between passes.
fn pixel_variance(passes: &[Image]) -> f64 {
    let k = passes.len() as f64;
    let n = passes[0].pixels.len();
    let mut sum = 0.0;
    for i in 0..n {
        for c in 0..3 {
            let v: Vec<f64> = passes.iter().map(|p| p.pixels[i][c] as f64).collect();
            let m = v.iter().sum::<f64>() / k;
            sum += v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (k - 1.0);
        }
    }
    sum / (3 * n) as f64
}

#[test]
fn light_tree_is_unbiased_and_less_noisy_with_many_lights() {
    let power = scene("power");
    let tree = scene("bvh");
    let session = radiant::Session::new(&tree, &Default::default()).expect("session");
    assert_eq!(session.ctx.world.light_sampler.name(), "bvh");
    assert!(session.ctx.world.lights.len() >= LIGHTS);

    // Equal samples: the variance between passes.
    let spp = 4;
    let p = common::render_passes(&power, spp, 4);
    let t = common::render_passes(&tree, spp, 4);
    let (vp, vt) = (pixel_variance(&p), pixel_variance(&t));
    eprintln!(
        "pixel variance at {spp} spp: power {vp:.4e}, bvh {vt:.4e}, ratio {:.1}",
        vp / vt
    );
    assert!(vp > 4.0 * vt, "power {vp} vs bvh {vt}");

    // Unbiased: the tree's tiles against a long render by power sampling.
    let reference = common::render_passes(&power, 64, 4);
    let (reference, _) = TileStats::from_passes(&reference, 8).unwrap();
    let tree_passes = common::render_passes(&tree, 16, 4);
    let (stats, image) = TileStats::from_passes(&tree_passes, 8).unwrap();
    let criterion = TileCriterion {
        k: 4.0,
        rel_floor: 0.005,
        abs_floor: 0.0,
    };
    let cmp = compare_tiles(&stats, &reference, criterion, &|_, _| false).unwrap();
    common::assert_tiles("light-tree", &cmp, &image);
}
