//! Random damage to valid scenes never panics the parser: it returns a scene or an
//! error with a location.

use std::path::PathBuf;

use proptest::prelude::*;
use radiant_scene::parse_str;

fn scenes_dir() -> PathBuf {
    radiant_testkit::repo_path("scenes")
}

fn seed_scenes() -> Vec<Vec<u8>> {
    let bitterli =
        radiant_testkit::shared_root().join("data/scenes/bitterli/cornell-box/scene-v4.pbrt");
    let mut out: Vec<Vec<u8>> = ["cornell-box.pbrt", "cornell-caustics.pbrt", "furnace.pbrt"]
        .iter()
        .map(|f| std::fs::read(scenes_dir().join(f)).unwrap())
        .collect();
    out.push(std::fs::read(bitterli).unwrap());
    // A scene that reaches the less common directives.
    out.push(
        b"Scale -1 1 1 LookAt 0 0 0 0 0 1 0 1 0 Camera \"orthographic\" \"float screenwindow\" [ -1 1 -2 2 ]\n\
          Sampler \"stratified\" PixelFilter \"gaussian\" Film \"rgb\" ActiveTransform EndTime\n\
          WorldBegin Attribute \"shape\" \"float radius\" 2 ObjectBegin \"o\" Shape \"sphere\" ObjectEnd\n\
          ObjectInstance \"o\" CoordinateSystem \"c\" CoordSysTransform \"camera\"\n\
          LightSource \"spot\" \"blackbody I\" 3000 \"float power\" 5 LightSource \"distant\"\n\
          AreaLightSource \"diffuse\" \"spectrum L\" [ 400 1 700 2 ] \"float power\" 3\n\
          Shape \"disk\" Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 1 1 0 ]\n\
          Material \"conductor\" \"spectrum eta\" \"metal-Ag-eta\" Texture \"t\" \"float\" \"scale\"\n\
          MakeNamedMaterial \"m\" \"string type\" \"dielectric\" \"spectrum eta\" \"glass-F11\"\n\
          NamedMaterial \"m\" ActiveTransform All TransformBegin Rotate 30 1 1 0 TransformEnd\n\
          Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"normal N\" [ 0 0 1 0 0 1 0 0 1 ]\n"
            .to_vec(),
    );
    out
}

#[derive(Clone, Debug)]
enum Edit {
    /// Overwrite the byte at (position mod length).
    Set(usize, u8),
    /// Delete a run of bytes.
    Delete(usize, usize),
    /// Insert a piece of pbrt syntax.
    Insert(usize, usize),
}

const PIECES: [&str; 16] = [
    "\"",
    "[",
    "]",
    "#",
    "\n",
    "-",
    "1e40",
    "nan",
    "AttributeEnd",
    "AttributeBegin",
    "WorldBegin",
    "\"float radius\"",
    "\"integer indices\" [ 7 ]",
    "Include \"cornell-box.pbrt\"",
    "ObjectEnd",
    "\\",
];

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Edit::Set(p, b)),
        (any::<usize>(), 1usize..40).prop_map(|(p, n)| Edit::Delete(p, n)),
        (any::<usize>(), 0..PIECES.len()).prop_map(|(p, k)| Edit::Insert(p, k)),
    ]
}

fn apply(mut text: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        let len = text.len().max(1);
        match *e {
            Edit::Set(p, b) => {
                if !text.is_empty() {
                    text[p % len] = b;
                }
            }
            Edit::Delete(p, n) => {
                let start = (p % len).min(text.len());
                let end = (start + n).min(text.len());
                text.drain(start..end);
            }
            Edit::Insert(p, k) => {
                let at = (p % len).min(text.len());
                let piece = format!(" {} ", PIECES[k]);
                text.splice(at..at, piece.bytes());
            }
        }
    }
    text
}

#[test]
fn the_undamaged_seeds_parse() {
    for (i, text) in seed_scenes().into_iter().enumerate() {
        let text = String::from_utf8(text).unwrap();
        if let Err(e) = parse_str(&text, "seed.pbrt", &scenes_dir()) {
            panic!("seed {i}: {e}");
        }
    }
}

proptest! {
    // 2000 damaged scenes at ~50 µs each: about 0.1 s.
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn damaged_scenes_never_panic(seed in 0usize..5, edits in prop::collection::vec(edit(), 1..8)) {
        let text = apply(seed_scenes()[seed].clone(), &edits);
        let text = String::from_utf8_lossy(&text);
        if let Err(e) = parse_str(&text, "fuzz.pbrt", &scenes_dir()) {
            let message = e.to_string();
            // Every error names a location in some file.
            prop_assert!(message.contains(".pbrt:") || message.contains(".ply") || message.contains(".dat"), "{}", message);
        }
    }
}
