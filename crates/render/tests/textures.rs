//! Textures: decoding, the procedural classes' closed forms, and image filtering on a
//! checkerboard plane receding to the horizon against a supersampled reference.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use radiant_math::color::Rgb;
use radiant_render::camera::{self, RaySpread};
use radiant_render::texture::image::{decode, read_linear};
use radiant_render::texture::{TextureEvalContext, TextureSet};
use radiant_render::world::World;
use radiant_scene::{ColorEncoding, SceneDesc, parse_str};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("radiant-textures-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn parse_in(text: &str, dir: &Path) -> SceneDesc {
    parse_str(text, "t.pbrt", dir).unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn encodings_decode_to_known_linear_values() {
    // IEC 61966-2-1: 0.5 encodes 0.21404; the linear toe below 0.04045.
    assert!(close(decode(ColorEncoding::Srgb, 0.5), 0.214_04, 2e-5));
    assert!(close(decode(ColorEncoding::Srgb, 0.04), 0.04 / 12.92, 1e-7));
    assert_eq!(decode(ColorEncoding::Srgb, 0.0), 0.0);
    assert!(close(decode(ColorEncoding::Srgb, 1.0), 1.0, 1e-6));
    assert!(close(
        decode(ColorEncoding::Gamma(2.2), 0.5),
        0.5f32.powf(2.2),
        1e-6
    ));
    assert_eq!(decode(ColorEncoding::Linear, 0.3), 0.3);

    let dir = temp_dir("decode");
    let p8 = dir.join("grey8.png");
    image::RgbImage::from_pixel(2, 2, image::Rgb([128, 64, 255]))
        .save(&p8)
        .unwrap();
    let l = read_linear(&p8, None).unwrap();
    // 128/255 and 64/255 through the sRGB curve.
    assert!(close(l.at(0).r, 0.215_861, 2e-5), "{:?}", l.at(0));
    assert!(close(l.at(0).g, 0.051_269, 2e-5), "{:?}", l.at(0));
    assert!(close(l.at(0).b, 1.0, 1e-6));
    let lin = read_linear(&p8, Some(ColorEncoding::Linear)).unwrap();
    assert!(close(lin.at(3).r, 128.0 / 255.0, 1e-6));

    let p16 = dir.join("grey16.png");
    image::ImageBuffer::<image::Rgb<u16>, _>::from_pixel(1, 1, image::Rgb([32768u16, 0, 65535]))
        .save(&p16)
        .unwrap();
    let l = read_linear(&p16, None).unwrap();
    assert!(close(
        l.at(0).r,
        decode(ColorEncoding::Srgb, 32768.0 / 65535.0),
        1e-6
    ));
    assert!(close(l.at(0).r, 0.214_04, 1e-4));

    let hdr = dir.join("bright.hdr");
    image::Rgb32FImage::from_pixel(1, 1, image::Rgb([4.0f32, 0.5, 0.25]))
        .save(&hdr)
        .unwrap();
    // Float images are linear whatever the encoding says (RGBE keeps ~1% precision).
    let l = read_linear(&hdr, Some(ColorEncoding::Srgb)).unwrap();
    assert!(close(l.at(0).r, 4.0, 0.04) && close(l.at(0).b, 0.25, 0.004));
    std::fs::remove_dir_all(dir).ok();
}

/// The textures of a scene, for evaluating them directly.
fn textures(body: &str) -> (SceneDesc, TextureSet) {
    let desc = parse_in(&format!("WorldBegin\n{body}"), Path::new("."));
    let set = TextureSet::build(&desc).unwrap_or_else(|e| panic!("{e}"));
    (desc, set)
}

fn id(desc: &SceneDesc, name: &str) -> u32 {
    desc.textures.iter().position(|t| t.name == name).unwrap() as u32
}

#[test]
fn procedural_textures_match_closed_forms() {
    let (desc, set) = textures(
        "Texture \"quarter\" \"float\" \"constant\" \"float value\" 0.25\n\
         Texture \"red\" \"spectrum\" \"constant\" \"rgb value\" [ 1 0 0 ]\n\
         Texture \"mixed\" \"spectrum\" \"mix\" \"texture tex1\" \"red\" \"rgb tex2\" [ 0 0 1 ] \"texture amount\" \"quarter\"\n\
         Texture \"scaled\" \"float\" \"scale\" \"float tex\" 2 \"texture scale\" \"quarter\"\n\
         Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2 \"rgb tex1\" [ 1 1 1 ] \"rgb tex2\" [ 0 0 0 ]\n\
         Texture \"corners\" \"spectrum\" \"bilerp\" \"rgb v00\" [ 1 0 0 ] \"rgb v01\" [ 0 1 0 ] \"rgb v10\" [ 0 0 1 ] \"rgb v11\" [ 1 1 1 ]\n\
         Texture \"facing\" \"spectrum\" \"directionmix\" \"vector3 dir\" [ 0 0 1 ] \"rgb tex1\" [ 1 0 0 ] \"rgb tex2\" [ 0 1 0 ]\n\
         Texture \"cubes\" \"float\" \"checkerboard\" \"integer dimension\" 3\n\
         Texture \"wr\" \"float\" \"wrinkled\"\n",
    );
    let at = |name: &str, ctx: &TextureEvalContext| set.eval(id(&desc, name), ctx);
    let uv = |u: f32, v: f32| TextureEvalContext::at_uv(Vec2::new(u, v));
    assert_eq!(at("mixed", &uv(0.3, 0.3)), Rgb::new(0.75, 0.0, 0.25));
    assert_eq!(at("scaled", &uv(0.3, 0.3)), Rgb::splat(0.5));
    // Parity of floor(s) + floor(t): s = 2u, t = 2v.
    for (u, v, white) in [
        (0.25, 0.25, true),
        (0.75, 0.25, false),
        (0.25, 0.75, false),
        (0.75, 0.75, true),
    ] {
        let expect = if white { Rgb::WHITE } else { Rgb::BLACK };
        assert_eq!(at("checks", &uv(u, v)), expect, "({u}, {v})");
    }
    // A footprint of many squares averages to half (box-filtered closed form).
    let mut wide = uv(0.3, 0.6);
    (wide.dudx, wide.dvdy) = (7.3, 5.1);
    assert!(
        close(at("checks", &wide).r, 0.5, 0.03),
        "{:?}",
        at("checks", &wide)
    );
    // Exactly half a square inside the footprint: a quarter of the way to the other value.
    let mut half = uv(0.25, 0.25);
    half.dudx = 0.25; // s ∈ [0, 1] lies on one square in s ...
    assert!(close(at("checks", &half).r, 1.0, 1e-5));
    half.dudx = 0.5; // ... s ∈ [−0.5, 1.5]: half of it on each parity.
    assert!(close(at("checks", &half).r, 0.5, 1e-5));
    for (u, v, c) in [
        (0.0, 0.0, Rgb::new(1.0, 0.0, 0.0)),
        (0.0, 1.0, Rgb::new(0.0, 1.0, 0.0)),
        (1.0, 0.0, Rgb::new(0.0, 0.0, 1.0)),
        (1.0, 1.0, Rgb::WHITE),
        (0.5, 0.5, Rgb::new(0.5, 0.5, 0.5)),
    ] {
        let got = at("corners", &uv(u, v));
        assert!(
            (0..3).all(|k| close(got[k], c[k], 1e-6)),
            "({u}, {v}): {got:?}"
        );
    }
    let mut facing = uv(0.0, 0.0);
    facing.n = Vec3::Z;
    assert_eq!(at("facing", &facing), Rgb::new(1.0, 0.0, 0.0));
    facing.n = Vec3::X;
    assert_eq!(at("facing", &facing), Rgb::new(0.0, 1.0, 0.0));
    let mut p = uv(0.0, 0.0);
    for (q, odd) in [
        (Vec3::new(0.5, 0.5, 0.5), false),
        (Vec3::new(1.5, 0.5, 0.5), true),
        (Vec3::new(1.5, -0.5, 0.5), false),
    ] {
        p.p = q;
        assert_eq!(at("cubes", &p).r, if odd { 0.0 } else { 1.0 }, "{q}");
    }
    // Turbulence sums |noise|: never negative, zero at the lattice.
    p.p = Vec3::new(3.0, -2.0, 7.0);
    assert_eq!(at("wr", &p).r, 0.0);
    p.p = Vec3::new(0.37, 0.71, 0.13);
    assert!(at("wr", &p).r > 0.0);
    // Radiosity's patch value: the mean over (u, v).
    assert!(close(
        set.uv_average(
            radiant_scene::TexturedParam::Texture(id(&desc, "checks")),
            16
        )
        .r,
        0.5,
        1e-6
    ));
}

#[test]
fn unreadable_images_are_located_errors() {
    let dir = temp_dir("broken");
    std::fs::write(dir.join("broken.png"), b"not a png at all").unwrap();
    let desc = parse_in(
        "WorldBegin\n\nTexture \"b\" \"spectrum\" \"imagemap\" \"string filename\" \"broken.png\"\n\
         Material \"diffuse\" \"texture reflectance\" \"b\"\n\
         Shape \"sphere\"\n",
        &dir,
    );
    let e = World::build(&desc).err().expect("an error").to_string();
    assert!(e.starts_with("t.pbrt:3:1"), "{e}");
    assert!(
        e.contains("broken.png") && e.contains("cannot read image"),
        "{e}"
    );
    std::fs::remove_dir_all(dir).ok();
}

const W: u32 = 128;
const H: u32 = 96;

/// A 256² image of 2 × 2-texel checks (0 and 1, stored linear), repeated 10 times over a
/// 200 × 200 floor seen from 1 unit above it: magnified near the camera, hundreds of
/// texels per pixel near the horizon.
fn floor_scene(dir: &Path, filter: &str) -> SceneDesc {
    let text = format!(
        "LookAt 0 1 0  0 0.7 10  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
         Film \"rgb\" \"integer xresolution\" {W} \"integer yresolution\" {H}\nWorldBegin\n\
         Texture \"checks\" \"spectrum\" \"imagemap\" \"string filename\" \"checks.png\"\n\
         \"string filter\" \"{filter}\" \"string encoding\" \"linear\" \"float uscale\" 10 \"float vscale\" 10\n\
         Material \"diffuse\" \"texture reflectance\" \"checks\"\n\
         Shape \"trianglemesh\" \"point3 P\" [ -100 0 -1  100 0 -1  100 0 199  -100 0 199 ]\n\
         \"point2 uv\" [ 0 0  1 0  1 1  0 1 ] \"integer indices\" [ 0 1 2  0 2 3 ]\n"
    );
    parse_in(&text, dir)
}

struct FloorImage {
    values: Vec<Option<f32>>,
    distance: Vec<f32>,
}

/// The floor's reflectance seen through each pixel: one ray through the pixel centre
/// with the camera's footprint (`supersample` = 1), or the mean of n × n stratified
/// point lookups (the reference).
fn render_floor(desc: &SceneDesc, supersample: u32) -> FloorImage {
    let (mut world, _) = World::build(desc).unwrap_or_else(|e| panic!("{e}"));
    let mut warnings = Vec::new();
    let cam = camera::from_desc(&desc.camera, &desc.film, (W, H), &mut warnings).unwrap();
    world.ray_spread = RaySpread::of_camera(&cam, (W, H), 1);
    let mut values = Vec::new();
    let mut distance = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let n = supersample;
            let (mut sum, mut hits, mut dist) = (0.0f64, 0, 0.0f32);
            for j in 0..n {
                for i in 0..n {
                    let raster = Vec2::new(
                        x as f32 + (i as f32 + 0.5) / n as f32,
                        y as f32 + (j as f32 + 0.5) / n as f32,
                    );
                    let ray = cam.generate_ray(raster, Vec2::splat(0.5)).unwrap().ray;
                    // One ray per pixel filters by its footprint; the supersampled
                    // reference takes point lookups.
                    let hit = if n == 1 {
                        world.intersect_with_footprint(&ray, f32::INFINITY, 0.0)
                    } else {
                        world.intersect(&ray, f32::INFINITY)
                    };
                    let Some(hit) = hit else {
                        continue;
                    };
                    let travelled = hit.t * ray.d.length();
                    sum += world.material_at(&hit, -ray.d).diffuse_albedo().r as f64;
                    hits += 1;
                    dist = travelled;
                }
            }
            // Pixels the floor covers entirely (the horizon row is left out).
            values.push((hits == n * n).then(|| (sum / hits as f64) as f32));
            distance.push(dist);
        }
    }
    FloorImage { values, distance }
}

struct FloorStats {
    rmse: f64,
    far_mean: f64,
    far_tile_variance: f64,
}

/// RMSE against the reference over the floor, and in the far field (distance > 15, well
/// past where a pixel covers many texels): the mean and the mean variance within 8 × 8
/// tiles.
fn floor_stats(img: &FloorImage, reference: &FloorImage) -> FloorStats {
    let (mut se, mut n) = (0.0f64, 0usize);
    for (a, b) in img.values.iter().zip(&reference.values) {
        if let (Some(a), Some(b)) = (a, b) {
            se += ((a - b) as f64).powi(2);
            n += 1;
        }
    }
    let (mut far_sum, mut far_n) = (0.0f64, 0usize);
    let (mut var_sum, mut tiles) = (0.0f64, 0usize);
    for ty in 0..H / 8 {
        for tx in 0..W / 8 {
            let mut v = Vec::new();
            for y in ty * 8..ty * 8 + 8 {
                for x in tx * 8..tx * 8 + 8 {
                    let i = (y * W + x) as usize;
                    if let (Some(a), Some(_)) = (img.values[i], reference.values[i])
                        && reference.distance[i] > 15.0
                    {
                        v.push(a as f64);
                    }
                }
            }
            far_sum += v.iter().sum::<f64>();
            far_n += v.len();
            if v.len() >= 16 {
                let m = v.iter().sum::<f64>() / v.len() as f64;
                var_sum += v.iter().map(|a| (a - m).powi(2)).sum::<f64>() / v.len() as f64;
                tiles += 1;
            }
        }
    }
    assert!(
        n > 4000 && far_n > 300 && tiles >= 8,
        "{n} floor, {far_n} far pixels, {tiles} tiles"
    );
    FloorStats {
        rmse: (se / n as f64).sqrt(),
        far_mean: far_sum / far_n as f64,
        far_tile_variance: var_sum / tiles as f64,
    }
}

#[test]
fn filtering_a_receding_checkerboard_converges_to_grey_where_point_sampling_aliases() {
    let dir = temp_dir("floor");
    let checks = image::RgbImage::from_fn(256, 256, |x, y| {
        image::Rgb([if (x / 2 + y / 2) % 2 == 0 { 255 } else { 0 }; 3])
    });
    checks.save(dir.join("checks.png")).unwrap();
    let reference = render_floor(&floor_scene(&dir, "point"), 16);
    let stats: Vec<(&str, FloorStats)> = ["point", "bilinear", "trilinear", "ewa"]
        .into_iter()
        .map(|f| {
            (
                f,
                floor_stats(&render_floor(&floor_scene(&dir, f), 1), &reference),
            )
        })
        .collect();
    let reference_stats = floor_stats(&reference, &reference);
    for (f, s) in &stats {
        eprintln!(
            "{f:9}: rmse vs 16x16-supersampled {:.4}, far-field mean {:.4}, tile variance {:.5}",
            s.rmse, s.far_mean, s.far_tile_variance
        );
    }
    eprintln!(
        "reference: far-field mean {:.4}, tile variance {:.5}",
        reference_stats.far_mean, reference_stats.far_tile_variance
    );
    let get = |name: &str| &stats.iter().find(|(f, _)| *f == name).unwrap().1;
    let (point, bilinear, trilinear, ewa) =
        (get("point"), get("bilinear"), get("trilinear"), get("ewa"));
    // The reference itself is grey in the far field.
    assert!((reference_stats.far_mean - 0.5).abs() < 0.02);
    assert!(reference_stats.far_tile_variance < 0.005);
    // Unfiltered lookups pick 0 or 1 at random: tile variance near 1/4.
    for s in [point, bilinear] {
        assert!(s.far_tile_variance > 0.1, "{}", s.far_tile_variance);
    }
    // Prefiltered: grey, little variance.
    for s in [trilinear, ewa] {
        assert!((s.far_mean - 0.5).abs() < 0.03, "{}", s.far_mean);
        assert!(s.far_tile_variance < 0.01, "{}", s.far_tile_variance);
        assert!(
            s.rmse < 0.6 * point.rmse,
            "{} vs point {}",
            s.rmse,
            point.rmse
        );
    }
    // Each filter against the reference over the whole floor (measured: point 0.387,
    // bilinear 0.256, trilinear 0.197, EWA 0.115).
    assert!(
        point.rmse < 0.45 && bilinear.rmse < 0.32,
        "{} {}",
        point.rmse,
        bilinear.rmse
    );
    assert!(bilinear.rmse < point.rmse);
    assert!(trilinear.rmse < 0.25, "{}", trilinear.rmse);
    // EWA blurs less across the grazing direction than trilinear's isotropic footprint.
    assert!(
        ewa.rmse < 0.15 && ewa.rmse < 0.75 * trilinear.rmse,
        "{} vs {}",
        ewa.rmse,
        trilinear.rmse
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn mappings_give_their_closed_form_coordinates() {
    // bilerp with these corners returns (s, t, 0): it shows the mapping's coordinates.
    let corners =
        "\"rgb v00\" [ 0 0 0 ] \"rgb v10\" [ 1 0 0 ] \"rgb v01\" [ 0 1 0 ] \"rgb v11\" [ 1 1 0 ]";
    let (desc, set) = textures(&format!(
        "Texture \"uv\" \"spectrum\" \"bilerp\" {corners} \"float uscale\" 2 \"float vscale\" 3 \"float udelta\" 0.1 \"float vdelta\" -0.2\n\
         Texture \"planar\" \"spectrum\" \"bilerp\" {corners} \"string mapping\" \"planar\" \"vector3 v1\" [ 0 0 1 ] \"vector3 v2\" [ 1 0 0 ] \"float udelta\" 0.25\n\
         Texture \"sphere\" \"spectrum\" \"bilerp\" {corners} \"string mapping\" \"spherical\"\n\
         AttributeBegin\nTranslate 0 0 5\n\
         Texture \"cylinder\" \"spectrum\" \"bilerp\" {corners} \"string mapping\" \"cylindrical\"\n\
         AttributeEnd\n"
    ));
    let st = |name: &str, ctx: &TextureEvalContext| {
        let c = set.eval(id(&desc, name), ctx);
        Vec2::new(c.r, c.g)
    };
    let near = |a: Vec2, b: Vec2| (a - b).length() < 1e-5;
    let mut ctx = TextureEvalContext::at_uv(Vec2::new(0.2, 0.4));
    assert!(
        near(st("uv", &ctx), Vec2::new(0.5, 1.0)),
        "{}",
        st("uv", &ctx)
    );
    ctx.p = Vec3::new(0.3, 7.0, 0.2);
    assert!(
        near(st("planar", &ctx), Vec2::new(0.45, 0.3)),
        "{}",
        st("planar", &ctx)
    );
    // Spherical: s = θ/π from +z, t = φ/2π from +x.
    ctx.p = Vec3::new(0.0, 2.0, 0.0);
    assert!(
        near(st("sphere", &ctx), Vec2::new(0.5, 0.25)),
        "{}",
        st("sphere", &ctx)
    );
    ctx.p = Vec3::new(0.0, 0.0, -3.0);
    assert!(
        near(st("sphere", &ctx), Vec2::new(1.0, 0.0)),
        "{}",
        st("sphere", &ctx)
    );
    // Cylindrical, in the texture's space (translated by 5 along z): s = (π + φ)/2π, t = z.
    ctx.p = Vec3::new(-1.0, 0.0, 5.5);
    assert!(
        near(st("cylinder", &ctx), Vec2::new(1.0, 0.5)),
        "{}",
        st("cylinder", &ctx)
    );
    ctx.p = Vec3::new(1.0, 0.0, 5.25);
    assert!(
        near(st("cylinder", &ctx), Vec2::new(0.5, 0.25)),
        "{}",
        st("cylinder", &ctx)
    );
}

#[test]
fn coated_diffuse_reads_its_reflectance_texture_at_each_hit() {
    use radiant_render::geometry::Ray;
    let dir = temp_dir("coated");
    let scene = |reflectance: &str| {
        format!(
            r#"WorldBegin
Texture "c" "spectrum" "checkerboard" "rgb tex1" [0.9 0.9 0.9] "rgb tex2" [0.1 0.1 0.1]
Material "coateddiffuse" {reflectance} "float roughness" 0.1
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [0 0 0  1 0 0  1 1 0  0 1 0] "point2 uv" [0 0 2 0 2 2 0 2]
"#
        )
    };
    let albedo_at = |desc: &SceneDesc, x: f32, y: f32| {
        let (world, _) = World::build(desc).unwrap_or_else(|e| panic!("{e}"));
        let ray = Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0));
        let hit = world.intersect(&ray, f32::INFINITY).expect("the square");
        world.material_at(&hit, Vec3::Z).diffuse_albedo()
    };
    let textured = parse_in(&scene(r#""texture reflectance" "c""#), &dir);
    assert!(textured.warnings.is_empty(), "{:?}", textured.warnings);
    // uv spans [0, 2]²: (0.25, 0.25) is in check (0, 0) (tex1), (0.75, 0.25) in (1, 0).
    let light = parse_in(&scene(r#""rgb reflectance" [0.9 0.9 0.9]"#), &dir);
    let dark = parse_in(&scene(r#""rgb reflectance" [0.1 0.1 0.1]"#), &dir);
    assert_eq!(
        albedo_at(&textured, 0.25, 0.25),
        albedo_at(&light, 0.25, 0.25)
    );
    assert_eq!(
        albedo_at(&textured, 0.75, 0.25),
        albedo_at(&dark, 0.75, 0.25)
    );
    assert!(albedo_at(&light, 0.5, 0.5).r > 2.0 * albedo_at(&dark, 0.5, 0.5).r);
}

#[test]
fn diffuse_transmission_reads_its_textures_at_each_hit_times_scale() {
    use radiant_render::geometry::Ray;
    use radiant_render::material::Material;
    let dir = temp_dir("transmission");
    let desc = parse_in(
        r#"WorldBegin
Texture "c" "spectrum" "checkerboard" "rgb tex1" [0.8 0.8 0.8] "rgb tex2" [0.2 0.2 0.2]
Material "diffusetransmission" "texture reflectance" "c" "rgb transmittance" [0.4 0.4 0.4]
  "float scale" 0.5
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
  "point3 P" [0 0 0  1 0 0  1 1 0  0 1 0] "point2 uv" [0 0 2 0 2 2 0 2]
"#,
        &dir,
    );
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let (world, _) = World::build(&desc).unwrap_or_else(|e| panic!("{e}"));
    let at = |x: f32, y: f32| {
        let ray = Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0));
        let hit = world.intersect(&ray, f32::INFINITY).expect("the square");
        world.material_at(&hit, Vec3::Z)
    };
    let want = |r: f32| Material::DiffuseTransmission {
        reflectance: Rgb::splat(r * 0.5),
        transmittance: Rgb::splat(0.2),
    };
    assert_eq!(at(0.25, 0.25), want(0.8));
    assert_eq!(at(0.75, 0.25), want(0.2));
}

/// Every parameter pbrt-v4 lets a texture give to the layered materials and
/// conductors: at a hit in either check of a checkerboard the material is exactly the
/// one with that check's constant, and the two constants give different materials.
#[test]
fn layered_and_conductor_parameters_take_textures() {
    use radiant_render::geometry::Ray;
    let dir = temp_dir("layered-params");
    let cases = [
        ("coateddiffuse", "float", "thickness", "0.01", "0.3"),
        ("coateddiffuse", "float", "g", "-0.5", "0.7"),
        (
            "coateddiffuse",
            "spectrum",
            "albedo",
            "[0.2 0.3 0.4]",
            "[0.8 0.7 0.6]",
        ),
        ("coateddiffuse", "float", "roughness", "0", "0.3"),
        (
            "coatedconductor",
            "float",
            "interface.roughness",
            "0.05",
            "0.4",
        ),
        (
            "coatedconductor",
            "float",
            "conductor.roughness",
            "0",
            "0.2",
        ),
        (
            "coatedconductor",
            "spectrum",
            "conductor.eta",
            "[0.2 0.9 1.1]",
            "[1.5 1.0 0.5]",
        ),
        (
            "coatedconductor",
            "spectrum",
            "reflectance",
            "[0.9 0.5 0.2]",
            "[0.3 0.6 0.9]",
        ),
        (
            "conductor",
            "spectrum",
            "reflectance",
            "[0.9 0.5 0.2]",
            "[0.3 0.6 0.9]",
        ),
        ("conductor", "spectrum", "k", "[3 2.5 2]", "[1 1.2 1.4]"),
    ];
    for (ty, kind, param, a, b) in cases {
        let value = |v: &str| {
            if kind == "float" {
                format!("\"float {param}\" {v}")
            } else {
                format!("\"rgb {param}\" {v}")
            }
        };
        let tex_value = |name: &str, v: &str| {
            if kind == "float" {
                format!("\"float {name}\" {v}")
            } else {
                format!("\"rgb {name}\" {v}")
            }
        };
        // The coat's medium scatters, so that g and the albedo matter.
        let extra = if ty == "coateddiffuse" && param != "albedo" {
            "\"rgb albedo\" [0.5 0.5 0.5]"
        } else {
            ""
        };
        let scene = |material_param: &str| {
            format!(
                "WorldBegin\n\
                 Texture \"t\" \"{kind}\" \"checkerboard\" {} {}\n\
                 Material \"{ty}\" {material_param} {extra}\n\
                 Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \
                   \"point3 P\" [0 0 0  1 0 0  1 1 0  0 1 0] \"point2 uv\" [0 0 2 0 2 2 0 2]\n",
                tex_value("tex1", a),
                tex_value("tex2", b)
            )
        };
        let material_at = |desc: &SceneDesc, x: f32, y: f32| {
            let (world, _) = World::build(desc).unwrap_or_else(|e| panic!("{e}"));
            let ray = Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0));
            let hit = world.intersect(&ray, f32::INFINITY).expect("the square");
            world.material_at(&hit, Vec3::Z)
        };
        let textured = parse_in(&scene(&format!("\"texture {param}\" \"t\"")), &dir);
        assert!(
            textured.warnings.is_empty(),
            "{ty} {param}: {:?}",
            textured.warnings
        );
        let first = parse_in(&scene(&value(a)), &dir);
        let second = parse_in(&scene(&value(b)), &dir);
        let (m1, m2) = (
            material_at(&first, 0.25, 0.25),
            material_at(&second, 0.75, 0.25),
        );
        assert_ne!(m1, m2, "{ty} {param}: the two values give one material");
        assert_eq!(
            material_at(&textured, 0.25, 0.25),
            m1,
            "{ty} {param} in check 1"
        );
        assert_eq!(
            material_at(&textured, 0.75, 0.25),
            m2,
            "{ty} {param} in check 2"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A far sphere and disk under a fine checker image, one ray per pixel with the
/// camera's footprint: their (u, v) derivatives come from ∂p/∂u and ∂p/∂v, so
/// trilinear and EWA filtering average the checks to grey in every covered pixel,
/// where point lookups alias (half the pixels black, half white).
#[test]
fn quadrics_filter_to_grey_by_their_uv_footprint() {
    let dir = temp_dir("quadrics");
    let checks = image::RgbImage::from_fn(256, 256, |x, y| {
        image::Rgb([if (x / 2 + y / 2) % 2 == 0 { 255 } else { 0 }; 3])
    });
    checks.save(dir.join("checks.png")).unwrap();
    const N: u32 = 64;
    for (shape, placement) in [
        ("Shape \"sphere\" \"float radius\" 1", "Rotate 90 1 0 0"),
        ("Shape \"disk\" \"float radius\" 1", ""),
        (
            "Shape \"sphere\" \"float radius\" 1 \"float zmin\" -0.5 \"float zmax\" 0.8",
            "Rotate 70 1 0 0",
        ),
    ] {
        let mut variance = Vec::new();
        for filter in ["point", "trilinear", "ewa"] {
            let desc = parse_in(
                &format!(
                    "LookAt 0 0 60  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 4\n\
                     Film \"rgb\" \"integer xresolution\" {N} \"integer yresolution\" {N}\n\
                     WorldBegin\n\
                     Texture \"checks\" \"spectrum\" \"imagemap\" \"string filename\" \"checks.png\" \
                       \"string filter\" \"{filter}\" \"string encoding\" \"linear\" \
                       \"float uscale\" 4 \"float vscale\" 2\n\
                     Material \"diffuse\" \"texture reflectance\" \"checks\"\n\
                     {placement}\n{shape}\n"
                ),
                &dir,
            );
            let (mut world, _) = World::build(&desc).unwrap_or_else(|e| panic!("{e}"));
            let mut warnings = Vec::new();
            let cam = camera::from_desc(&desc.camera, &desc.film, (N, N), &mut warnings).unwrap();
            world.ray_spread = RaySpread::of_camera(&cam, (N, N), 1);
            let mut values = Vec::new();
            for y in 0..N {
                for x in 0..N {
                    // Pixels whose four corners all hit the shape: fully covered.
                    let corner_hits =
                        [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                            .iter()
                            .all(|&(dx, dy)| {
                                let r = Vec2::new(x as f32 + dx, y as f32 + dy);
                                let ray = cam.generate_ray(r, Vec2::splat(0.5)).unwrap().ray;
                                world.intersect(&ray, f32::INFINITY).is_some()
                            });
                    if !corner_hits {
                        continue;
                    }
                    let raster = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let ray = cam.generate_ray(raster, Vec2::splat(0.5)).unwrap().ray;
                    let hit = world
                        .intersect_with_footprint(&ray, f32::INFINITY, 0.0)
                        .unwrap();
                    values.push(world.material_at(&hit, -ray.d).diffuse_albedo().r as f64);
                }
            }
            assert!(
                values.len() > 100,
                "{shape}: {} covered pixels",
                values.len()
            );
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64;
            assert!((mean - 0.5).abs() < 0.1, "{shape} {filter}: mean {mean}");
            variance.push(var);
        }
        let [point, trilinear, ewa] = variance[..] else {
            unreachable!()
        };
        assert!(point > 0.1, "{shape}: point lookups should alias: {point}");
        assert!(
            trilinear < 0.01 && ewa < 0.01,
            "{shape}: filtered variance {trilinear} (trilinear), {ewa} (EWA)"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
