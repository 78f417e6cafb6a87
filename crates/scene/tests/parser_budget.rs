//! The memory budget as the scene reader applies it (its own process: the budget is
//! process-wide).

use std::path::Path;

use radiant_scene::{budget, parse_str};

#[test]
fn loop_subdivision_over_the_memory_limit_is_refused_before_it_is_made() {
    budget::set_limit(1 << 30);
    let scene = |levels: u32| {
        format!(
            "WorldBegin\nShape \"loopsubdiv\" \"integer levels\" [ {levels} ]\n  \"point3 P\" [ -1 -1 0 1 -1 0 1 1 0 ] \"integer indices\" [ 0 1 2 ]\n"
        )
    };
    // 4^13 = 67M triangles: more than 1 GB to make, refused at once.
    let e = parse_str(&scene(13), "t.pbrt", Path::new("."))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("t.pbrt:2:20: error: \"levels\" 13 would make 67108864 triangles")
            && e.contains("the memory limit is 1.1 GB"),
        "{e}"
    );
    assert!(parse_str(&scene(3), "t.pbrt", Path::new(".")).is_ok());
    budget::set_limit(0);
}
