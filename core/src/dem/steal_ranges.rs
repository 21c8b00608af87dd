//! Work sharing for the team step: items 0..n are split into one contiguous range per thread;
//! a thread takes its own items from one end of its range and, when that is empty, steals from
//! the other end of the others'. Each item is taken exactly once, so work whose result does
//! not depend on who does it (the pair-pass chunks, the particle blocks) stays bit-identical,
//! while a thread slowed down for a while (a busy neighbour on a VM, more contacts in its part
//! of the bed) hands its last items to the others instead of making them wait for it.

use std::sync::atomic::{AtomicU64, Ordering};

pub struct StealRanges {
    /// Per thread, what is left of its range: front in the low 32 bits, back in the high 32.
    left: Vec<AtomicU64>,
    /// Owners take from the back (thieves from the front), else the other way round.
    own_from_back: bool,
}

impl StealRanges {
    /// Items 0..n over `threads` ranges of (nearly) equal length.
    pub fn new(n: usize, threads: usize, own_from_back: bool) -> Self {
        assert!(n < u32::MAX as usize && threads > 0, "{n} items over {threads} threads");
        let bound = |t: usize| (t * n / threads) as u64;
        StealRanges {
            left: (0..threads).map(|t| AtomicU64::new(bound(t + 1) << 32 | bound(t))).collect(),
            own_from_back,
        }
    }

    /// The next item for thread t: from its own range, else from the next non-empty one.
    pub fn take(&self, t: usize) -> Option<usize> {
        let nt = self.left.len();
        (0..nt).find_map(|o| self.take_from((t + o) % nt, (o == 0) != self.own_from_back))
    }

    fn take_from(&self, r: usize, front: bool) -> Option<usize> {
        let slot = &self.left[r];
        let mut cur = slot.load(Ordering::Acquire);
        loop {
            let (lo, hi) = (cur & 0xffff_ffff, cur >> 32);
            if lo >= hi {
                return None;
            }
            let (next, item) = if front { (hi << 32 | (lo + 1), lo) } else { ((hi - 1) << 32 | lo, hi - 1) };
            match slot.compare_exchange_weak(cur, next, Ordering::AcqRel, Ordering::Acquire) {
                Ok(_) => return Some(item as usize),
                Err(now) => cur = now,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::StealRanges;

    #[test]
    fn one_thread_takes_its_range_in_order_then_steals_from_the_other_end() {
        let q = StealRanges::new(10, 2, false);
        let mine: Vec<usize> = (0..5).map(|_| q.take(0).unwrap()).collect();
        assert_eq!(mine, [0, 1, 2, 3, 4]);
        let stolen: Vec<usize> = std::iter::from_fn(|| q.take(0)).collect();
        assert_eq!(stolen, [9, 8, 7, 6, 5]);
        assert_eq!(q.take(1), None);
        let q = StealRanges::new(10, 2, true);
        let all: Vec<usize> = std::iter::from_fn(|| q.take(1)).collect();
        assert_eq!(all, [9, 8, 7, 6, 5, 0, 1, 2, 3, 4]);
    }

    #[test]
    fn every_item_is_taken_exactly_once_under_contention() {
        for (n, threads, back) in [(1000, 4, false), (1000, 4, true), (7, 3, true), (0, 2, false), (3, 5, true)] {
            let q = StealRanges::new(n, threads, back);
            let taken: Vec<Vec<usize>> = std::thread::scope(|s| {
                let hs: Vec<_> = (0..threads)
                    .map(|t| {
                        s.spawn({
                            let q = &q;
                            move || std::iter::from_fn(|| q.take(t)).collect::<Vec<_>>()
                        })
                    })
                    .collect();
                hs.into_iter().map(|h| h.join().unwrap()).collect()
            });
            let mut all: Vec<usize> = taken.concat();
            all.sort_unstable();
            assert_eq!(all, (0..n).collect::<Vec<_>>(), "{n} items, {threads} threads");
        }
    }
}
