//! Glossy surfaces where the photon integrators end their camera paths: a varnished
//! (coated diffuse, near-specular coat) and a rough-metal sphere alone in a uniform
//! environment. The objects are convex, so every photon leaves after one bounce and
//! what the camera sees is direct light only: the light sample and the BSDF sample at
//! the visible point (SPPM) or estimate point (photon mapper). With the light sample
//! alone, the environment's reflection in the coat's narrow lobe arrives in rare, very
//! bright samples, and at these counts the spheres' tiles fall short of the path
//! tracer's (Bitterli's material-testball lost 20–50 % of the ball's light that way).
//! And a conductor too polished for a photon estimate, which passes camera paths on,
//! and a varnish that narrow over the room's walls, whose two parts the photon
//! integrators take apart.

use radiant::image::Image;
use radiant::image::tiles::{TileCriterion, TileStats, compare_tiles};
use radiant::math::color::Rgb;
use radiant::scene::builtin::cornell_caustics;
use radiant::scene::params::{ParamSet, ParamValue};
use radiant::scene::{CoatDesc, MaterialDesc, SceneDesc};

use crate::common;
use crate::rough_glass::{photon_methods_match_the_path_tracer, roughened};
use crate::scenes::with_integrator;

const RES: u32 = 32;
const TILE: usize = 4;
const PASSES: u64 = 4;

/// A sphere of `material` (a pbrt `Material` line) filling most of an orthographic view,
/// in a uniform white environment.
fn sphere_in_white(material: &str) -> SceneDesc {
    let text = format!(
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-1.25 1.25 -1.25 1.25]
Film "rgb" "integer xresolution" {RES} "integer yresolution" {RES}
PixelFilter "box" "float xradius" 0.5 "float yradius" 0.5
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
{material}
Shape "sphere" "float radius" 1
"#
    );
    radiant::scene::parse_str(&text, "glossy.pbrt", std::path::Path::new(".")).expect("parses")
}

fn passes(desc: &SceneDesc, spp: u32) -> (TileStats, Image) {
    TileStats::from_passes(&common::render_passes(desc, spp, PASSES), TILE).unwrap()
}

/// Path tracer (4 × 128 spp) against SPPM (4 × 32 iterations) and the photon mapper
/// (4 × 8 spp), tile by tile: within 4 standard errors of the two images plus 0.5 % of
/// the path tracer's mean (no density estimate enters: there are no photons to gather).
#[test]
fn glossy_visible_points_see_the_light_their_lobes_reflect() {
    const CRITERION: TileCriterion = TileCriterion {
        k: 4.0,
        rel_floor: 0.005,
        abs_floor: 0.0,
    };
    for (name, material) in [
        (
            "varnish",
            r#"Material "coateddiffuse" "rgb reflectance" [0.5 0.3 0.1] "float roughness" 0.001 "bool remaproughness" false"#,
        ),
        (
            "rough-metal",
            r#"Material "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float roughness" 0.2 "bool remaproughness" false"#,
        ),
    ] {
        let scene = sphere_in_white(material);
        let depth = ParamSet::new().with("maxdepth", ParamValue::Int(vec![8]));
        let path = with_integrator(scene.clone(), "path", depth.clone(), None);
        let (reference, _) = passes(&path, 128);

        let sppm = with_integrator(scene.clone(), "sppm", depth.clone(), None);
        let (s, s_img) = passes(&sppm, 32);
        let cmp = compare_tiles(&s, &reference, CRITERION, &|_, _| false).unwrap();
        common::assert_tiles(&format!("glossy-{name}-sppm"), &cmp, &s_img);

        let params = depth
            .with("photons", ParamValue::Int(vec![20_000]))
            .with("causticphotons", ParamValue::Int(vec![20_000]))
            .with("finalgathersamples", ParamValue::Int(vec![4]));
        let pm = with_integrator(scene, "photonmap", params, None);
        let (p, p_img) = passes(&pm, 8);
        let cmp = compare_tiles(&p, &reference, CRITERION, &|_, _| false).unwrap();
        common::assert_tiles(&format!("glossy-{name}-photonmap"), &cmp, &p_img);
    }
}

/// cornell-caustics with its glass made rough (as in `rough_glass`) and its mirror a
/// polished metal (alpha 0.03, below `NARROW_LOBE_ALPHA`): the room reflected in the
/// metal is indirect light, which a photon estimate on the metal would weigh by a lobe
/// peaking near 1 / (π α²) ≈ 350, a few photons making fireflies. The metal passes
/// camera paths on instead, and SPPM and the photon mapper match the path tracer tile by
/// tile (`photon_methods_match_the_path_tracer`), and SPPM's tiles are no noisier than
/// the path tracer's.
#[test]
fn polished_metal_passes_camera_paths_on() {
    let mut scene = roughened(cornell_caustics());
    let mut found = 0;
    for m in &mut scene.materials {
        if let MaterialDesc::Conductor(c) = m {
            *m = MaterialDesc::RoughConductor {
                conductor: c.clone(),
                alpha_u: 0.03,
                alpha_v: 0.03,
            };
            found += 1;
        }
    }
    assert_eq!(found, 1, "one mirror expected");
    let (reference, s) = photon_methods_match_the_path_tracer(scene, "polished-metal");
    // Without the pass-through the fireflies show as noise: SPPM's summed tile
    // variance was 18 times the path tracer's (2.9e-3 against 1.6e-4); with it, 0.6
    // times (9.8e-5).
    assert_no_noisier_than_twice(&s, &reference);
}

/// SPPM's summed variance of its tile means is below twice the path tracer's.
fn assert_no_noisier_than_twice(sppm: &TileStats, reference: &TileStats) {
    let summed = |t: &TileStats| t.var.iter().map(|v| v[0] + v[1] + v[2]).sum::<f64>();
    assert!(
        summed(sppm) < 2.0 * summed(reference),
        "SPPM tile variance {:.3e} against the path tracer's {:.3e}",
        summed(sppm),
        summed(reference)
    );
}

/// cornell-caustics with rough glass and its white walls, floor and ceiling varnished:
/// a coat of alpha 0.001 over the white base. The coat reflects the room and the
/// glass's caustic (indirect light the photons would carry), with a lobe peaking near
/// 1 / (π α²) ≈ 3 × 10⁵. The photon integrators follow the coat's reflection with the
/// camera path and gather photons for the light under the coat only; both match the path
/// tracer tile by tile (`photon_methods_match_the_path_tracer`) and SPPM's tiles are
/// no noisier than twice the path tracer's.
#[test]
fn varnished_walls_gather_photons_under_the_coat() {
    let mut scene = roughened(cornell_caustics());
    let MaterialDesc::Diffuse { reflectance } = scene.materials[0] else {
        panic!("the room's first material is its white diffuse");
    };
    scene.materials[0] = MaterialDesc::CoatedDiffuse {
        reflectance,
        coat: CoatDesc {
            eta: 1.5,
            alpha_u: 0.001,
            alpha_v: 0.001,
            thickness: 0.01,
            albedo: Rgb::BLACK,
            g: 0.0,
            max_depth: 10,
            samples: 1,
        },
    };
    let (reference, s) = photon_methods_match_the_path_tracer(scene, "varnished-walls");
    assert_no_noisier_than_twice(&s, &reference);
}
