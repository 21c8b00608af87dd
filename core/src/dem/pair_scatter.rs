//! The pair forces of a batch added into a chunk buffer: F on i, −F on j, and R n × F_t on both
//! (contact points ±R n, forces ±F_t). The buffer's rows are single precision, eight floats
//! (32 bytes, aligned) per particle, so the partner side (j), which had been the largest single
//! cost left in the pair pass, is one vector load, add and store, and no row crosses a cache line
//! (docs/BENCHMARKS.md, "Chunk sums in single precision"). The particle pass adds the chunks'
//! rows in double.
//!
//! Error: a row sums at most a few dozen forces, each already single precision (the contact
//! law's); rounding the running sum adds at most (k − 1)·2⁻²⁴·Σ|F| for k terms (test
//! `chunk_sums_within_the_rounding_bound_of_the_exact_sums`), the order of the law's own error.

use super::batch::{Batch, CAP};
use super::kernel::Isa;

/// Force (0..3) and n × F_t (3..6) sums of one particle over one chunk's pairs; 6 and 7 are zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct PairSum(pub [f32; 8]);

/// Add lanes 0..batch.m into `acc` (indices as the lanes'), lane by lane, i before j.
/// Panics unless every lane's particles index `acc`.
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(unused_mut, unused_variables))] // the vector path is x86-64 only
pub(crate) fn scatter<const FR: bool, const V: bool>(isa: Isa<V>, b: &Batch, acc: &mut [PairSum]) {
    let m = b.m.min(CAP);
    #[cfg(target_arch = "x86_64")]
    if let Some(_proof) = isa.as_avx512() {
        for l in (0..m).step_by(8) {
            // SAFETY: `_proof` shows the CPU has the features; l + 8 ≤ CAP (CAP is a multiple
            // of 8); scatter8 checks the particle indices.
            unsafe { scatter8::<FR>(b, l, (m - l).min(8), acc) };
        }
        return;
    }
    for l in 0..m {
        let c = if FR { [b.c[0][l], b.c[1][l], b.c[2][l]] } else { [0.0; 3] };
        let on_i = [b.f[0][l], b.f[1][l], b.f[2][l], c[0], c[1], c[2], 0.0, 0.0];
        let on_j = [-on_i[0], -on_i[1], -on_i[2], c[0], c[1], c[2], 0.0, 0.0];
        for (p, add) in [(b.i[l], on_i), (b.j[l], on_j)] {
            let row = &mut acc[p as usize].0;
            for q in 0..8 {
                row[q] += add[q];
            }
        }
    }
}

/// Lanes l..l + cnt (cnt ≤ 8): the batch's six output arrays transposed in registers into one
/// row per lane, then one load-add-store per side; the same additions in the same order as the
/// scalar loop (the sign flip is exact), so the same bits.
///
/// # Safety
/// The CPU has avx512f and avx512vl (the instructions are AVX; the feature set is the pair
/// pass's); l + 8 ≤ CAP.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn scatter8<const FR: bool>(b: &Batch, l: usize, cnt: usize, acc: &mut [PairSum]) {
    use std::arch::x86_64::*;
    debug_assert!(l + 8 <= CAP && cnt <= 8);
    let ld = |a: &[f32; CAP]| _mm256_loadu_ps(a.as_ptr().add(l));
    let z = _mm256_setzero_ps();
    let (r0, r1, r2) = (ld(&b.f[0]), ld(&b.f[1]), ld(&b.f[2]));
    let (r3, r4, r5) = if FR { (ld(&b.c[0]), ld(&b.c[1]), ld(&b.c[2])) } else { (z, z, z) };
    // 8 × 8 transpose (rows 6 and 7 zero): lane q's row is [f, c, 0, 0].
    let (t0, t1) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpackhi_ps(r0, r1));
    let (t2, t3) = (_mm256_unpacklo_ps(r2, r3), _mm256_unpackhi_ps(r2, r3));
    let (t4, t5) = (_mm256_unpacklo_ps(r4, r5), _mm256_unpackhi_ps(r4, r5));
    let (u0, u1) = (_mm256_shuffle_ps::<0x44>(t0, t2), _mm256_shuffle_ps::<0xEE>(t0, t2));
    let (u2, u3) = (_mm256_shuffle_ps::<0x44>(t1, t3), _mm256_shuffle_ps::<0xEE>(t1, t3));
    let (u4, u5) = (_mm256_shuffle_ps::<0x44>(t4, z), _mm256_shuffle_ps::<0xEE>(t4, z));
    let (u6, u7) = (_mm256_shuffle_ps::<0x44>(t5, z), _mm256_shuffle_ps::<0xEE>(t5, z));
    let rows = [
        _mm256_permute2f128_ps::<0x20>(u0, u4),
        _mm256_permute2f128_ps::<0x20>(u1, u5),
        _mm256_permute2f128_ps::<0x20>(u2, u6),
        _mm256_permute2f128_ps::<0x20>(u3, u7),
        _mm256_permute2f128_ps::<0x31>(u0, u4),
        _mm256_permute2f128_ps::<0x31>(u1, u5),
        _mm256_permute2f128_ps::<0x31>(u2, u6),
        _mm256_permute2f128_ps::<0x31>(u3, u7),
    ];
    let minus_f = _mm256_setr_ps(-0.0, -0.0, -0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (n, p) = (acc.len(), acc.as_mut_ptr() as *mut f32);
    for (q, &row) in rows.iter().enumerate().take(cnt) {
        let (i, j) = (b.i[l + q] as usize, b.j[l + q] as usize);
        assert!(i < n && j < n, "lane particle outside the chunk window");
        let pi = p.add(8 * i);
        _mm256_store_ps(pi, _mm256_add_ps(_mm256_load_ps(pi), row));
        let pj = p.add(8 * j);
        _mm256_store_ps(pj, _mm256_add_ps(_mm256_load_ps(pj), _mm256_xor_ps(row, minus_f)));
    }
}
