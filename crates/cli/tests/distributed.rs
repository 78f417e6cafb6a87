//! Distributed renders through the command line: units chosen by every spelling of
//! the flags, partial files, `radiant merge`, and a radiosity solution solved once and
//! displayed in parts — merged images bit for bit the one-machine render's.

use std::path::Path;

use radiant::image::read_image;

mod common;
use common::*;

fn ok(dir: &Path, args: &[&str]) {
    let out = radiant_in(dir, args);
    assert!(
        out.status.success(),
        "radiant {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn failure(dir: &Path, args: &[&str]) -> String {
    let out = radiant_in(dir, args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(
        out.status.code(),
        Some(1),
        "radiant {}: {stderr}",
        args.join(" ")
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

fn bits(path: &Path) -> Vec<u32> {
    read_image(path)
        .unwrap()
        .pixels
        .iter()
        .flat_map(|p| [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()])
        .collect()
}

#[test]
fn flag_spellings_make_the_same_units_and_merge_exactly() {
    let d = temp_dir("flags");
    let common = [
        "cornell-box",
        "--resolution",
        "20x10",
        "--spp",
        "130",
        "--quiet",
    ];
    let run = |extra: &[&str]| ok(&d, &[&["render"][..], &common, extra].concat());
    run(&["-o", "full.exr"]);
    // Left half by pixel bounds (pbrt-v4's spelling), right half by crop window, the
    // right half's samples in two ranges.
    run(&[
        "--pixelbounds",
        "0",
        "10",
        "0",
        "10",
        "--partial",
        "a.rpart",
        "-o",
        "a.exr",
    ]);
    run(&[
        "--cropwindow",
        "0.5",
        "1",
        "0",
        "1",
        "--sample-range",
        "0..64",
        "--partial",
        "b.rpart",
    ]);
    run(&[
        "--pixel-bounds",
        "10,20,0,10",
        "--sample-range",
        "64..130",
        "--partial",
        "c.rpart",
    ]);
    assert!(
        !d.join("cornell-box.exr").exists(),
        "a partial-only unit wrote an image"
    );
    // A crop render writes the crop's image.
    let crop = read_image(d.join("a.exr")).unwrap();
    assert_eq!((crop.width, crop.height), (10, 10));
    ok(
        &d,
        &["merge", "a.rpart", "b.rpart", "c.rpart", "-o", "merged.exr"],
    );
    assert_eq!(bits(&d.join("merged.exr")), bits(&d.join("full.exr")));

    // Refusals: a gap, an overlap, another scene, a range off the blocks.
    let e = failure(&d, &["merge", "a.rpart", "b.rpart", "-o", "x.exr"]);
    assert!(e.contains("gap"), "{e}");
    let e = failure(
        &d,
        &[
            "merge", "a.rpart", "b.rpart", "c.rpart", "c.rpart", "-o", "x.exr",
        ],
    );
    assert!(e.contains("duplicate"), "{e}");
    ok(
        &d,
        &[
            "render",
            "cornell-box",
            "--resolution",
            "20x10",
            "--spp",
            "130",
            "--seed",
            "3",
            "--quiet",
            "--pixel-bounds",
            "10,20,0,10",
            "--partial",
            "d.rpart",
        ],
    );
    let e = failure(&d, &["merge", "a.rpart", "d.rpart", "-o", "x.exr"]);
    assert!(e.contains("seed"), "{e}");
    let e = failure(
        &d,
        &[
            &["render"][..],
            &common,
            &["--sample-range", "0..100", "--partial", "e.rpart"],
        ]
        .concat(),
    );
    assert!(e.contains("multiples of 64"), "{e}");
    let e = failure(
        &d,
        &[
            &["render"][..],
            &common,
            &[
                "--integrator",
                "sppm",
                "--part",
                "0/2",
                "--part-by",
                "samples",
                "--partial",
                "e.rpart",
            ],
        ]
        .concat(),
    );
    assert!(e.contains("sppm"), "{e}");
}

#[test]
fn a_saved_radiosity_solution_displays_in_parts_exactly() {
    let d = temp_dir("radiosity");
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let text = std::fs::read_to_string(scenes.join("cornell-box.pbrt")).unwrap();
    let text = text.replace(
        "Integrator \"path\" \"integer maxdepth\" [ 100 ]",
        "Integrator \"radiosity\" \"float maxpatcharea\" [ 5000 ] \"string solver\" \"jacobi\" \"integer finalgather\" [ 2 ]",
    );
    assert!(
        text.contains("\"radiosity\""),
        "the scene's Integrator line moved"
    );
    let scene = d.join("cornell-box.pbrt");
    std::fs::write(&scene, &text).unwrap();
    let scene = scene.to_str().unwrap();
    let view = ["--resolution", "16x16", "--spp", "2", "--quiet"];
    ok(
        &d,
        &[&["render", scene, "-o", "full.exr"][..], &view].concat(),
    );
    ok(
        &d,
        &["radiosity", scene, "--save-solution", "sol.bin", "--quiet"],
    );
    let mut parts = Vec::new();
    for k in 0..3 {
        let part = format!("{k}/3");
        let file = format!("p{k}.rpart");
        ok(
            &d,
            &[
                &[
                    "render",
                    scene,
                    "--integrator",
                    "radiosity",
                    "--solution",
                    "sol.bin",
                    "--part",
                    &part,
                    "--partial",
                    &file,
                ][..],
                &view,
            ]
            .concat(),
        );
        parts.push(file);
    }
    let mut merge = vec!["merge", "-o", "merged.exr"];
    merge.extend(parts.iter().map(String::as_str));
    ok(&d, &merge);
    assert_eq!(bits(&d.join("merged.exr")), bits(&d.join("full.exr")));
    // The solution belongs to its mesh: a finer one refuses it.
    let finer = text.replace("[ 5000 ]", "[ 2000 ]");
    std::fs::write(d.join("finer.pbrt"), finer).unwrap();
    let e = failure(
        &d,
        &[
            &[
                "render",
                "finer.pbrt",
                "--solution",
                "sol.bin",
                "-o",
                "x.exr",
            ][..],
            &view,
        ]
        .concat(),
    );
    assert!(e.contains("another mesh"), "{e}");
}
