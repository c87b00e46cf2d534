//! The first factor's value buffer, mapped while the analysis runs by a thread that only takes
//! a core nothing else wants.
//!
//! A fresh factor's pages fault at their first write, one per 4 KiB (153,000 on the L cell's
//! 628 MB, 2.5–12 µs each on the VM the benchmarks ran on: `benches/fresh_pages.c`); in the
//! factorization both cores take them in its critical path. During the analysis a core is
//! idle part of the time (METIS is sequential, and AMD and the Θ load beside it end first).
//! A helper at idle priority (Linux `SCHED_IDLE`) writes zeros into the buffer in chunks, up
//! to a target the analysis raises as it learns the factor's size: a lower bound of every
//! ordering's nnz(L) at once, then the predicted nnz(L), then the symbolic factor's value
//! count. The factorization stops it — never waiting for more than the chunk in hand — takes
//! what it mapped and zeroes the rest on all threads. An analysis that no factorization
//! follows holds the mapped buffer (the factor's size) until its solver analyzes again or is
//! dropped.

use fibercell_solver::{extend_with_zeros, extend_with_zeros_par};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Matrices whose factor holds at least this many bytes by the first, lower-bound target get
/// a prefaulted buffer. Below it the gain is lost in the noise: on the M cell (90 MB factor,
/// 15 MB by the bound) a threshold of 8 MiB left `homogenize` at 0.44–0.54 s against
/// 0.44–0.56 s, five alternating pairs.
pub(crate) const PREFAULT_BYTES: usize = 64 << 20;

/// Values the helper writes between two looks at its target and stop flag (2 MiB).
const CHUNK: usize = 1 << 18;

/// What the helper is told.
#[derive(Default)]
struct Target {
    /// Values to have mapped.
    values: AtomicUsize,
    /// Stop and hand the buffer over.
    stop: AtomicBool,
}

/// A value buffer being mapped by its helper thread.
pub(crate) struct PrefaultedValues {
    target: Arc<Target>,
    /// `None` once taken.
    helper: Option<JoinHandle<Vec<f64>>>,
}

impl PrefaultedValues {
    /// Starts mapping `values` zeros when they are at least `threshold_bytes`; `None` for a
    /// smaller factor or when no thread can be started.
    pub(crate) fn start(values: usize, threshold_bytes: usize) -> Option<Self> {
        if values.saturating_mul(8) < threshold_bytes {
            return None;
        }
        let target = Arc::new(Target::default());
        target.values.store(values, Ordering::Release);
        let shared = Arc::clone(&target);
        let helper = std::thread::Builder::new()
            .name("fibercell-prefault".into())
            .spawn(move || map(&shared))
            .ok()?;
        Some(PrefaultedValues {
            target,
            helper: Some(helper),
        })
    }

    /// Raises the number of values to map (a lower target is ignored: the mapped values are
    /// all used).
    pub(crate) fn aim(&self, values: usize) {
        self.target.values.fetch_max(values, Ordering::AcqRel);
        if let Some(h) = &self.helper {
            h.thread().unpark();
        }
    }

    /// `len` zeros: what the helper mapped (it stops after its current chunk), the rest
    /// written here on all threads.
    pub(crate) fn take(mut self, len: usize) -> Vec<f64> {
        self.stop();
        let mut values = self
            .helper
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        values.truncate(len);
        extend_with_zeros_par(&mut values, len);
        values
    }

    fn stop(&self) {
        self.target.stop.store(true, Ordering::Release);
        if let Some(h) = &self.helper {
            h.thread().unpark();
        }
    }
}

impl Drop for PrefaultedValues {
    /// An analysis that failed or was replaced: the helper stops and frees its buffer on its
    /// own thread.
    fn drop(&mut self) {
        self.stop();
    }
}

/// The helper: zeros appended in chunks up to the target until told to stop.
fn map(target: &Target) -> Vec<f64> {
    idle_priority();
    let mut values: Vec<f64> = Vec::new();
    while !target.stop.load(Ordering::Acquire) {
        let want = target.values.load(Ordering::Acquire);
        if values.len() >= want {
            std::thread::park_timeout(Duration::from_millis(5));
            continue;
        }
        // One reservation per target: a large buffer grows by remapping, not copying.
        if values.capacity() < want && values.try_reserve_exact(want - values.len()).is_err() {
            break;
        }
        let next = want.min(values.len() + CHUNK);
        extend_with_zeros(&mut values, next);
    }
    values
}

/// Puts the calling thread at idle priority: it runs only on a core no other thread wants.
#[cfg(target_os = "linux")]
fn idle_priority() {
    let param = libc::sched_param { sched_priority: 0 };
    // SAFETY: `param` is a valid sched_param; pid 0 is the calling thread. A refusal leaves
    // the thread at its priority, which is only slower.
    unsafe {
        libc::sched_setscheduler(0, libc::SCHED_IDLE, &param);
    }
}

/// Elsewhere the helper keeps its priority.
#[cfg(not(target_os = "linux"))]
fn idle_priority() {}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whatever the helper managed before the take — nothing, part or all of its target,
    /// with the target raised on the way — the buffer is `len` zeros, and a target below
    /// the threshold starts no helper.
    #[test]
    fn the_taken_buffer_is_zeros_of_the_asked_length() {
        assert!(PrefaultedValues::start(1000, 8001).is_none());
        for (first, raised, len) in [(10, 0, 10), (1000, 5 * CHUNK + 3, 5 * CHUNK + 3)] {
            for wait in [false, true] {
                let p = PrefaultedValues::start(first, 0).expect("a helper");
                p.aim(raised);
                if wait {
                    std::thread::sleep(Duration::from_millis(50));
                }
                let v = p.take(len);
                assert_eq!(v.len(), len);
                assert!(v.iter().all(|&x| x == 0.0));
            }
        }
        // A take shorter than what was mapped, and one longer.
        let p = PrefaultedValues::start(3 * CHUNK, 0).expect("a helper");
        std::thread::sleep(Duration::from_millis(50));
        assert_eq!(p.take(CHUNK).len(), CHUNK);
        let p = PrefaultedValues::start(7, 0).expect("a helper");
        let v = p.take(2 * CHUNK + 1);
        assert!(v.len() == 2 * CHUNK + 1 && v.iter().all(|&x| x == 0.0));
        // Dropped without a take: the helper stops on its own.
        drop(PrefaultedValues::start(CHUNK, 0));
    }
}
