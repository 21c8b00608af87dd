//! The particle-particle contact law of `contact::law_force`, evaluated for a batch of
//! touching pairs at a time (PHYSICS.md 2.2-2.3), in single precision from double-precision
//! positions, velocities and histories (see `lanes`; `pair_scatter` sums the forces). The lanes
//! hold single-precision values only (each rounded once from the double it is formed in), so
//! the lane loop is all single precision and runs sixteen lanes per AVX-512 vector.
//!
//! Three phases: a scalar gather (velocities, spins and histories of the lanes' particles into
//! lane arrays), a branch-free lane loop over independent contacts that the compiler turns into
//! SIMD (the Coulomb limit is a select), and the history write-back. The caller (the pair pass)
//! is compiled for AVX-512, AVX2 and baseline (`kernel::Kernel`); Rust never fuses a multiply
//! and an add by itself, so every variant does the same IEEE operations and gives the same bits.

use super::batch::{Batch, PairInputs, CAP};
use super::contact::{law_force, ContactLaw, ContactStyle};
use super::contact_styles::{HertzMindlin, LinearSpringDashpot, Style};
use super::kernel::Isa;
use super::neighbors::Hist;
#[cfg(target_arch = "x86_64")]
use super::pair_simd::{gather8, write_back8, LANES};

/// Evaluate every lane of `b`: fills `f` (and `c`, and the history `shear[k − base]` when FR; a
/// lane with `was` = 0 starts from a zero history). Returns (max overlap, max (|F_t|² − (μF_n)²) /
/// (μF_n)²), the second −∞ unless `inp.audit`. Panics unless every lane's particles index
/// `inp.v` (and `inp.w` when FR) and its slot lies in base..base + shear.len().
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(unused_mut, unused_variables))] // the vector path is x86-64 only
pub(crate) fn evaluate<const FR: bool, const V: bool>(
    isa: Isa<V>,
    b: &mut Batch,
    inp: &PairInputs,
    shear: &mut [Hist],
    base: usize,
) -> (f64, f64) {
    let m = b.m.min(CAP);
    let (v, w) = (inp.v, inp.w);
    let n = v.len();
    assert!(w.len() == n || !FR);
    let mut l0 = 0;
    #[cfg(target_arch = "x86_64")]
    if let Some(isa) = isa.as_avx512() {
        for l in (0..m).step_by(LANES) {
            let valid = if m - l >= LANES { 0xff } else { (1u8 << (m - l)) - 1 };
            gather8::<FR>(isa, b, l, valid, inp, shear, base);
        }
        l0 = m;
    }
    for l in l0..m {
        let (i, j) = (b.i[l] as usize, b.j[l] as usize);
        let (vi, vj) = (v[i], v[j]);
        for q in 0..3 {
            b.vrel[q][l] = (vi[q] - vj[q]) as f32;
        }
        if FR {
            let (wi, wj) = (w[i], w[j]);
            let s = shear[b.k[l] as usize - base];
            let live = b.was[l] != 0;
            for q in 0..3 {
                b.ws[q][l] = (inp.r * (wi[q] + wj[q])) as f32;
                b.s[q][l] = if live { s[q] } else { 0.0 };
            }
        }
    }
    let audit = FR && inp.audit;
    if audit {
        lanes::<FR, true>(b, inp.law, 2.0 * inp.r, inp.h);
    } else {
        lanes::<FR, false>(b, inp.law, 2.0 * inp.r, inp.h);
    }
    let max_delta = lane_max(m, 0.0f32, |l| b.delta[l]) as f64;
    if !FR {
        return (max_delta, f64::NEG_INFINITY);
    }
    let max_excess = if audit { lane_max(m, f32::NEG_INFINITY, |l| b.excess[l]) as f64 } else { f64::NEG_INFINITY };
    let mut l0 = 0;
    #[cfg(target_arch = "x86_64")]
    if let Some(isa) = isa.as_avx512() {
        for l in (0..m).step_by(LANES) {
            let valid = if m - l >= LANES { 0xff } else { (1u8 << (m - l)) - 1 };
            write_back8(isa, b, l, valid, shear, base);
        }
        l0 = m;
    }
    for l in l0..m {
        shear[b.k[l] as usize - base] = [b.s[0][l], b.s[1][l], b.s[2][l]];
    }
    (max_delta, max_excess)
}

/// max(start, value(0), …, value(n − 1)) with eight independent partial maxima (a vector max,
/// not a serial chain; max is exact, so the grouping does not change the result).
#[inline(always)]
fn lane_max<T: Copy + PartialOrd>(n: usize, start: T, value: impl Fn(usize) -> T) -> T {
    let mut part = [start; 8];
    for g in 0..n / 8 {
        for (q, p) in part.iter_mut().enumerate() {
            let x = value(8 * g + q);
            *p = if x > *p { x } else { *p };
        }
    }
    for l in n / 8 * 8..n {
        let x = value(l);
        part[0] = if x > part[0] { x } else { part[0] };
    }
    part.iter().fold(start, |a, &b| if b > a { b } else { a })
}

/// The contact law (`contact::law_force` of the law's style, in f32) over lanes 0..m, no
/// branches, from double-precision inputs: the overlap comes from d² − r² taken in double,
/// δ = (d² − r²)/(d + |r|), so it keeps ~1e-7 relative accuracy however small it is, and every
/// force, torque and history is within ~1.5e-6 of the double law (test `batch_kernel`).
/// Every array the loop reads or writes is single precision, so the compiler takes sixteen
/// lanes per AVX-512 vector (docs/BENCHMARKS.md). All kernel variants do the same IEEE
/// operations (no FMA), so they give the same bits. AUDIT also fills each lane's Coulomb excess.
#[inline(always)]
fn lanes<const FR: bool, const AUDIT: bool>(b: &mut Batch, law: &ContactLaw, d: f64, h: f64) {
    match law.style {
        ContactStyle::HertzMindlin => lanes_of::<HertzMindlin, FR, AUDIT>(b, law, d, h),
        ContactStyle::LinearSpringDashpot => lanes_of::<LinearSpringDashpot, FR, AUDIT>(b, law, d, h),
    }
}

#[inline(always)]
fn lanes_of<S: Style, const FR: bool, const AUDIT: bool>(b: &mut Batch, law: &ContactLaw, d: f64, h: f64) {
    // Whole vectors of 16: the lanes past b.m hold scratch (zeros or older pairs) whose results
    // nobody reads; a count of b.m would leave a scalar tail of lanes per batch.
    let m = ((b.m.min(CAP) + 15) & !15).min(CAP);
    let c = law.coeffs::<f32>();
    let (d1, h) = (d as f32, h as f32);
    for l in 0..m {
        let dist = b.r2[l].sqrt();
        let inv = 1.0 / dist;
        let n = [b.dx[0][l] * inv, b.dx[1][l] * inv, b.dx[2][l] * inv];
        let delta = b.gap2[l] / (d1 + dist);
        b.delta[l] = delta;
        let vr = [b.vrel[0][l], b.vrel[1][l], b.vrel[2][l]];
        let (ws, s0) = if FR {
            ([b.ws[0][l], b.ws[1][l], b.ws[2][l]], [b.s[0][l], b.s[1][l], b.s[2][l]])
        } else {
            ([0.0; 3], [0.0; 3])
        };
        let out = law_force::<S, f32, FR, AUDIT>(&c, delta, n, vr, ws, s0, h);
        for q in 0..3 {
            b.f[q][l] = out.f[q];
            if FR {
                b.c[q][l] = out.c[q];
                b.s[q][l] = out.s[q];
            }
        }
        if AUDIT {
            b.excess[l] = out.excess;
        }
    }
}
