//! A slice shared by a team of threads (one rayon broadcast): read in windows that may overlap,
//! written in disjoint pieces, in phases the team's code orders (a phase's reads start only after
//! the writes they need are done). Safe Rust has no such view across a broadcast's threads.

/// A slice the team reads in (possibly overlapping) windows and writes in disjoint pieces.
#[derive(Clone, Copy)]
pub(crate) struct Raw<T> {
    pub(crate) ptr: *mut T,
    pub(crate) len: usize,
}

// SAFETY: `Raw` hands out references only under the phase rules of its team (`dem::team_step`,
// `cfd::team_rhs`), which the callers of `view` and `part` uphold.
unsafe impl<T: Send + Sync> Send for Raw<T> {}
unsafe impl<T: Send + Sync> Sync for Raw<T> {}

impl<T> Raw<T> {
    pub(crate) fn new(s: &mut [T]) -> Self {
        Raw { ptr: s.as_mut_ptr(), len: s.len() }
    }
    /// # Safety
    /// No mutable reference into lo..hi is live while the returned one is.
    pub(crate) unsafe fn view<'a>(self, lo: usize, hi: usize) -> &'a [T] {
        assert!(lo <= hi && hi <= self.len, "view {lo}..{hi} of {}", self.len);
        std::slice::from_raw_parts(self.ptr.add(lo), hi - lo)
    }
    /// # Safety
    /// No other reference into lo..hi is live while the returned one is.
    pub(crate) unsafe fn part<'a>(self, lo: usize, hi: usize) -> &'a mut [T] {
        assert!(lo <= hi && hi <= self.len, "piece {lo}..{hi} of {}", self.len);
        std::slice::from_raw_parts_mut(self.ptr.add(lo), hi - lo)
    }
}
