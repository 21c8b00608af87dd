//! The multistep update on flat arrays (PHYSICS.md 7): y ← y + (hb0 f + hb1 f_newer + hb2
//! f_older), then f_older ← f; the past derivatives are stored in single precision
//! (`forces::PastV3`), read widened to f64. `ab_flat` serves velocities and spins; `ab_flat_moved` serves
//! positions and also returns the largest |increment| and |new y|, which grow the system's bound
//! on the displacement since the near-list refresh. With those maxima in the loop the compiler
//! left it scalar (a redundant second update of x, v and ω cost 14% of a step), so on AVX-512
//! it is written with intrinsics: the same IEEE operations in the same order, the same bits.

use super::kernel::Isa;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// y ← y + (hb0 f + hb1 f_newer + hb2 f_older), f_older ← f (a loop the compiler vectorises).
#[inline(always)]
pub(crate) fn ab_flat(hb: [f64; 3], y: &mut [f64], f: &[f64], newer: &[f32], older: &mut [f32]) {
    for (((y, &f), &f1), f2) in y.iter_mut().zip(f).zip(newer).zip(older.iter_mut()) {
        *y += hb[0] * f + hb[1] * f1 as f64 + hb[2] * *f2 as f64;
        *f2 = f as f32;
    }
}

/// As `ab_flat`, returning (max |increment|, max |new y|) (a NaN is passed over); with AVX-512
/// intrinsics when `isa` proves them. Panics unless the four arrays have one length.
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(unused_mut, unused_variables))] // the vector path is x86-64 only
pub(crate) fn ab_flat_moved<const V: bool>(
    isa: Isa<V>,
    hb: [f64; 3],
    y: &mut [f64],
    f: &[f64],
    newer: &[f32],
    older: &mut [f32],
) -> (f64, f64) {
    let n = y.len();
    assert!(f.len() == n && newer.len() == n && older.len() == n, "arrays of one length");
    #[cfg(target_arch = "x86_64")]
    if let Some(_proof) = isa.as_avx512() {
        // SAFETY: `_proof` shows the CPU has the feature; the lengths are equal (asserted).
        return unsafe { moved_avx512(hb, y, f, newer, older) };
    }
    moved_portable(hb, y, f, newer, older)
}

fn moved_portable(hb: [f64; 3], y: &mut [f64], f: &[f64], newer: &[f32], older: &mut [f32]) -> (f64, f64) {
    let (mut inc_max, mut y_max) = (0.0f64, 0.0f64);
    for (((y, &f), &f1), f2) in y.iter_mut().zip(f).zip(newer).zip(older.iter_mut()) {
        let inc = hb[0] * f + hb[1] * f1 as f64 + hb[2] * *f2 as f64;
        *y += inc;
        *f2 = f as f32;
        let (a, b) = (inc.abs(), y.abs());
        inc_max = if a > inc_max { a } else { inc_max };
        y_max = if b > y_max { b } else { y_max };
    }
    (inc_max, y_max)
}

/// # Safety
/// The CPU has avx512f and avx512vl; the four arrays have one length.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn moved_avx512(hb: [f64; 3], y: &mut [f64], f: &[f64], newer: &[f32], older: &mut [f32]) -> (f64, f64) {
    let n = y.len();
    let h = hb.map(|c| _mm512_set1_pd(c));
    let (mut inc_max, mut y_max) = (_mm512_setzero_pd(), _mm512_setzero_pd());
    let (py, pf, pn, po) = (y.as_mut_ptr(), f.as_ptr(), newer.as_ptr(), older.as_mut_ptr());
    for k in (0..n).step_by(8) {
        // The tail by masks: its lanes past n load zeros, which leave the maxima alone.
        let m: __mmask8 = if n - k >= 8 { 0xff } else { (1u8 << (n - k)) - 1 };
        let fk = _mm512_maskz_loadu_pd(m, pf.add(k));
        let f1 = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(m, pn.add(k)));
        let f2 = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(m, po.add(k)));
        let inc =
            _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(h[0], fk), _mm512_mul_pd(h[1], f1)), _mm512_mul_pd(h[2], f2));
        let yk = _mm512_add_pd(_mm512_maskz_loadu_pd(m, py.add(k)), inc);
        _mm512_mask_storeu_pd(py.add(k), m, yk);
        _mm256_mask_storeu_ps(po.add(k), m, _mm512_cvtpd_ps(fk));
        // max(a, b) is a > b ? a : b, so a NaN in a is passed over, as in the portable loop.
        inc_max = _mm512_max_pd(_mm512_abs_pd(inc), inc_max);
        y_max = _mm512_max_pd(_mm512_abs_pd(yk), y_max);
    }
    (_mm512_reduce_max_pd(inc_max), _mm512_reduce_max_pd(y_max))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX-512 update gives the portable one's arrays and maxima bit for bit, for every tail
    /// length, with a NaN among the values; the maxima are those of the increments and new values.
    #[test]
    fn vector_update_with_maxima_equals_the_portable_one() {
        let mut seed = 11u64;
        let mut u = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let hb = [23.0 / 12.0 * 1e-3, -16.0 / 12.0 * 1e-3, 5.0 / 12.0 * 1e-3];
        for n in 0..41 {
            let mut arrays: Vec<Vec<f64>> = (0..4).map(|_| (0..n).map(|_| u() * 10.0).collect()).collect();
            if n > 20 {
                arrays[1][17] = f64::NAN;
            }
            let narrow = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
            let (y0, f, f1, f2) = (arrays[0].clone(), &arrays[1], &narrow(&arrays[2]), narrow(&arrays[3]));
            let (mut ya, mut oa) = (y0.clone(), f2.clone());
            let Some(isa) = Isa::avx512() else {
                return crate::dem::tests::skip("vector_update_with_maxima_equals_the_portable_one", "no AVX-512");
            };
            let got = ab_flat_moved(isa, hb, &mut ya, f, f1, &mut oa);
            let (mut yb, mut ob) = (y0.clone(), f2.clone());
            let want = moved_portable(hb, &mut yb, f, f1, &mut ob);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let bits32 = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!((bits(&ya), bits32(&oa)), (bits(&yb), bits32(&ob)), "arrays, n = {n}");
            assert_eq!((got.0.to_bits(), got.1.to_bits()), (want.0.to_bits(), want.1.to_bits()), "maxima, n = {n}");
            let (mut inc_max, mut y_max) = (0.0f64, 0.0f64);
            for k in (0..n).filter(|&k| !f[k].is_nan()) {
                inc_max = inc_max.max((ya[k] - y0[k]).abs());
                y_max = y_max.max(ya[k].abs());
            }
            assert!(
                (want.0 - inc_max).abs() <= 1e-12 * inc_max.max(1e-300) + 1e-15,
                "n = {n}: {} against {inc_max}",
                want.0
            );
            assert_eq!(want.1, y_max, "n = {n}");
        }
    }
}
