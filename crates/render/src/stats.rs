//! Event counters for `--stats`: rays by kind, scene queries, paths.
//!
//! Each thread counts into its own cache-line-sized slot (a plain load and store, no
//! locked read-modify-write and no sharing between cores), registered once per thread;
//! a report sums the slots. Counting therefore costs a thread-local access per event
//! and never changes what is rendered. Slots outlive their threads, so counts of a
//! finished pool stay in the totals; a report takes the difference of two totals.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// What is counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Counter {
    /// Rays leaving the camera (one per pixel sample that has a ray).
    CameraRays,
    /// Closest-hit scene queries (camera, indirect and photon rays).
    ClosestHitTests,
    /// Any-hit scene queries (shadow rays).
    ShadowTests,
    /// Rays of photon paths (photon mapping and SPPM photon passes).
    PhotonRays,
    /// Photon paths started at the lights.
    PhotonPaths,
}

const COUNTERS: usize = 5;

#[repr(align(128))]
#[derive(Default)]
struct Slot([AtomicU64; COUNTERS]);

static SLOTS: Mutex<Vec<Arc<Slot>>> = Mutex::new(Vec::new());

thread_local! {
    static MINE: Arc<Slot> = {
        let slot = Arc::new(Slot::default());
        SLOTS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(Arc::clone(&slot));
        slot
    };
}

/// Adds `n` events of `counter` on this thread.
#[inline]
pub fn add(counter: Counter, n: u64) {
    MINE.with(|slot| {
        // Only this thread writes its slot: a relaxed load and store is exact.
        let c = &slot.0[counter as usize];
        c.store(c.load(Ordering::Relaxed) + n, Ordering::Relaxed);
    });
}

/// Counts summed over all threads (since the process started).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub camera_rays: u64,
    pub closest_hit_tests: u64,
    pub shadow_tests: u64,
    pub photon_rays: u64,
    pub photon_paths: u64,
}

impl Counts {
    /// The totals so far.
    pub fn now() -> Counts {
        let mut sum = [0u64; COUNTERS];
        for slot in SLOTS.lock().unwrap_or_else(|e| e.into_inner()).iter() {
            for (s, c) in sum.iter_mut().zip(&slot.0) {
                *s += c.load(Ordering::Relaxed);
            }
        }
        Counts {
            camera_rays: sum[Counter::CameraRays as usize],
            closest_hit_tests: sum[Counter::ClosestHitTests as usize],
            shadow_tests: sum[Counter::ShadowTests as usize],
            photon_rays: sum[Counter::PhotonRays as usize],
            photon_paths: sum[Counter::PhotonPaths as usize],
        }
    }

    /// The events between `earlier` and `self`.
    pub fn since(&self, earlier: &Counts) -> Counts {
        Counts {
            camera_rays: self.camera_rays - earlier.camera_rays,
            closest_hit_tests: self.closest_hit_tests - earlier.closest_hit_tests,
            shadow_tests: self.shadow_tests - earlier.shadow_tests,
            photon_rays: self.photon_rays - earlier.photon_rays,
            photon_paths: self.photon_paths - earlier.photon_paths,
        }
    }

    /// Closest-hit rays that are neither camera nor photon rays: path continuations,
    /// final gathering, SPPM's camera paths past the first hit.
    pub fn indirect_rays(&self) -> u64 {
        self.closest_hit_tests
            .saturating_sub(self.camera_rays + self.photon_rays)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_of_all_threads_are_summed() {
        let before = Counts::now();
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    for _ in 0..1000 {
                        add(Counter::ShadowTests, 1);
                    }
                    add(Counter::PhotonPaths, 7);
                });
            }
        });
        let d = Counts::now().since(&before);
        // Other tests of this process may count too, but never fewer.
        assert!(d.shadow_tests >= 4000, "{d:?}");
        assert!(d.photon_paths >= 28, "{d:?}");
    }
}
