//! Helpers shared by the integration tests.
#![allow(dead_code)]

use radiant::Session;
use radiant::image::Image;
use radiant::render::{Overrides, Progress};
use radiant::scene::SceneDesc;

pub use radiant_testkit::shared;

/// Renders a scene with the given overrides on all cores.
pub fn render(desc: &SceneDesc, overrides: &Overrides) -> Image {
    let session = Session::new(desc, overrides).expect("scene builds");
    session.render(&Progress::default()).film.image()
}

/// Reads `key value` lines of a reference's `.noise.txt`.
pub fn noise_figure(rel: &str, key: &str) -> f64 {
    let text = std::fs::read_to_string(shared(rel)).expect("noise file");
    text.lines()
        .find_map(|l| {
            let mut it = l.split_whitespace();
            (it.next() == Some(key)).then(|| it.next().and_then(|v| v.parse().ok()))?
        })
        .unwrap_or_else(|| panic!("{key} not in {rel}"))
}

/// Chooses the integrator an `Integrator` directive names, as a scene would.
pub fn choose(
    desc: &radiant::scene::IntegratorDesc,
) -> Result<
    (
        Box<dyn radiant::render::Integrator>,
        Vec<radiant::scene::Warning>,
    ),
    radiant::scene::SceneError,
> {
    radiant::integrator_from_desc(&radiant::scene::builtin::cornell_box(), desc)
}

/// The integrator as its concrete type; panics when it is another.
pub fn concrete<T: radiant::render::Integrator>(i: &dyn radiant::render::Integrator) -> &T {
    let any: &dyn std::any::Any = i;
    any.downcast_ref::<T>()
        .unwrap_or_else(|| panic!("{} is not the integrator expected", i.name()))
}
