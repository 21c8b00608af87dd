//! A barrier for the threads of one broadcast that spins (then yields) instead of parking:
//! `std::sync::Barrier` puts the waiters to sleep, and waking them costs tens of µs on a VM,
//! more than a gas pass. A thread that panics marks the barrier failed, so nobody waits for it.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Spins (then yields) until `done()`; false as soon as `failed` is set (a thread of the team
/// panicked), so that nobody waits for it for ever.
pub(crate) fn spin_until(done: impl Fn() -> bool, failed: &AtomicBool) -> bool {
    let mut spins = 0u32;
    while !done() {
        if failed.load(Ordering::Acquire) {
            return false;
        }
        if spins < 1 << 12 {
            std::hint::spin_loop();
            spins += 1;
        } else {
            std::thread::yield_now();
        }
    }
    true
}

pub(crate) struct SpinBarrier {
    threads: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
    failed: AtomicBool,
}

impl SpinBarrier {
    pub(crate) fn new(threads: usize) -> SpinBarrier {
        SpinBarrier {
            threads,
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            failed: AtomicBool::new(false),
        }
    }

    /// Waits until all `threads` have arrived (what each wrote before is then visible to all);
    /// false if a thread failed, and then at once.
    pub(crate) fn wait(&self) -> bool {
        let generation = self.generation.load(Ordering::Acquire);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.threads {
            // The last to arrive opens the next round: the count is reset before the release.
            self.arrived.store(0, Ordering::Relaxed);
            self.generation.fetch_add(1, Ordering::Release);
            return !self.failed.load(Ordering::Acquire);
        }
        spin_until(|| self.generation.load(Ordering::Acquire) != generation, &self.failed)
            && !self.failed.load(Ordering::Acquire)
    }

    /// Marks the team failed: every `wait`, now and later, returns false.
    pub(crate) fn fail(&self) {
        self.failed.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_thread_passes_a_round_before_all_wrote() {
        // Each of 4 threads writes its slot in round r, then after the barrier reads all slots:
        // every slot must hold r (a thread that ran ahead would have written r + 1).
        let (threads, rounds) = (4, 2000);
        let slots: Vec<AtomicUsize> = (0..threads).map(|_| AtomicUsize::new(0)).collect();
        let barrier = SpinBarrier::new(threads);
        std::thread::scope(|s| {
            for t in 0..threads {
                let (slots, barrier) = (&slots, &barrier);
                s.spawn(move || {
                    for r in 1..=rounds {
                        slots[t].store(r, Ordering::Relaxed);
                        assert!(barrier.wait());
                        assert!(slots.iter().all(|v| v.load(Ordering::Relaxed) == r), "round {r}");
                        assert!(barrier.wait());
                    }
                });
            }
        });
    }

    #[test]
    fn a_failed_team_releases_the_waiters() {
        let barrier = SpinBarrier::new(2);
        std::thread::scope(|s| {
            let waiter = s.spawn(|| barrier.wait());
            std::thread::sleep(std::time::Duration::from_millis(20));
            barrier.fail();
            assert!(!waiter.join().unwrap());
        });
        assert!(!barrier.wait());
    }
}
