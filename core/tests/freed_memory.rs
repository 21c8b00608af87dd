//! `memory::return_freed_memory`: a large buffer freed after the first large free leaves the
//! resident set (one test in its own process, so no other test's buffers move the count).

/// Resident bytes of this process (Linux `/proc/self/statm`).
fn resident_bytes() -> usize {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap();
    let pages: usize = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4096
}

/// A buffer of `mb` MiB, every page written.
fn touched(mb: usize) -> Vec<u8> {
    let mut v = vec![0u8; mb << 20];
    for p in v.iter_mut().step_by(4096) {
        *p = 1;
    }
    v
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[test]
fn a_freed_buffer_after_the_first_large_free_leaves_the_resident_set() {
    fluidbed_core::memory::return_freed_memory();
    // Without the setting, this free raises glibc's mmap threshold to 16 MiB ...
    drop(std::hint::black_box(touched(16)));
    // ... and these 8 MiB would come from the heap, below a live small block, and stay resident.
    let before = resident_bytes();
    let big = std::hint::black_box(touched(8));
    let small = std::hint::black_box(vec![1u8; 64]);
    let with = resident_bytes();
    drop(big);
    let after = resident_bytes();
    drop(small);
    assert!(with >= before + (7 << 20), "the buffer was resident: {before} → {with}");
    assert!(after + (7 << 20) <= with, "freed 8 MiB, resident {with} → {after}");
}
