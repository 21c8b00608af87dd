//! Natural logarithm and exponential for the drag laws' per-particle powers (Re^x = exp(x ln Re)):
//! inlined, without libm's call and special-case branches, so that the powers of a block of
//! particles overlap in the pipeline.
//!
//! Both reduce the argument with a small table (tables.rs) so that the polynomials are short.
//! Accuracy (tested against std over the ranges used, `tests` below): relative error ≤ 4e-15 for
//! `fast_exp` on [−700, 700] and absolute error ≤ 3e-15 for `fast_ln` on [1e-300, 1e300], so a
//! drag coefficient built from them differs from the libm one by ≲ 1e-14 relative.

mod tables;

use tables::{EXP2_64THS, INV_C, LN_C};

/// ln 2 and ln 2 / 64 split into a high part with trailing zero bits (exact products with small
/// integers) and the rest (Cody–Waite).
const LN2_HI: f64 = 0.693_147_180_369_123_8;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
const LN2_64_HI: f64 = LN2_HI / 64.0;
const LN2_64_LO: f64 = LN2_LO / 64.0;
/// 1.5·2⁵²: adding and subtracting it rounds a double of magnitude < 2⁵¹ to the nearest integer.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

/// e^x for x in [−700, 700] (clamped outside): x = (64n + j)·ln2/64 + r, |r| ≤ ln2/128, so
/// e^x = 2ⁿ·2^(j/64)·e^r with e^r by its Taylor polynomial to r⁵ (truncation < 4e-17), evaluated
/// in two short chains (the latency of one long Horner chain was the cost).
#[inline(always)]
pub fn fast_exp(x: f64) -> f64 {
    let x = x.clamp(-700.0, 700.0);
    let k = (x * (64.0 * std::f64::consts::LOG2_E) + ROUND_MAGIC) - ROUND_MAGIC;
    let r = (x - k * LN2_64_HI) - k * LN2_64_LO;
    let ki = k as i64;
    let (n, j) = (ki >> 6, (ki & 63) as usize);
    let r2 = r * r;
    let p = (1.0 + r) + r2 * ((0.5 + r * (1.0 / 6.0)) + r2 * (1.0 / 24.0 + r * (1.0 / 120.0)));
    let scale = f64::from_bits(((n + 1023) as u64) << 52);
    EXP2_64THS[j] * p * scale
}

/// ln x for normal positive x: x = 2^e·m, m in [1, 2), its top seven mantissa bits pick c_i
/// with m·(1/c_i) = 1 + u, |u| < 1/256, and ln(1 + u) by its series to u⁶ (truncation < 2e-18).
#[inline(always)]
pub fn fast_ln(x: f64) -> f64 {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let i = ((bits >> 45) & 127) as usize;
    let u = m * INV_C[i] - 1.0;
    let u2 = u * u;
    let p = u - u2 * ((0.5 - u * (1.0 / 3.0)) + u2 * ((0.25 - u * 0.2) + u2 * (1.0 / 6.0)));
    let ef = e as f64;
    (ef * LN2_HI + LN_C[i]) + p + ef * LN2_LO
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn exp_matches_std_to_a_few_ulp() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = if k < 1000 { -700.0 + 1.4 * k as f64 } else { rng.gen_range(-40.0..40.0) };
            let (a, b) = (fast_exp(x), x.exp());
            worst = worst.max(((a - b) / b).abs());
        }
        assert!(worst <= 4e-15, "worst relative error {worst:e}");
        assert_eq!(fast_exp(0.0), 1.0);
    }

    #[test]
    fn ln_matches_std_to_a_few_ulp() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = if k < 1200 { 10f64.powf(-300.0 + 0.5 * k as f64) } else { rng.gen_range(1e-6..1e4) };
            let (a, b) = (fast_ln(x), x.ln());
            worst = worst.max((a - b).abs() / b.abs().max(1.0));
        }
        assert!(worst <= 3e-15, "worst error {worst:e}");
        assert!(fast_ln(1.0).abs() < 1e-16);
    }

    /// The tables, as written by (Python 3):
    ///     exp2 = [2.0**(j/64) for j in range(64)]
    ///     inv = [1.0/(1.0 + (i + 0.5)/128.0) for i in range(128)]; ln_c = [-math.log(v) for v in inv]
    #[test]
    fn tables_match_std() {
        let ulp = |a: f64, b: f64| ((a - b) / b).abs() <= f64::EPSILON;
        for (j, &v) in EXP2_64THS.iter().enumerate() {
            assert!(ulp(v, (j as f64 / 64.0).exp2()), "2^({j}/64)");
        }
        for i in 0..128 {
            assert!(ulp(INV_C[i], 1.0 / (1.0 + (i as f64 + 0.5) / 128.0)), "1/c_{i}");
            assert!(ulp(LN_C[i], -INV_C[i].ln()), "ln c_{i}");
        }
    }
}
