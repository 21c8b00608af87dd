//! Resizing reused per-particle, per-entry and per-cell buffers (the DEM's chunk force rows,
//! near list and selection codes; the exchange's per-cell tables and sums). `Vec::resize` past
//! the capacity doubles it and copies the old contents, so a buffer a few rows longer than last
//! time held two, then four copies' worth of memory; here a buffer that must grow is freed first
//! and replaced by one 1/16 longer than asked.

/// `v` resized to `len` (new elements `fill`); the old contents are kept only when it fits.
pub(crate) fn resize_reused<T: Clone>(v: &mut Vec<T>, len: usize, fill: T) {
    if len > v.capacity() {
        *v = Vec::new();
        v.reserve_exact(len + len / 16);
    }
    v.resize(len, fill);
}

#[cfg(test)]
mod tests {
    use super::resize_reused;

    /// Growing by a few rows reserves 1/16 more, not twice the length; shrinking keeps the storage.
    #[test]
    fn a_grown_buffer_is_a_sixteenth_longer_not_doubled() {
        let mut v = vec![1u32; 1600];
        resize_reused(&mut v, 1604, 7);
        assert_eq!(v.len(), 1604);
        assert_eq!(v.capacity(), 1604 + 1604 / 16);
        assert!(v.iter().all(|&x| x == 7), "grown storage is filled anew");
        let cap = v.capacity();
        resize_reused(&mut v, 1000, 9);
        assert_eq!((v.len(), v.capacity()), (1000, cap));
        resize_reused(&mut v, 1700, 3);
        assert_eq!(v.capacity(), cap, "within the capacity nothing moves");
        assert!(v[..1000].iter().all(|&x| x == 7) && v[1000..].iter().all(|&x| x == 3));
    }
}
