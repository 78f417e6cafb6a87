//! Resuming through the session: a film whose rows stopped at different sample counts
//! (as a render cancelled in the middle of a pass leaves it) and SPPM statistics after
//! some iterations continue to the image of the uninterrupted render, bit for bit, and
//! survive the checkpoint file unchanged.

use std::ops::ControlFlow;

use radiant::Session;
use radiant::checkpoint::{self, State};
use radiant::render::integrator::IntegratorState;
use radiant::render::{Overrides, Progress, RenderOutput};
use radiant::scene::SceneDesc;
use radiant::scene::builtin::{cornell_box, cornell_caustics};

fn session(desc: &SceneDesc, spp: u32, integrator: &str) -> Session {
    Session::new(
        desc,
        &Overrides {
            spp: Some(spp),
            resolution: Some((12, 10)),
            integrator: Some(integrator.into()),
            ..Default::default()
        },
    )
    .expect("scene builds")
}

/// Renders on `threads` threads from `resume`, asking for the final state.
fn render(session: &Session, threads: usize, resume: Option<IntegratorState>) -> RenderOutput {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let progress = Progress::default();
    let mut hook = |_: u32, _: &dyn Fn() -> IntegratorState| ControlFlow::Continue(());
    pool.install(|| {
        session
            .render_resumable(&progress, &mut |_, _| {}, resume, Some(&mut hook))
            .unwrap()
    })
}

fn bits(out: &RenderOutput) -> Vec<u32> {
    out.film
        .image()
        .pixels
        .iter()
        .flat_map(|p| [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()])
        .collect()
}

/// Through the file format and back.
fn saved(session: &Session, desc: &SceneDesc, state: IntegratorState) -> IntegratorState {
    let bytes = checkpoint::encode(&session.run_key(desc), &State::Render(state));
    match checkpoint::decode(&bytes).unwrap().state {
        State::Render(s) => s,
        State::Radiosity(_) => panic!("not a render state"),
    }
}

#[test]
fn a_film_cut_off_mid_pass_resumes_to_the_uninterrupted_image() {
    let desc = cornell_box();
    let straight = render(&session(&desc, 12, "path"), 1, None);
    let (Some(IntegratorState::Film(at3)), Some(IntegratorState::Film(at5))) = (
        render(&session(&desc, 3, "path"), 1, None).state,
        render(&session(&desc, 5, "path"), 2, None).state,
    ) else {
        panic!("no film state");
    };
    // Rows above the middle with 5 samples, the rest with 3.
    let mut mixed = at3.clone();
    let half = mixed.width * mixed.height / 2;
    mixed.pixels[..half].copy_from_slice(&at5.pixels[..half]);
    let twelve = session(&desc, 12, "path");
    let mixed = saved(&twelve, &desc, IntegratorState::Film(mixed));
    let resumed = render(&twelve, 2, Some(mixed));
    assert!(!resumed.interrupted);
    assert_eq!(resumed.spp_done, 12);
    assert_eq!(bits(&resumed), bits(&straight));
}

#[test]
fn sppm_statistics_resume_to_the_uninterrupted_image() {
    let desc = cornell_caustics();
    let straight = render(&session(&desc, 5, "sppm"), 2, None);
    let Some(after2) = render(&session(&desc, 2, "sppm"), 1, None).state else {
        panic!("no SPPM state");
    };
    assert_eq!(after2.done(), 2);
    let five = session(&desc, 5, "sppm");
    let resumed = render(&five, 1, Some(saved(&five, &desc, after2)));
    assert_eq!(resumed.spp_done, 5);
    assert_eq!(bits(&resumed), bits(&straight));
    // A path tracer's film is not SPPM's state.
    let film = render(&session(&desc, 2, "path"), 1, None).state;
    let progress = Progress::default();
    let e = five
        .render_resumable(&progress, &mut |_, _| {}, film, None)
        .err()
        .expect("refused");
    assert!(e.to_string().contains("film state"), "{e}");
}
