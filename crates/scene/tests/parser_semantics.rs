//! Defaults, materials, lights and warnings of the pbrt-v4 reader.

use std::path::Path;

use radiant_math::color::Rgb;
use radiant_math::{PI, Vec2, Vec3};
use radiant_scene::named_spectra::metal_spectrum;
use radiant_scene::spectrum::blackbody_rgb;
use radiant_scene::{
    CameraKind, CoatDesc, ConductorDesc, DigitRandomization, FilterKind, Geometry, LightDesc,
    MaterialDesc, RoughnessDesc, SamplerKind, SceneDesc, TexturedCoatDesc, TexturedMaterialDesc,
    TexturedParam, parse_str,
};

fn parse(text: &str) -> SceneDesc {
    parse_str(text, "t.pbrt", Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

fn err(text: &str) -> String {
    parse_str(text, "t.pbrt", Path::new("."))
        .unwrap_err()
        .to_string()
}

/// Relative tolerance for values that pass through a few f32 operations.
fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-5 * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn absent_directives_take_pbrt_v4_defaults() {
    let s = parse("WorldBegin\n");
    assert!(s.camera.camera_from_world.is_identity());
    assert!(matches!(
        s.camera.kind,
        CameraKind::Perspective {
            fov_deg: 90.0,
            lens_radius: 0.0,
            ..
        }
    ));
    assert_eq!((s.film.xresolution, s.film.yresolution), (1280, 720));
    assert_eq!(s.film.filename.as_deref(), Some("pbrt.exr"));
    assert_eq!(
        (s.sampler.kind, s.sampler.pixel_samples),
        (SamplerKind::Sobol, 16)
    );
    assert_eq!(s.filter.kind, FilterKind::Gaussian { sigma: 0.5 });
    assert_eq!(s.filter.radius, Vec2::splat(1.5));
    assert_eq!(s.integrator.name, "path");
    assert_eq!(s.integrator.params.int("maxdepth", 0).unwrap(), 5);
    assert!(s.warnings.is_empty());
}

#[test]
fn options_are_read_with_their_defaults() {
    let s = parse(
        "Camera \"perspective\" \"float fov\" 45 \"float frameaspectratio\" 2\n\
         Film \"rgb\" \"integer xresolution\" 300 \"float iso\" 400\n\
         Sampler \"stratified\" \"integer xsamples\" 3 \"integer ysamples\" 5 \"bool jitter\" false\n\
         PixelFilter \"triangle\" \"float yradius\" 1\nIntegrator \"bdpt\" \"integer maxdepth\" 7\nWorldBegin\n",
    );
    match s.camera.kind {
        CameraKind::Perspective {
            fov_deg,
            screen_window,
            ..
        } => {
            assert_eq!(fov_deg, 45.0);
            assert_eq!(screen_window, Some([-2.0, 2.0, -1.0, 1.0]));
        }
        k => panic!("{k:?}"),
    }
    assert_eq!(
        (s.film.xresolution, s.film.yresolution, s.film.iso),
        (300, 720, 400.0)
    );
    assert_eq!(s.sampler.pixel_samples, 15);
    assert_eq!(
        s.sampler.kind,
        SamplerKind::Stratified {
            x: 3,
            y: 5,
            jitter: false
        }
    );
    assert_eq!(s.filter.radius, Vec2::new(2.0, 1.0));
    // The integrator's parameters are left for the integrator to use and report.
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn samplers_read_their_randomization() {
    let kind = |text: &str| parse(&format!("{text}\nWorldBegin\n")).sampler.kind;
    let halton = |randomization| SamplerKind::Halton { randomization };
    assert_eq!(
        kind("Sampler \"halton\""),
        halton(DigitRandomization::PermuteDigits)
    );
    for (name, r) in [
        ("none", DigitRandomization::None),
        ("permutedigits", DigitRandomization::PermuteDigits),
        ("fastowen", DigitRandomization::Owen),
        ("owen", DigitRandomization::Owen),
    ] {
        let text = format!("Sampler \"halton\" \"string randomization\" \"{name}\"");
        assert_eq!(kind(&text), halton(r), "{name}");
    }
    assert_eq!(
        kind("Sampler \"stratified\""),
        SamplerKind::Stratified {
            x: 4,
            y: 4,
            jitter: true
        }
    );
    let e = err("Sampler \"halton\" \"string randomization\" \"shuffle\"\nWorldBegin\n");
    assert!(e.contains("t.pbrt:1:18") && e.contains("shuffle"), "{e}");
    // Sobol points are always scrambled: asking for none is a warning at the parameter.
    let s = parse("Sampler \"sobol\" \"string randomization\" \"none\"\nWorldBegin\n");
    assert_eq!(s.sampler.kind, SamplerKind::Sobol);
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert_eq!(s.warnings[0].loc.column, 17, "{:?}", s.warnings);
    assert!(
        parse("Sampler \"zsobol\"\nWorldBegin\n").warnings[0]
            .message
            .contains("Owen-scrambled Sobol")
    );
}

#[test]
fn realistic_camera_resolves_its_lens_file_from_the_scene_folder() {
    let lenses = radiant_testkit::shared_root().join("data");
    let s = parse_str(
        "Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.50mm.dat\" \"float focusdistance\" 2\nWorldBegin\n",
        "t.pbrt",
        &lenses,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    match s.camera.kind {
        CameraKind::Realistic {
            lens_file,
            aperture_diameter_mm,
            focus_distance,
        } => {
            assert_eq!(lens_file, lenses.join("lenses/dgauss.50mm.dat"));
            assert_eq!((aperture_diameter_mm, focus_distance), (1.0, 2.0));
        }
        k => panic!("{k:?}"),
    }
    let e = err("Camera \"realistic\"\n  \"string lensfile\" \"nope.dat\"\n");
    assert!(e.starts_with("t.pbrt:2:3: error: lens file"), "{e}");
}

#[test]
fn unused_and_unsupported_parameters_warn_with_their_location() {
    let s = parse(
        "Film \"rgb\" \"float exposuretime\" 5500 \"bool savefp16\" true\nWorldBegin\n\
         Shape \"sphere\" \"float radius\" 2\n      \"float radisu\" 3\n",
    );
    let msgs: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(msgs.len(), 3, "{msgs:#?}");
    assert!(msgs[1].starts_with("t.pbrt:1:12: warning: Film: parameter \"exposuretime\""));
    assert!(msgs[0].starts_with("t.pbrt:1:38: warning: Film: parameter \"savefp16\""));
    assert_eq!(
        msgs[2],
        "t.pbrt:4:7: warning: parameter \"float radisu\" is not used by Shape \"sphere\""
    );
}

#[test]
fn materials_map_to_radiant_materials() {
    let s = parse(
        "WorldBegin\n\
         Material \"diffuse\"\n\
         Material \"diffuse\" \"rgb reflectance\" [ 0.2 0.4 0.6 ]\n\
         Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n\
         Material \"dielectric\" \"float eta\" 1.33 \"float roughness\" 0.1\n\
         Material \"conductor\"\n\
         Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\"\n\
         Material \"conductor\" \"rgb reflectance\" [ 0.9 0.9 0.9 ]\n\
         Material \"hair\" \"rgb reflectance\" [ 1 0 0 ]\n\
         Texture \"checks\" \"spectrum\" \"checkerboard\"\n\
         Material \"diffuse\" \"texture reflectance\" \"checks\"\n\
         Material \"interface\"\n",
    );
    let named = |n: &str| metal_spectrum(n).unwrap();
    let expected = vec![
        MaterialDesc::Diffuse {
            reflectance: Rgb::splat(0.5),
        },
        MaterialDesc::Diffuse {
            reflectance: Rgb::new(0.2, 0.4, 0.6),
        },
        MaterialDesc::Dielectric { eta: 1.5168 },
        // remaproughness (default true): alpha = sqrt(roughness).
        MaterialDesc::RoughDielectric {
            eta: 1.33,
            alpha_u: 0.1f32.sqrt(),
            alpha_v: 0.1f32.sqrt(),
        },
        // pbrt-v4's default conductor is copper.
        MaterialDesc::Conductor(ConductorDesc::EtaK {
            eta: named("metal-Cu-eta"),
            k: named("metal-Cu-k"),
        }),
        MaterialDesc::Conductor(ConductorDesc::EtaK {
            eta: named("metal-Au-eta"),
            k: named("metal-Au-k"),
        }),
        MaterialDesc::Conductor(ConductorDesc::Reflectance(Rgb::splat(0.9))),
        MaterialDesc::Diffuse {
            reflectance: Rgb::splat(0.5),
        },
        MaterialDesc::Textured(TexturedMaterialDesc::Diffuse {
            reflectance: TexturedParam::Texture(0),
        }),
        MaterialDesc::Interface,
    ];
    assert_eq!(s.materials, expected);
    // One warning each: BK7 without dispersion, hair.
    let msgs: Vec<&str> = s.warnings.iter().map(|w| w.message.as_str()).collect();
    assert_eq!(msgs.len(), 2, "{msgs:#?}");
    assert!(msgs[1].contains("diffuse with reflectance 0.5"));
    assert!(err("WorldBegin\nMaterial \"plastic\"\n").contains("unknown material type"));
}

#[test]
fn microfacet_roughness_follows_pbrt_v4() {
    let s = parse(
        "WorldBegin\n\
         Material \"conductor\" \"float roughness\" 0.25 \"float vroughness\" 0.04\n\
         Material \"conductor\" \"rgb reflectance\" [ 0.5 0.5 0.5 ] \"float uroughness\" 0.3 \"float vroughness\" 0.3 \"bool remaproughness\" false\n\
         Material \"dielectric\" \"float roughness\" 0\n\
         Material \"dielectric\" \"float roughness\" 0.2 \"bool remaproughness\" false\n",
    );
    let cu = ConductorDesc::EtaK {
        eta: metal_spectrum("metal-Cu-eta").unwrap(),
        k: metal_spectrum("metal-Cu-k").unwrap(),
    };
    assert_eq!(
        s.materials,
        vec![
            MaterialDesc::RoughConductor {
                conductor: cu,
                alpha_u: 0.5,
                alpha_v: 0.2,
            },
            MaterialDesc::RoughConductor {
                conductor: ConductorDesc::Reflectance(Rgb::splat(0.5)),
                alpha_u: 0.3,
                alpha_v: 0.3,
            },
            MaterialDesc::Dielectric { eta: 1.5 },
            MaterialDesc::RoughDielectric {
                eta: 1.5,
                alpha_u: 0.2,
                alpha_v: 0.2,
            },
        ]
    );
    // Anisotropic roughness is oriented along ∂p/∂u, as in pbrt-v4: nothing to report.
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    assert!(err("WorldBegin\nMaterial \"conductor\" \"float roughness\" -0.1\n").contains(">= 0"));
}

#[test]
fn thin_dielectric_diffuse_transmission_and_mix_follow_pbrt_v4() {
    let s = parse(
        "WorldBegin\n\
         Material \"thindielectric\"\n\
         Material \"thindielectric\" \"float eta\" 1.33\n\
         Material \"diffusetransmission\"\n\
         MakeNamedMaterial \"dt\" \"string type\" \"diffusetransmission\" \"rgb reflectance\" [ 0.2 0.4 0.6 ] \"rgb transmittance\" [ 0.5 0.3 0.1 ] \"float scale\" 0.5\n\
         MakeNamedMaterial \"glass\" \"string type\" \"dielectric\"\n\
         MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [ \"dt\" \"glass\" ]\n\
         Material \"mix\" \"string materials\" [ \"m\" \"glass\" ] \"float amount\" 0.3\n",
    );
    assert_eq!(
        s.materials,
        vec![
            MaterialDesc::ThinDielectric { eta: 1.5 },
            MaterialDesc::ThinDielectric { eta: 1.33 },
            MaterialDesc::DiffuseTransmission {
                reflectance: Rgb::splat(0.25),
                transmittance: Rgb::splat(0.25),
            },
            MaterialDesc::DiffuseTransmission {
                reflectance: Rgb::new(0.1, 0.2, 0.3),
                transmittance: Rgb::new(0.25, 0.15, 0.05),
            },
            MaterialDesc::Dielectric { eta: 1.5 },
            MaterialDesc::Mix {
                materials: [3, 4],
                amount: TexturedParam::Constant(0.5),
            },
            MaterialDesc::Mix {
                materials: [5, 4],
                amount: TexturedParam::Constant(0.3),
            },
        ]
    );
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let e = err("WorldBegin\nMaterial \"mix\" \"string materials\" [ \"a\" \"b\" ]\n");
    assert!(e.contains("unknown named material \"a\""), "{e}");
    let e = err(
        "WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"diffuse\"\nMaterial \"mix\" \"string materials\" \"a\"\n",
    );
    assert!(e.contains("two names"), "{e}");
    assert!(err("WorldBegin\nMaterial \"mix\"\n").contains("string materials"));
}

#[test]
fn coated_materials_follow_pbrt_v4() {
    let s = parse(
        "WorldBegin\n\
         Material \"coateddiffuse\"\n\
         Material \"coateddiffuse\" \"rgb reflectance\" [ 0.2 0.3 0.4 ] \"float roughness\" 0.04\n\
           \"float thickness\" 0.2 \"float eta\" 1.33 \"rgb albedo\" [ 0.5 0.5 0.5 ] \"float g\" 0.3\n\
           \"integer maxdepth\" 20 \"integer nsamples\" 4\n\
         Material \"coatedconductor\" \"float interface.roughness\" 0.01 \"float interface.eta\" 1.4\n\
           \"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\"\n\
           \"float conductor.uroughness\" 0.3 \"float conductor.vroughness\" 0.3 \"bool remaproughness\" false\n\
         Material \"coatedconductor\" \"rgb reflectance\" [ 0.9 0.8 0.7 ]\n\
         Texture \"t\" \"float\" \"constant\" \"float value\" 0.3\n\
         Material \"coateddiffuse\" \"texture thickness\" \"t\"\n",
    );
    let pbrt_default = CoatDesc {
        eta: 1.5,
        alpha_u: 0.0,
        alpha_v: 0.0,
        thickness: 0.01,
        albedo: Rgb::BLACK,
        g: 0.0,
        max_depth: 10,
        samples: 1,
    };
    let expected = vec![
        MaterialDesc::CoatedDiffuse {
            reflectance: Rgb::splat(0.5),
            coat: pbrt_default,
        },
        MaterialDesc::CoatedDiffuse {
            reflectance: Rgb::new(0.2, 0.3, 0.4),
            coat: CoatDesc {
                eta: 1.33,
                alpha_u: 0.2,
                alpha_v: 0.2,
                thickness: 0.2,
                albedo: Rgb::splat(0.5),
                g: 0.3,
                max_depth: 20,
                samples: 4,
            },
        },
        MaterialDesc::CoatedConductor {
            conductor: ConductorDesc::EtaK {
                eta: metal_spectrum("metal-Au-eta").unwrap(),
                k: metal_spectrum("metal-Au-k").unwrap(),
            },
            alpha_u: 0.3,
            alpha_v: 0.3,
            coat: CoatDesc {
                eta: 1.4,
                alpha_u: 0.01,
                alpha_v: 0.01,
                ..pbrt_default
            },
        },
        MaterialDesc::CoatedConductor {
            conductor: ConductorDesc::Reflectance(Rgb::new(0.9, 0.8, 0.7)),
            alpha_u: 0.0,
            alpha_v: 0.0,
            coat: pbrt_default,
        },
        MaterialDesc::Textured(TexturedMaterialDesc::CoatedDiffuse {
            reflectance: TexturedParam::Constant(Rgb::splat(0.5)),
            coat: TexturedCoatDesc {
                eta: 1.5,
                roughness: RoughnessDesc {
                    u: TexturedParam::Constant(0.0),
                    v: TexturedParam::Constant(0.0),
                    remap: false,
                },
                thickness: TexturedParam::Texture(0),
                albedo: TexturedParam::Constant(Rgb::BLACK),
                g: TexturedParam::Constant(0.0),
                max_depth: 10,
                samples: 1,
            },
        }),
    ];
    assert_eq!(s.materials, expected);
    // A textured thickness is taken as it is; nothing is reported or left unused.
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    for bad in [
        "\"float thickness\" 0",
        "\"float g\" 1",
        "\"integer maxdepth\" 0",
        "\"integer nsamples\" -1",
    ] {
        let e = err(&format!("WorldBegin\nMaterial \"coateddiffuse\" {bad}\n"));
        assert!(e.contains("error"), "{bad}: {e}");
    }
}

#[test]
fn shapes_without_a_material_share_pbrts_default_diffuse() {
    let s = parse("WorldBegin\nShape \"sphere\"\nShape \"disk\" \"float innerradius\" 0.5\n");
    assert_eq!(
        s.materials,
        vec![MaterialDesc::Diffuse {
            reflectance: Rgb::splat(0.5)
        }]
    );
    assert_eq!(s.shapes[0].material, s.shapes[1].material);
    assert_eq!(
        s.shapes[1].geometry,
        Geometry::Disk {
            height: 0.0,
            radius: 1.0,
            inner_radius: 0.5,
            phi_max_deg: 360.0
        }
    );
}

#[test]
fn attribute_defaults_apply_to_later_shapes() {
    let s = parse(
        "WorldBegin\nAttributeBegin\n  Attribute \"shape\" \"float radius\" 3\n  Shape \"sphere\"\n\
           Shape \"sphere\" \"float radius\" 4\n  Shape \"disk\"\nAttributeEnd\nShape \"sphere\"\n",
    );
    let radius = |i: usize| match &s.shapes[i].geometry {
        Geometry::Sphere { radius, .. } | Geometry::Disk { radius, .. } => *radius,
        g => panic!("{g:?}"),
    };
    assert_eq!(
        [radius(0), radius(1), radius(2), radius(3)],
        [3.0, 4.0, 3.0, 1.0]
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn attribute_parameters_nobody_reads_are_reported_once() {
    let s = parse(
        "WorldBegin\nAttribute \"shape\" \"float bogus1\" [ 1 ]\nAttribute \"light\" \"float bogus2\" 1\n\
         Attribute \"material\" \"float bogus3\" 1\nAttribute \"shape\" \"float radius\" 2\n\
         Attribute \"texture\" \"float uscale\" 4 \"float bogus4\" 1\n\
         Texture \"c\" \"float\" \"checkerboard\"\nLightSource \"point\"\nShape \"sphere\"\nShape \"sphere\"\n",
    );
    let msgs: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        msgs,
        [
            "t.pbrt:2:19: warning: parameter \"float bogus1\" of Attribute \"shape\" is not used by any later shape",
            "t.pbrt:3:19: warning: parameter \"float bogus2\" of Attribute \"light\" is not used by any later light",
            "t.pbrt:4:22: warning: parameter \"float bogus3\" of Attribute \"material\" is not used by any later material",
            "t.pbrt:6:38: warning: parameter \"float bogus4\" of Attribute \"texture\" is not used by any later texture",
        ]
    );
    let radius = |i: usize| match &s.shapes[i].geometry {
        Geometry::Sphere { radius, .. } => *radius,
        g => panic!("{g:?}"),
    };
    assert_eq!([radius(0), radius(1)], [2.0, 2.0]);
}

#[test]
fn attribute_medium_is_ignored_with_a_warning_and_unknown_targets_refused() {
    let s = parse("WorldBegin\nAttribute \"medium\" \"float g\" 0.5\n");
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(s.warnings[0].message.contains("media are not supported"));
    let e = err("WorldBegin\nAttribute \"camera\" \"float fov\" 30\n");
    assert!(
        e.starts_with("t.pbrt:2:11: error: Attribute: unknown target \"camera\""),
        "{e}"
    );
}

#[test]
fn accelerators_are_accepted_with_a_warning_and_unknown_ones_refused() {
    let s = parse(
        "Accelerator \"bvh\"\nAccelerator \"kdtree\" \"integer maxprims\" 4\n\
         Accelerator \"bvh\" \"float bogus0\" [ 1 ]\n",
    );
    let msgs: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        msgs,
        [
            "t.pbrt:2:1: warning: Accelerator \"kdtree\": radiant always builds its own BVH; its parameter \"integer maxprims\" is ignored",
            "t.pbrt:3:1: warning: Accelerator \"bvh\": radiant always builds its own BVH; its parameter \"float bogus0\" is ignored",
        ]
    );
    let e = err("Accelerator \"octree\" \"float bogus0\" [ 1 ]\n");
    assert!(
        e.starts_with("t.pbrt:1:1: error: unknown accelerator \"octree\""),
        "{e}"
    );
}

#[test]
fn point_and_spot_lights_follow_the_ctm_and_their_power() {
    let s = parse(
        "WorldBegin\nTranslate 0 10 0\n\
         LightSource \"point\" \"rgb I\" [ 1 2 3 ] \"float scale\" 2 \"point3 from\" [ 1 0 0 ]\n\
         LightSource \"point\" \"float power\" 100\n\
         LightSource \"spot\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 -1 0 ] \"float coneangle\" 40\n\
           \"float conedeltaangle\" 10 \"float power\" 50 \"blackbody I\" 3000\n",
    );
    let LightDesc::Point {
        position,
        intensity,
        ..
    } = s.lights[0]
    else {
        panic!()
    };
    assert_eq!(position, Vec3::new(1.0, 10.0, 0.0));
    assert_eq!(intensity, Rgb::new(2.0, 4.0, 6.0));
    // Φ = 4π Y(I) for an isotropic point light.
    let LightDesc::Point { intensity, .. } = s.lights[1] else {
        panic!()
    };
    assert!(close(4.0 * PI * intensity.luminance(), 100.0));
    let LightDesc::Spot {
        position,
        direction,
        intensity,
        cos_falloff_start,
        cos_total_width,
        ..
    } = s.lights[2]
    else {
        panic!()
    };
    assert_eq!(
        (position, direction),
        (Vec3::new(0.0, 10.0, 0.0), Vec3::NEG_Y)
    );
    assert!(
        close(cos_total_width, 40f32.to_radians().cos())
            && close(cos_falloff_start, 30f32.to_radians().cos())
    );
    // Φ = 2π I [(1 - cos 30°) + (cos 30° - cos 40°) / 2], and the colour is the
    // blackbody's.
    let solid_angle =
        2.0 * PI * ((1.0 - cos_falloff_start) + 0.5 * (cos_falloff_start - cos_total_width));
    assert!(close(solid_angle * intensity.luminance(), 50.0));
    let bb = blackbody_rgb(3000.0).unwrap();
    assert!(close(intensity.r / intensity.g, bb.r / bb.g));
}

#[test]
fn distant_and_infinite_lights() {
    let s = parse(
        "WorldBegin\nRotate 90 0 0 1\n\
         LightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 1 0 0 ] \"rgb L\" [ 2 2 2 ]\n\
         LightSource \"infinite\" \"rgb L\" [ 0.5 0.5 0.5 ] \"float scale\" 3\n\
         LightSource \"infinite\" \"float illuminance\" 10\n",
    );
    let LightDesc::Distant {
        direction,
        radiance,
        ..
    } = s.lights[0]
    else {
        panic!()
    };
    assert!((direction - Vec3::Y).length() < 1e-6);
    assert_eq!(radiance, Rgb::splat(2.0));
    let LightDesc::Infinite { radiance, .. } = s.lights[1] else {
        panic!()
    };
    assert_eq!(radiance, Rgb::splat(1.5));
    // E = π L on an upward-facing surface.
    let LightDesc::Infinite { radiance, .. } = s.lights[2] else {
        panic!()
    };
    assert!(close(PI * radiance.luminance(), 10.0));
}

#[test]
fn area_lights_scale_and_power() {
    let s = parse(
        "WorldBegin\nAttributeBegin\n  AreaLightSource \"diffuse\" \"rgb L\" [ 1 2 3 ] \"float scale\" 2 \"bool twosided\" true\n\
           Shape \"sphere\"\nAttributeEnd\n\
         AttributeBegin\n  Scale 2 2 2\n  AreaLightSource \"diffuse\" \"blackbody L\" 6500 \"float power\" 10\n\
           Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0 ]\nAttributeEnd\nShape \"disk\"\n",
    );
    let al = s.shapes[0].area_light.as_ref().unwrap();
    assert_eq!((al.l, al.two_sided), (Rgb::new(2.0, 4.0, 6.0), true));
    // The patch is 2 × 2 after the scale: Φ = π A Y(L) = 10 for one side.
    let al = s.shapes[1].area_light.as_ref().unwrap();
    assert!(close(PI * 4.0 * al.l.luminance(), 10.0), "{:?}", al.l);
    assert!(
        s.shapes[2].area_light.is_none(),
        "AttributeEnd ends the area light"
    );
}

#[test]
fn unsupported_things_warn_once_each_and_parse_on() {
    let s = parse(
        "Sampler \"pmj02bn\"\nPixelFilter \"lanczos\" \"float tau\" 3\nFilm \"spectral\"\nAccelerator \"bvh\"\n\
         Option \"bool disablepixeljitter\" true\nWorldBegin\nTexture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" 4\n\
         MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"fog\" \"\"\n\
         Shape \"curve\" \"point3 P\" [ 0 0 0 1 1 1 2 2 2 3 3 3 ]\nLightSource \"goniometric\"\n\
         Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer faceIndices\" [ 0 ]\n",
    );
    let lines: Vec<u32> = s.warnings.iter().map(|w| w.loc.line).collect();
    assert_eq!(
        lines,
        vec![1, 2, 3, 5, 8, 9, 10, 11, 12],
        "{:#?}",
        s.warnings
    );
    assert_eq!(s.shapes.len(), 1);
    // A goniometric light without an image is isotropic (with the warning of line 11).
    assert!(matches!(
        s.lights[..],
        [LightDesc::Goniometric { image: None, .. }]
    ));
}

#[test]
fn bad_values_are_errors_at_their_location() {
    for (text, at) in [
        (
            "WorldBegin\nShape \"sphere\" \"float radius\" \"big\"\n",
            "t.pbrt:2:16:",
        ),
        (
            "WorldBegin\nShape \"sphere\" \"float radius\" [ 1 \"x\" ]\n",
            "t.pbrt:2:35:",
        ),
        (
            "WorldBegin\nShape \"sphere\" \"floot radius\" 1\n",
            "t.pbrt:2:16:",
        ),
        (
            "WorldBegin\nShape \"sphere\" \"float radius\" 1 \"float radius\" 2\n",
            "t.pbrt:2:33:",
        ),
        // A singular Scale is accepted with a warning (pbrt-v4); the camera refuses it.
        ("Scale 1 0 1\nCamera \"perspective\"\n", "t.pbrt:2:1:"),
        ("LookAt 0 0 0  0 0 0  0 1 0\n", "t.pbrt:1:1:"),
        ("Translate 1 2\nWorldBegin\n", "t.pbrt:2:1:"),
        (
            "WorldBegin\nShape \"bilinearmesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ]\n",
            "t.pbrt:2:1:",
        ),
        ("WorldBegin\nWorldBegin\n", "t.pbrt:2:1:"),
        (
            "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"point2 uv\" [ 0 0 ]\n",
            "t.pbrt:2:55:",
        ),
        ("\"float x\" 1\n", "t.pbrt:1:1:"),
    ] {
        let e = err(text);
        assert!(e.starts_with(at), "{text:?}: expected {at}, got {e}");
    }
}

/// Values outside what the quantity can be: an error at the parameter, naming the value.
#[test]
fn out_of_range_light_camera_and_film_values_are_errors_at_the_parameter() {
    let spot = |params: &str| {
        format!("WorldBegin\nLightSource \"spot\" \"point3 from\" [ 0 0 -1 ]\n  {params}\n")
    };
    for (text, at, words) in [
        (
            spot("\"float coneangle\" 0 \"float conedeltaangle\" 0"),
            "t.pbrt:3:3:",
            "\"coneangle\" must lie in (0, 180]",
        ),
        (spot("\"float coneangle\" -20"), "t.pbrt:3:3:", "got -20"),
        (spot("\"float coneangle\" 500"), "t.pbrt:3:3:", "got 500"),
        (
            spot("\"float coneangle\" 20 \"float conedeltaangle\" -5"),
            "t.pbrt:3:24:",
            "\"conedeltaangle\" must lie in [0, coneangle = 20]",
        ),
        (
            spot("\"float coneangle\" 20 \"float conedeltaangle\" 30"),
            "t.pbrt:3:24:",
            "got 30",
        ),
        (
            "WorldBegin\nLightSource \"point\" \"float scale\" -1\n".to_string(),
            "t.pbrt:2:21:",
            "\"scale\" must not be negative",
        ),
        (
            "WorldBegin\nAreaLightSource \"diffuse\" \"rgb scale\" [ 1 -1 1 ]\n".to_string(),
            "t.pbrt:2:27:",
            "\"scale\" must not be negative",
        ),
        (
            "Film \"rgb\" \"float iso\" -100\n".to_string(),
            "t.pbrt:1:12:",
            "\"iso\" must be positive, got -100",
        ),
        (
            "Film \"rgb\" \"float diagonal\" 0\n".to_string(),
            "t.pbrt:1:12:",
            "\"diagonal\" must be positive",
        ),
        (
            "Camera \"perspective\" \"float lensradius\" -0.1\n".to_string(),
            "t.pbrt:1:22:",
            "\"lensradius\" must not be negative, got -0.1",
        ),
        (
            "Camera \"orthographic\" \"float lensradius\" 0.1 \"float focaldistance\" 0\n"
                .to_string(),
            "t.pbrt:1:46:",
            "\"focaldistance\" must be positive, got 0",
        ),
    ] {
        let e = err(&text);
        assert!(
            e.starts_with(at) && e.contains(words),
            "{text:?}: expected {at} … {words}, got {e}"
        );
    }
}

/// pbrt-v4's Mitchell and sinc filters, with their default radii and parameters.
#[test]
fn mitchell_and_sinc_filters_follow_pbrt_v4() {
    let s = parse("PixelFilter \"mitchell\"\n");
    assert_eq!(
        s.filter.kind,
        FilterKind::Mitchell {
            b: 1.0 / 3.0,
            c: 1.0 / 3.0
        }
    );
    assert_eq!(s.filter.radius, glam::Vec2::splat(2.0));
    let s = parse("PixelFilter \"mitchell\" \"float B\" 0 \"float C\" 0.5 \"float xradius\" 1.5\n");
    assert_eq!(s.filter.kind, FilterKind::Mitchell { b: 0.0, c: 0.5 });
    assert_eq!(s.filter.radius, glam::Vec2::new(1.5, 2.0));
    let s = parse("PixelFilter \"sinc\"\n");
    assert_eq!(s.filter.kind, FilterKind::LanczosSinc { tau: 3.0 });
    assert_eq!(s.filter.radius, glam::Vec2::splat(4.0));
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let e = err("PixelFilter \"sinc\" \"float tau\" 0\n");
    assert!(
        e.starts_with("t.pbrt:1:20:") && e.contains("\"tau\" must be positive"),
        "{e}"
    );
}

/// The exposure time is the shutter interval (pbrt-v4's imaging ratio); a shutter that
/// never opens is an error at the camera, as in pbrt-v4.
#[test]
fn the_camera_shutter_sets_the_exposure_time() {
    assert_eq!(parse("Camera \"perspective\"\n").camera.exposure_time, 1.0);
    let s = parse("Camera \"perspective\" \"float shutteropen\" 0.5 \"float shutterclose\" 0.75\n");
    assert_eq!(s.camera.exposure_time, 0.25);
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let e = err("Camera \"orthographic\" \"float shutteropen\" 1 \"float shutterclose\" 1\n");
    assert!(
        e.starts_with("t.pbrt:1:1:") && e.contains("the shutter never opens"),
        "{e}"
    );
}

/// pbrt-v4 ignores a `power` or `illuminance` that is not positive; radiant does too,
/// and says so where the value is written.
#[test]
fn a_power_that_is_not_positive_is_ignored_with_a_warning() {
    let s = parse(
        "WorldBegin\nLightSource \"point\" \"rgb I\" [ 1 2 3 ]\n  \"float power\" -5\n\
         LightSource \"distant\" \"float illuminance\" 0\n\
         AreaLightSource \"diffuse\" \"float power\" -1\n\
         LightSource \"spot\" \"float coneangle\" 3\n",
    );
    let at: Vec<(u32, u32)> = s
        .warnings
        .iter()
        .map(|w| (w.loc.line, w.loc.column))
        .collect();
    assert_eq!(at, vec![(3, 3), (4, 23), (5, 27)], "{:#?}", s.warnings);
    assert!(
        s.warnings
            .iter()
            .all(|w| w.message.contains("is not positive; ignored"))
    );
    let LightDesc::Point { intensity, .. } = s.lights[0] else {
        panic!()
    };
    assert_eq!(intensity, Rgb::new(1.0, 2.0, 3.0));
    // A cone narrower than the default falloff of 5 degrees falls off over its width.
    let LightDesc::Spot {
        cos_falloff_start,
        cos_total_width,
        ..
    } = s.lights[2]
    else {
        panic!()
    };
    assert_eq!(cos_falloff_start, 1.0);
    assert_eq!(cos_total_width, 3f32.to_radians().cos());
}

#[test]
fn value_errors_name_what_was_written() {
    for (text, want) in [
        (
            "WorldBegin\nShape \"sphere\" \"float radius\" 1 \"float phimax\" [ -10 ]\n",
            "t.pbrt:2:33: error: \"phimax\" must lie in (0, 360] degrees, got -10",
        ),
        (
            "WorldBegin\nShape \"disk\" \"float phimax\" 0\n",
            "t.pbrt:2:14: error: \"phimax\" must lie in (0, 360] degrees, got 0",
        ),
        (
            "Film \"rgb\" \"integer xresolution\" [ 1e1 ]\n",
            "t.pbrt:1:36: error: parameter \"integer xresolution\": an integer must be written without a fraction or exponent",
        ),
        (
            "Film \"rgb\" \"integer xresolution\" 3000000000\n",
            "t.pbrt:1:34: error: parameter \"integer xresolution\": 3000000000 does not fit a 32-bit integer",
        ),
        (
            "Camera \"realistic\" \"string lensfile\" \".\"\n",
            "t.pbrt:1:20: error: lens file './.' is a directory, not a file",
        ),
        (
            "WorldBegin\nTexture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \".\"\n",
            "t.pbrt:2:35: error: image './.' is a directory, not a file",
        ),
    ] {
        assert_eq!(err(text), want, "{text:?}");
    }
    let s = parse("WorldBegin\nShape \"sphere\" \"float phimax\" 720\n");
    assert!(matches!(
        s.shapes[0].geometry,
        Geometry::Sphere {
            phi_max_deg: 360.0,
            ..
        }
    ));
}

#[test]
fn infinite_light_with_an_image() {
    let dir = std::env::temp_dir().join(format!("radiant-envparse-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // 4 x 4 pixels: each pixel's value is its index + 1 (row-major from the top).
    let mut bytes = b"PF\n4 4\n-1.0\n".to_vec();
    // PFM stores the bottom row first.
    for y in (0..4).rev() {
        for x in 0..4 {
            let v = (y * 4 + x + 1) as f32;
            for c in [v, 2.0 * v, 0.5 * v] {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join("sky.pfm"), bytes).unwrap();
    let s = parse_str(
        "WorldBegin\nAttributeBegin\nRotate -90 1 0 0\n\
         LightSource \"infinite\" \"string filename\" \"sky.pfm\" \"float scale\" 3 \"point3 portal\" [0 0 0 1 0 0 1 1 0 0 1 0]\nAttributeEnd\n\
         LightSource \"infinite\" \"string filename\" \"sky.pfm\" \"float illuminance\" 7\n",
        "t.pbrt",
        &dir,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let LightDesc::Infinite {
        radiance,
        image: Some(image),
        ..
    } = &s.lights[0]
    else {
        panic!("{:?}", s.lights[0])
    };
    assert_eq!(*radiance, Rgb::splat(3.0));
    assert_eq!(image.path, dir.join("sky.pfm"));
    assert_eq!(image.illuminance, None);
    assert_eq!((image.at.line, image.at.column), (4, 24));
    // The CTM orients the image: the light's +z is world +y.
    assert!((image.render_from_light.vector(Vec3::Z) - Vec3::Y).length() < 1e-6);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.message.contains("\"portal\" ignored")),
        "{:?}",
        s.warnings
    );
    // illuminance is kept for the world build, which reads the image.
    let LightDesc::Infinite {
        image: Some(image), ..
    } = &s.lights[1]
    else {
        panic!()
    };
    assert_eq!(image.illuminance, Some(7.0));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn film_sensor_white_balance_and_max_component_value() {
    let d = parse("Film \"rgb\"\nWorldBegin\n");
    assert_eq!(d.film.max_component_value, f32::INFINITY);
    assert_eq!(d.film.white_balance, None);

    let d = parse(
        "Film \"rgb\" \"float maxcomponentvalue\" 10 \"string sensor\" \"cie1931\" \"float whitebalance\" 5000\nWorldBegin\n",
    );
    assert_eq!(d.film.max_component_value, 10.0);
    assert_eq!(d.film.white_balance, Some(5000.0));
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);

    // A camera sensor: read through the CIE observer, with a warning, and white-balanced
    // to 6500 K as pbrt-v4 does for camera sensors.
    let d = parse("Film \"rgb\" \"string sensor\" \"canon_eos_100d\"\nWorldBegin\n");
    assert_eq!(d.film.white_balance, Some(6500.0));
    assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
    assert!(d.warnings[0].message.contains("CIE 1931"));
    let d = parse("Film \"rgb\" \"string sensor\" \"my_camera\"\nWorldBegin\n");
    assert!(
        d.warnings[0]
            .message
            .contains("unknown sensor \"my_camera\"")
    );

    assert!(
        err("Film \"rgb\" \"float maxcomponentvalue\" 0\nWorldBegin\n")
            .contains("maxcomponentvalue")
    );
    assert!(err("Film \"rgb\" \"float whitebalance\" -1\nWorldBegin\n").contains("whitebalance"));
}
