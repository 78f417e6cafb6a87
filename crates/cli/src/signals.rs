//! SIGINT, SIGTERM and SIGHUP: the first stops the work (the integrators poll the
//! progress's `cancel` flag) so the result so far can be written; a second one quits at
//! once, unless an output file is being written, which it lets finish; a third quits
//! regardless. Outputs are written under a temporary name and renamed when complete, so
//! even that last exit leaves the previous file whole.

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};

use anyhow::Context;
use radiant::render::Progress;

/// The exit status of a process ended by a repeated signal (128 + SIGINT, as shells do).
const EXIT_SIGNALLED: i32 = 130;

/// Shared between the signal handler and the command.
#[derive(Default)]
struct Shared {
    signals: AtomicU32,
    /// Output files being written now.
    writing: AtomicU32,
}

/// The progress whose `cancel` flag the signals set, and the guard for writes.
#[derive(Clone)]
pub struct Interrupts {
    pub progress: Arc<Progress>,
    shared: Arc<Shared>,
}

/// While alive, a second signal waits for the write instead of quitting.
pub struct WriteGuard(Arc<Shared>);

impl Drop for WriteGuard {
    fn drop(&mut self) {
        self.0.writing.fetch_sub(1, Ordering::SeqCst);
    }
}

impl Interrupts {
    /// Installs the handler (once per process).
    pub fn install() -> anyhow::Result<Interrupts> {
        let progress = Arc::new(Progress::default());
        let shared = Arc::new(Shared::default());
        let (flag, state) = (Arc::clone(&progress), Arc::clone(&shared));
        // ctrlc runs this on its own thread, not in the signal context, so it may print.
        ctrlc::set_handler(move || {
            let n = state.signals.fetch_add(1, Ordering::SeqCst) + 1;
            flag.cancel.store(true, Ordering::SeqCst);
            let writing = state.writing.load(Ordering::SeqCst) > 0;
            match n {
                1 => eprintln!("radiant: stopping (a second signal quits at once)"),
                2 if writing => eprintln!(
                    "radiant: finishing the file being written (signal once more to quit now)"
                ),
                _ => {
                    eprintln!("radiant: quit by a repeated signal");
                    std::process::exit(EXIT_SIGNALLED);
                }
            }
        })
        .context("installing the handler for SIGINT, SIGTERM and SIGHUP")?;
        Ok(Interrupts { progress, shared })
    }

    /// Marks an output file as being written until the guard is dropped.
    pub fn writing(&self) -> WriteGuard {
        self.shared.writing.fetch_add(1, Ordering::SeqCst);
        WriteGuard(Arc::clone(&self.shared))
    }
}
