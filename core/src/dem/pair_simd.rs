//! AVX-512 kernels of the pair pass, eight lanes at a time, doing the same IEEE operations in the
//! same order as the scalar code they replace (so the same bits):
//! - `scan8`: gather both positions of eight list entries, r² < (2R)², and compress the
//!   touching ones into the next batch lanes (the scalar scan is in `forces`);
//! - `gather8`: the velocities, spins and live histories of eight batch lanes (the scalar
//!   gather is in `Batch::evaluate`);
//! - `write_back8`: the lanes' new histories back into their slots (scalar: `Batch::evaluate`).
//!
//! The row side of eight entries or lanes (x_i, v_i, ω_i) and their history slots are ascending
//! and close together, so `Rows` loads them as two or four whole vectors and permutes instead
//! of gathering (docs/BENCHMARKS.md, "Rows by permute").

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

use super::batch::{Batch, Entries, PairInputs, CAP};
use super::contact::V3;
use super::kernel::Isa;
use super::neighbors::Hist;

/// Lanes this step can add to a batch: a batch with more than `CAP - LANES` filled is flushed
/// first.
pub(crate) const LANES: usize = 8;

/// Entries k..k+8 of `e` (flags `to[k - base..]` when FR) into `batch` from lane m (≤ CAP − 8);
/// returns the new lane count. Panics unless the entries, flags and lanes exist and every row
/// and partner index − `e.first` is in 0..e.x.len().
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn scan8<const FR: bool>(
    isa: Isa<true>,
    e: &Entries,
    k: usize,
    base: usize,
    to: &mut [u8],
    batch: &mut Batch,
    m: usize,
) -> usize {
    let _proof = isa;
    assert!(k + LANES <= e.owner.len() && k + LANES <= e.nbr.len() && m <= CAP - LANES, "entries or lanes");
    assert!(e.x.len() <= i32::MAX as usize / 3 && e.first <= u32::MAX as usize, "window size");
    assert!(!FR || (k >= base && k - base + LANES <= to.len()), "contact flags");
    // SAFETY: `isa` proves the CPU features; the bounds are checked above, the indices inside.
    unsafe { scan8_avx512::<FR>(e, k, base, to, batch, m) }
}

/// # Safety
/// The CPU has avx512f, avx512vl and bmi2; the bounds `scan8` checks hold.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,bmi2")]
unsafe fn scan8_avx512<const FR: bool>(
    e: &Entries,
    k: usize,
    base: usize,
    to: &mut [u8],
    batch: &mut Batch,
    m: usize,
) -> usize {
    let &Entries { owner, nbr, first, x, d2 } = e;
    debug_assert!(k + LANES <= owner.len() && k + LANES <= nbr.len() && m <= CAP - LANES);
    let at = _mm256_set1_epi32(first as u32 as i32);
    let oi = _mm256_cvtepu16_epi32(_mm_loadu_si128(owner.as_ptr().add(k) as *const __m128i));
    let oj = _mm256_sub_epi32(_mm256_loadu_si256(nbr.as_ptr().add(k) as *const __m256i), at);
    // Indices below first wrap to large unsigned values, so one compare checks both ends.
    let len = _mm256_set1_epi32(x.len() as i32);
    let inside = _mm256_cmplt_epu32_mask(oi, len) & _mm256_cmplt_epu32_mask(oj, len);
    assert!(inside == 0xff, "pair index outside the chunk window");
    // f64 offsets of x[i][0]: 3 i.
    let (ti, tj) = (_mm256_add_epi32(_mm256_add_epi32(oi, oi), oi), _mm256_add_epi32(_mm256_add_epi32(oj, oj), oj));
    let p = x.as_ptr() as *const f64;
    // The rows of eight consecutive entries are ascending (the list's order).
    let (i0, i7) = (owner[k] as usize, owner[k + 7] as usize); // the lanes' values, checked above
    let rows = Rows::new(p, i0, i7, x.len(), ti, 0xff);
    let mut dx = [_mm512_setzero_pd(); 3];
    for (a, d) in dx.iter_mut().enumerate() {
        let xi = rows.component(a);
        let xj = _mm512_i32gather_pd::<8>(tj, p.add(a));
        *d = _mm512_sub_pd(xj, xi);
    }
    // r² = (dx₀² + dx₁²) + dx₂², as the scalar scan.
    let r2 = _mm512_add_pd(
        _mm512_add_pd(_mm512_mul_pd(dx[0], dx[0]), _mm512_mul_pd(dx[1], dx[1])),
        _mm512_mul_pd(dx[2], dx[2]),
    );
    let d2v = _mm512_set1_pd(d2);
    let touch: __mmask8 = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(r2, d2v);
    const BYTES: u64 = 0x0101_0101_0101_0101;
    if FR {
        // Per-entry byte flags: read "touched last step", write "touches now".
        let t = to.as_mut_ptr().add(k - base) as *mut u64;
        let was = _pext_u64(t.read_unaligned(), BYTES) as u32;
        t.write_unaligned(_pdep_u64(touch as u64, BYTES));
        let kept = _pext_u32(was, touch as u32) as u64;
        (batch.was.as_mut_ptr().add(m) as *mut u64).write_unaligned(_pdep_u64(kept, BYTES));
    }
    // Compressed in registers, stored as whole vectors (lanes past the count are scratch).
    let kk = _mm256_add_epi32(_mm256_set1_epi32(k as i32), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    _mm256_storeu_si256(batch.k.as_mut_ptr().add(m) as *mut __m256i, _mm256_maskz_compress_epi32(touch, kk));
    _mm256_storeu_si256(batch.i.as_mut_ptr().add(m) as *mut __m256i, _mm256_maskz_compress_epi32(touch, oi));
    _mm256_storeu_si256(batch.j.as_mut_ptr().add(m) as *mut __m256i, _mm256_maskz_compress_epi32(touch, oj));
    // Rounded to single precision as `Batch::set` does.
    let put = |lanes: &mut [f32; CAP], d: __m512d| {
        _mm256_storeu_ps(lanes.as_mut_ptr().add(m), _mm256_maskz_compress_ps(touch, _mm512_cvtpd_ps(d)))
    };
    for (a, d) in dx.iter().enumerate() {
        put(&mut batch.dx[a], *d);
    }
    put(&mut batch.r2, r2);
    put(&mut batch.gap2, _mm512_sub_pd(d2v, r2));
    m + touch.count_ones() as usize
}

/// Lanes l..l+8 of `batch` (those in `valid`): v_i − v_j, R(ω_i + ω_j) and, for lanes whose
/// history is live, the history `shear[k − base]` (zero otherwise). Panics unless l + 8 ≤ CAP and
/// every valid lane has i, j < v.len() (and w.len() when FR) and base ≤ k < base + shear.len().
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn gather8<const FR: bool>(
    isa: Isa<true>,
    batch: &mut Batch,
    l: usize,
    valid: __mmask8,
    inp: &PairInputs,
    shear: &[Hist],
    base: usize,
) {
    let _proof = isa;
    assert!(l + LANES <= CAP, "lanes");
    let limit = i32::MAX as usize / 3;
    assert!(inp.v.len() <= limit && inp.w.len() <= limit && shear.len() <= limit && base <= u32::MAX as usize);
    // SAFETY: `isa` proves the CPU features; the sizes are checked above, the indices inside.
    unsafe { gather8_avx512::<FR>(batch, l, valid, inp.r, inp.v, inp.w, shear, base) }
}

/// # Safety
/// The CPU has avx512f, avx512vl and bmi2; the bounds `gather8` checks hold.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,bmi2")]
#[allow(clippy::too_many_arguments)] // `gather8`'s, unpacked for the intrinsics
unsafe fn gather8_avx512<const FR: bool>(
    batch: &mut Batch,
    l: usize,
    valid: __mmask8,
    r: f64,
    v: &[V3],
    w: &[V3],
    shear: &[Hist],
    base: usize,
) {
    debug_assert!(l + LANES <= CAP);
    let three = |a: __m256i| _mm256_add_epi32(_mm256_add_epi32(a, a), a);
    let oi = _mm256_loadu_si256(batch.i.as_ptr().add(l) as *const __m256i);
    let oj = _mm256_loadu_si256(batch.j.as_ptr().add(l) as *const __m256i);
    let below = |a: __m256i, n: usize| _mm256_cmplt_epu32_mask(a, _mm256_set1_epi32(n as i32));
    let nv = if FR { v.len().min(w.len()) } else { v.len() };
    assert!(below(oi, nv) & below(oj, nv) & valid == valid, "pair index beyond the particles");
    let (ti, tj) = (three(oi), three(oj));
    let z = _mm512_setzero_pd();
    let vp = v.as_ptr() as *const f64;
    // Lanes keep the entries' order, so rows and slots ascend from the first to the last valid lane.
    let last = l + 7 - valid.leading_zeros() as usize;
    let (i0, il) = (batch.i[l] as usize, batch.i[last] as usize);
    let vrows = Rows::new(vp, i0, il, v.len(), ti, valid);
    for q in 0..3 {
        let vi = vrows.component(q);
        let vj = _mm512_mask_i32gather_pd::<8>(z, valid, tj, vp.add(q));
        _mm256_storeu_ps(batch.vrel[q].as_mut_ptr().add(l), _mm512_cvtpd_ps(_mm512_sub_pd(vi, vj)));
    }
    if !FR {
        return;
    }
    let (wp, sp, rr) = (w.as_ptr() as *const f64, shear.as_ptr() as *const f32, _mm512_set1_pd(r));
    let kk = _mm256_sub_epi32(
        _mm256_loadu_si256(batch.k.as_ptr().add(l) as *const __m256i),
        _mm256_set1_epi32(base as u32 as i32),
    );
    // k < base wraps to a large unsigned value, so one compare checks both ends.
    assert!(below(kk, shear.len()) & valid == valid, "history slot beyond the chunk");
    let tk = three(kk);
    const BYTES: u64 = 0x0101_0101_0101_0101;
    let live = valid & _pext_u64((batch.was.as_ptr().add(l) as *const u64).read_unaligned(), BYTES) as __mmask8;
    let wrows = Rows::new(wp, i0, il, w.len(), ti, valid);
    let slot = |k: u32| k.wrapping_sub(base as u32) as usize; // the lanes' values, checked above
    let (k0, kl) = (slot(batch.k[l]), slot(batch.k[last]));
    let slots = Slots::new(sp, k0, kl, shear.len(), tk, live);
    for q in 0..3 {
        let wi = wrows.component(q);
        let wj = _mm512_mask_i32gather_pd::<8>(z, valid, tj, wp.add(q));
        _mm256_storeu_ps(batch.ws[q].as_mut_ptr().add(l), _mm512_cvtpd_ps(_mm512_mul_pd(rr, _mm512_add_pd(wi, wj))));
        _mm256_storeu_ps(batch.s[q].as_mut_ptr().add(l), slots.component(q));
    }
}

/// The histories of lanes l..l+8 (those in `valid`) back into `shear[k − base]`, by three
/// vector scatters (the slots are distinct; the values are exact in single precision). Panics
/// unless l + 8 ≤ CAP and every valid lane has base ≤ k < base + shear.len().
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn write_back8(isa: Isa<true>, batch: &Batch, l: usize, valid: __mmask8, shear: &mut [Hist], base: usize) {
    let _proof = isa;
    assert!(l + LANES <= CAP && shear.len() <= i32::MAX as usize / 3 && base <= u32::MAX as usize);
    // SAFETY: `isa` proves the CPU features; the sizes are checked above, the slots inside.
    unsafe { write_back8_avx512(batch, l, valid, shear, base) }
}

/// # Safety
/// The CPU has avx512f and avx512vl; the bounds `write_back8` checks hold.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn write_back8_avx512(batch: &Batch, l: usize, valid: __mmask8, shear: &mut [Hist], base: usize) {
    debug_assert!(l + LANES <= CAP);
    let kk = _mm256_sub_epi32(
        _mm256_loadu_si256(batch.k.as_ptr().add(l) as *const __m256i),
        _mm256_set1_epi32(base as u32 as i32),
    );
    let inside = _mm256_cmplt_epu32_mask(kk, _mm256_set1_epi32(shear.len() as i32));
    assert!(inside & valid == valid, "history slot beyond the chunk");
    let tk = _mm256_add_epi32(_mm256_add_epi32(kk, kk), kk);
    let sp = shear.as_mut_ptr() as *mut f32;
    for q in 0..3 {
        let s = _mm256_loadu_ps(batch.s[q].as_ptr().add(l));
        _mm256_mask_i32scatter_ps::<4>(sp.add(q), valid, tk, s);
    }
}

/// Component q of eight lanes' records (a V3 array at `p` of `len` records, lanes `valid`,
/// offsets `t` = 3 i, ascending, first lane i0, last valid lane il): from two or four vector
/// loads and permutes when the lanes span at most five or ten records, else a gather (the same
/// values either way; lanes outside `valid` are zero).
#[cfg(target_arch = "x86_64")]
struct Rows {
    p: *const f64,
    t: __m256i,
    valid: __mmask8,
    near: Near,
}

#[cfg(target_arch = "x86_64")]
enum Near {
    Two([__m512d; 2], __m256i),
    Four([__m512d; 4], __m256i),
    Far,
}

#[cfg(target_arch = "x86_64")]
impl Rows {
    /// # Safety
    /// As the gathers: every valid lane's 3 i + 2 < 3 len; i0 ≤ il are its first and last records.
    #[inline(always)]
    unsafe fn new(p: *const f64, i0: usize, il: usize, len: usize, t: __m256i, valid: __mmask8) -> Rows {
        let span = il.wrapping_sub(i0);
        let at = p.add(3 * i0);
        let rel = || _mm256_sub_epi32(t, _mm256_set1_epi32(3 * i0 as i32));
        let near = if span <= 4 && 3 * i0 + 16 <= 3 * len {
            Near::Two([_mm512_loadu_pd(at), _mm512_loadu_pd(at.add(8))], rel())
        } else if span <= 9 && 3 * i0 + 32 <= 3 * len {
            let l = |o: usize| _mm512_loadu_pd(at.add(o));
            Near::Four([l(0), l(8), l(16), l(24)], rel())
        } else {
            Near::Far
        };
        Rows { p, t, valid, near }
    }

    #[inline(always)]
    unsafe fn component(&self, q: usize) -> __m512d {
        let idx = |rel: __m256i| _mm512_cvtepi32_epi64(_mm256_add_epi32(rel, _mm256_set1_epi32(q as i32)));
        match self.near {
            Near::Two([a, b], rel) => _mm512_maskz_permutex2var_pd(self.valid, a, idx(rel), b),
            Near::Four([a, b, c, d], rel) => {
                let i = idx(rel);
                let (lo, hi) = (_mm512_permutex2var_pd(a, i, b), _mm512_permutex2var_pd(c, i, d));
                let upper = _mm512_cmpge_epi64_mask(i, _mm512_set1_epi64(16));
                _mm512_maskz_mov_pd(self.valid, _mm512_mask_blend_pd(upper, lo, hi))
            }
            Near::Far => _mm512_mask_i32gather_pd::<8>(_mm512_setzero_pd(), self.valid, self.t, self.p.add(q)),
        }
    }
}

/// Component q of eight lanes' histories (single precision, a `Hist` array at `p` of `len`
/// slots, lanes `valid`, offsets `t` = 3 k, ascending, first lane k0, last valid lane kl): from
/// two vector loads and a permute when the lanes span at most ten slots, else a gather (the same
/// values either way; lanes outside `valid` are zero).
#[cfg(target_arch = "x86_64")]
struct Slots {
    p: *const f32,
    t: __m256i,
    valid: __mmask8,
    near: Option<([__m512; 2], __m256i)>,
}

#[cfg(target_arch = "x86_64")]
impl Slots {
    /// # Safety
    /// As the gathers: every valid lane's 3 k + 2 < 3 len; k0 ≤ kl are its first and last slots.
    #[inline(always)]
    unsafe fn new(p: *const f32, k0: usize, kl: usize, len: usize, t: __m256i, valid: __mmask8) -> Slots {
        let near = if kl.wrapping_sub(k0) <= 9 && 3 * k0 + 32 <= 3 * len {
            let at = p.add(3 * k0);
            Some((
                [_mm512_loadu_ps(at), _mm512_loadu_ps(at.add(16))],
                _mm256_sub_epi32(t, _mm256_set1_epi32(3 * k0 as i32)),
            ))
        } else {
            None
        };
        Slots { p, t, valid, near }
    }

    #[inline(always)]
    unsafe fn component(&self, q: usize) -> __m256 {
        let got = match self.near {
            Some(([a, b], rel)) => {
                let idx = _mm512_zextsi256_si512(_mm256_add_epi32(rel, _mm256_set1_epi32(q as i32)));
                _mm512_castps512_ps256(_mm512_permutex2var_ps(a, idx, b))
            }
            None => _mm256_mmask_i32gather_ps::<4>(_mm256_setzero_ps(), self.valid, self.t, self.p.add(q)),
        };
        _mm256_maskz_mov_ps(self.valid, got)
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    /// `Rows` and `Slots` give what a masked gather gives, for every span (the two-load,
    /// four-load and gather paths), lanes near both ends of the array and partial masks.
    #[test]
    fn rows_and_slots_by_permute_equal_the_gather() {
        if Isa::avx512().is_none() {
            return crate::dem::tests::skip("rows_and_slots_by_permute_equal_the_gather", "no AVX-512");
        }
        let len = 40;
        let data: Vec<[f64; 3]> = (0..len).map(|i| [i as f64, 1000.0 + i as f64, -(i as f64) - 0.5]).collect();
        let p = data.as_ptr() as *const f64;
        let hist: Vec<[f32; 3]> = data.iter().map(|d| d.map(|c| c as f32)).collect();
        let mut seed = 7u64;
        for case in 0..3000 {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let span = (seed >> 33) as usize % 14;
            let i0 = (seed >> 13) as usize % (len - span);
            // Eight ascending rows in i0..=i0 + span, the first i0, the last valid one i0 + span.
            let valid: u8 = if case % 3 == 0 { 0xff >> ((seed >> 50) % 8) } else { 0xff };
            let nvalid = 8 - valid.leading_zeros() as usize;
            let mut rows = [i0; 8];
            for (q, r) in rows.iter_mut().enumerate().take(nvalid) {
                *r = if nvalid == 1 { i0 } else { i0 + (span * q) / (nvalid - 1) };
            }
            let mask = if case % 5 == 0 { valid & (seed >> 40) as u8 } else { valid };
            let t: [i32; 8] = rows.map(|r| 3 * r as i32);
            // SAFETY: the features were checked; every lane's row is below len.
            unsafe {
                let tv = _mm256_loadu_si256(t.as_ptr() as *const __m256i);
                let r = Rows::new(p, i0, rows[nvalid - 1], len, tv, mask);
                let s = Slots::new(hist.as_ptr() as *const f32, i0, rows[nvalid - 1], len, tv, mask);
                for q in [0, 1, 2] {
                    let got: [f64; 8] = std::mem::transmute(r.component(q));
                    let got_hist: [f32; 8] = std::mem::transmute(s.component(q));
                    for (lane, &row) in rows.iter().enumerate() {
                        let want = if mask >> lane & 1 == 1 { data[row][q] } else { 0.0 };
                        assert_eq!(
                            got[lane], want,
                            "case {case}: span {span}, first row {i0}, lane {lane}, component {q}"
                        );
                        assert_eq!(
                            got_hist[lane] as f64, want,
                            "histories: case {case}, span {span}, lane {lane}, component {q}"
                        );
                    }
                }
            }
        }
    }
}
