//! Freed buffers go back to the operating system. glibc's malloc raises its mmap threshold after
//! the first large free (up to 32 MiB), so later large buffers (a list refresh's codes, a
//! rebuild's copies) come from its heap and stay resident once freed, on top of the run's live
//! data. Fixed thresholds keep the resident memory of a run its live data: blocks of 256 KiB or
//! more are mapped and unmapped, and the heap is trimmed when 256 KiB are free at its top. A run
//! maps such blocks at its start and a few per near-list refresh (tens of steps apart), not per
//! step (docs/BENCHMARKS.md, "Scaling"). By hand: `mallopt` is glibc's own setting (through
//! `libc`); no allocator crate is needed for it.

/// Set the thresholds, once per process (later calls do nothing). Other C libraries: nothing.
pub fn return_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        static ONCE: std::sync::Once = std::sync::Once::new();
        const BLOCK: libc::c_int = 256 * 1024;
        // SAFETY: mallopt only changes malloc's parameters; it is thread-safe in glibc.
        ONCE.call_once(|| unsafe {
            libc::mallopt(libc::M_MMAP_THRESHOLD, BLOCK);
            libc::mallopt(libc::M_TRIM_THRESHOLD, BLOCK);
        });
    }
}
