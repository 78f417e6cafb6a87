//! `Texture` directives and texture-valued material parameters.

use std::path::Path;

use radiant_math::color::Rgb;
use radiant_scene::{
    ColorEncoding, ImageFilter, Mapping2D, MaterialDesc, SceneDesc, TextureKind, TextureType,
    TexturedMaterialDesc, TexturedParam, WrapMode, parse_str,
};

fn parse(text: &str) -> SceneDesc {
    parse_str(text, "t.pbrt", Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

fn err(text: &str) -> String {
    parse_str(text, "t.pbrt", Path::new("."))
        .unwrap_err()
        .to_string()
}

#[test]
fn classes_read_their_parameters_and_operands() {
    let s = parse(
        "WorldBegin\n\
         Texture \"amt\" \"float\" \"constant\" \"float value\" 0.25\n\
         Texture \"red\" \"spectrum\" \"constant\" \"rgb value\" [ 1 0 0 ]\n\
         Texture \"m\" \"spectrum\" \"mix\" \"texture tex1\" \"red\" \"rgb tex2\" [ 0 0 1 ] \"texture amount\" \"amt\"\n\
         Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 4 \"float udelta\" 0.5\n\
         Texture \"s\" \"float\" \"scale\" \"float tex\" 2 \"texture scale\" \"amt\"\n\
         Texture \"amt\" \"spectrum\" \"bilerp\"\n",
    );
    assert_eq!(s.textures.len(), 6);
    assert_eq!(s.textures[0].kind, TextureKind::Constant(Rgb::splat(0.25)));
    assert_eq!(s.textures[0].ty, TextureType::Float);
    assert_eq!(
        s.textures[2].kind,
        TextureKind::Mix {
            tex1: TexturedParam::Texture(1),
            tex2: TexturedParam::Constant(Rgb::new(0.0, 0.0, 1.0)),
            amount: TexturedParam::Texture(0),
        }
    );
    let TextureKind::Checkerboard2D {
        mapping,
        tex1,
        tex2,
    } = &s.textures[3].kind
    else {
        panic!("{:?}", s.textures[3].kind)
    };
    assert_eq!(
        *mapping,
        Mapping2D::Uv {
            su: 8.0,
            sv: 4.0,
            du: 0.5,
            dv: 0.0
        }
    );
    assert_eq!(
        (*tex1, *tex2),
        (
            TexturedParam::Constant(Rgb::WHITE),
            TexturedParam::Constant(Rgb::BLACK)
        )
    );
    assert_eq!(
        s.textures[4].kind,
        TextureKind::Scale {
            tex: TexturedParam::Constant(Rgb::splat(2.0)),
            scale: TexturedParam::Texture(0),
        }
    );
    // Float and spectrum names are separate namespaces.
    assert_eq!(s.textures[5].ty, TextureType::Spectrum);
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
}

#[test]
fn image_maps_take_filter_wrap_and_encoding() {
    let dir = radiant_testkit::repo_path("tests/scenes/malformed");
    let s = parse_str(
        "WorldBegin\n\
         Texture \"i\" \"spectrum\" \"imagemap\" \"string filename\" \"bad_number.pbrt\"\n\
         \"string filter\" \"ewa\" \"string wrap\" \"clamp\" \"string encoding\" \"gamma 2.2\"\n\
         \"float maxanisotropy\" 4 \"bool invert\" true \"float scale\" 2\n",
        "t.pbrt",
        &dir,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let TextureKind::ImageMap { image, .. } = &s.textures[0].kind else {
        panic!()
    };
    assert_eq!(image.filter, ImageFilter::Ewa);
    assert_eq!(image.wrap, WrapMode::Clamp);
    assert_eq!(image.encoding, Some(ColorEncoding::Gamma(2.2)));
    assert_eq!(image.max_anisotropy, 4.0);
    assert!(image.invert);
    assert_eq!(image.scale, 2.0);
    assert!(image.filename.ends_with("bad_number.pbrt"));
}

#[test]
fn textured_parameters_make_textured_materials() {
    let s = parse(
        "WorldBegin\n\
         Texture \"r\" \"float\" \"fbm\"\n\
         Texture \"k\" \"spectrum\" \"checkerboard\"\n\
         Material \"diffuse\" \"texture reflectance\" \"k\"\n\
         Material \"conductor\" \"texture roughness\" \"r\" \"float vroughness\" 0.1\n\
         Material \"dielectric\" \"texture uroughness\" \"r\" \"bool remaproughness\" false\n\
         Material \"diffuse\" \"rgb reflectance\" [ 0.1 0.2 0.3 ]\n",
    );
    assert_eq!(
        s.materials[0],
        MaterialDesc::Textured(TexturedMaterialDesc::Diffuse {
            reflectance: TexturedParam::Texture(1)
        })
    );
    let MaterialDesc::Textured(TexturedMaterialDesc::RoughConductor { roughness, .. }) =
        &s.materials[1]
    else {
        panic!("{:?}", s.materials[1])
    };
    assert_eq!(roughness.u, TexturedParam::Texture(0));
    assert_eq!(roughness.v, TexturedParam::Constant(0.1));
    assert!(roughness.remap);
    assert_eq!(roughness.alphas(0.25, 0.04), (0.5, 0.2));
    let MaterialDesc::Textured(TexturedMaterialDesc::RoughDielectric { roughness, eta }) =
        &s.materials[2]
    else {
        panic!("{:?}", s.materials[2])
    };
    assert_eq!(*eta, 1.5);
    assert!(!roughness.remap);
    assert_eq!(roughness.v, TexturedParam::Constant(0.0));
    // Constant parameters keep the plain variant.
    assert_eq!(
        s.materials[3],
        MaterialDesc::Diffuse {
            reflectance: Rgb::new(0.1, 0.2, 0.3)
        }
    );
}

#[test]
fn malformed_textures_are_located_errors() {
    for (text, at, words) in [
        (
            "WorldBegin\nTexture \"t\" \"float\" \"constant\"\nTexture \"t\" \"float\" \"constant\"\n",
            "t.pbrt:3:1",
            "defined twice",
        ),
        (
            "WorldBegin\nTexture \"t\" \"color3\" \"constant\"\n",
            "t.pbrt:2:13",
            "neither",
        ),
        (
            "WorldBegin\nTexture \"t\" \"spectrum\" \"fbm\"\n",
            "t.pbrt:2:1",
            "float texture",
        ),
        (
            "WorldBegin\nTexture \"t\" \"float\" \"checkerboard\" \"integer dimension\" 4\n",
            "t.pbrt:2:36",
            "must be 2 or 3",
        ),
        (
            "WorldBegin\nTexture \"t\" \"float\" \"bilerp\" \"string mapping\" \"cubic\"\n",
            "t.pbrt:2:30",
            "unknown mapping",
        ),
        (
            "WorldBegin\nTexture \"a\" \"spectrum\" \"dots\"\nTexture \"t\" \"spectrum\" \"scale\" \"texture scale\" \"a\"\n",
            "t.pbrt:3:32",
            "needs a float texture",
        ),
        (
            "Texture \"t\" \"float\" \"constant\"\n",
            "t.pbrt:1:1",
            "WorldBegin",
        ),
    ] {
        let e = err(text);
        assert!(e.starts_with(at), "{text}: {e}");
        assert!(e.contains(words), "{text}: {e}");
    }
}
