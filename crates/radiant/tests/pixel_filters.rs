//! Pixel filters with negative lobes (Mitchell, Lanczos' windowed sinc) through a whole
//! render: sampled by |f|, their signed weights must still give each pixel the radiance
//! it sees. In the white furnace every pixel converges to Le / (1 − albedo) = 2
//! whatever its offsets, so the image must lie within its noise of 2 everywhere, and at
//! few samples no pixel may blow up where its weights nearly cancel.

use radiant::render::Overrides;
use radiant::scene::builtin::furnace;
use radiant::scene::{FilterKind, SceneDesc};

mod common;

fn with_filter(mut desc: SceneDesc, kind: FilterKind, radius: f32) -> SceneDesc {
    desc.filter.kind = kind;
    desc.filter.radius = glam::Vec2::splat(radius);
    desc
}

#[test]
fn filters_with_negative_lobes_keep_the_furnace_at_its_closed_form() {
    for (kind, radius) in [
        (
            FilterKind::Mitchell {
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
            2.0,
        ),
        (FilterKind::Mitchell { b: 0.0, c: 0.75 }, 1.5),
        (FilterKind::LanczosSinc { tau: 3.0 }, 4.0),
    ] {
        for spp in [2, 16] {
            let desc = with_filter(furnace(), kind, radius);
            let img = common::render(
                &desc,
                &Overrides {
                    spp: Some(spp),
                    seed: Some(7),
                    ..Default::default()
                },
            );
            let values: Vec<f64> = img.pixels.iter().map(|p| p[1] as f64).collect();
            // A sample's |weight| is about ∫|f| / ∫f (under 2 for these filters), and the
            // furnace's paths carry a few times 2 at most.
            let worst = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(worst < 100.0, "{kind:?} at {spp} spp: a pixel of {worst}");
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let se = sd / n.sqrt();
            assert!(
                (mean - 2.0).abs() <= 4.0 * se + 1e-4,
                "{kind:?} at {spp} spp: mean {mean} ± {se}, expected 2"
            );
        }
    }
}
