//! The chunk buffers' single-precision sums (`pair_scatter`): against the exact sums of the same
//! pair forces, within the rounding bound of sequential addition, and the vector scatter bit for
//! bit the portable one.

use crate::dem::batch::{Batch, CAP};
use crate::dem::kernel::Isa;
use crate::dem::pair_scatter::{scatter, PairSum};
use rand::{Rng, SeedableRng};

/// Chunk sums, exact sums, Σ|term| per value, terms per particle.
type Scattered = (Vec<PairSum>, Vec<[f64; 6]>, Vec<[f64; 6]>, Vec<usize>);

/// Random batches (every count 1..=CAP, particles drawn from a small window so rows repeat
/// within a batch), scattered into `acc` by `run`; returns the exact sums and, per value,
/// Σ|term| and the number of terms.
fn scatter_random(run: impl Fn(&Batch, &mut [PairSum])) -> Scattered {
    let n = 40;
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let (mut acc, mut exact, mut abs, mut terms) =
        (vec![PairSum::default(); n], vec![[0.0; 6]; n], vec![[0.0; 6]; n], vec![0; n]);
    let mut b = Batch::new();
    for m in (1..=CAP).chain(1..=CAP) {
        for l in 0..m {
            let i = rng.gen_range(0..n - 1);
            let j = rng.gen_range(i + 1..n);
            (b.i[l], b.j[l]) = (i as u32, j as u32);
            for q in 0..3 {
                // Magnitudes over six decades, as forces in a bed under load.
                b.f[q][l] = (rng.gen::<f32>() - 0.5) * 10f32.powi(rng.gen_range(-3..3));
                b.c[q][l] = (rng.gen::<f32>() - 0.5) * 10f32.powi(rng.gen_range(-3..3));
            }
            let on = [b.f[0][l], b.f[1][l], b.f[2][l], b.c[0][l], b.c[1][l], b.c[2][l]].map(f64::from);
            for (p, sign) in [(i, 1.0), (j, -1.0)] {
                for q in 0..6 {
                    let t = if q < 3 { sign * on[q] } else { on[q] };
                    exact[p][q] += t; // in double: within ~1e-16 of exact, far below the bound
                    abs[p][q] += t.abs();
                }
                terms[p] += 1;
            }
        }
        b.m = m;
        run(&b, &mut acc);
    }
    (acc, exact, abs, terms)
}

#[test]
fn chunk_sums_within_the_rounding_bound_of_the_exact_sums() {
    let (acc, exact, abs, terms) = scatter_random(|b, acc| scatter::<true, false>(Isa::PORTABLE, b, acc));
    let u = f64::from(f32::EPSILON) / 2.0;
    let mut worst: f64 = 0.0;
    for p in 0..acc.len() {
        assert!(terms[p] > 20, "particle {p} summed only {} terms", terms[p]);
        for q in 0..6 {
            // Sequential addition of k terms: |fl(Σ) − Σ| ≤ (k − 1) u Σ|t| (to first order).
            let bound = (terms[p] - 1) as f64 * u * abs[p][q] * (1.0 + 1e-6);
            let err = (f64::from(acc[p].0[q]) - exact[p][q]).abs();
            assert!(err <= bound, "particle {p} value {q}: error {err:e} over the bound {bound:e}");
            worst = worst.max(err / abs[p][q]);
        }
        assert_eq!(acc[p].0[6..], [0.0, 0.0], "padding stays zero");
    }
    // The bound is not loose enough to pass anything: the sums do carry rounding.
    assert!(worst > 0.0 && worst < 1e-5, "largest error relative to Σ|t|: {worst:e}");
}

#[test]
fn vector_scatter_equals_the_portable_one() {
    let Some(isa) = Isa::avx512() else {
        return super::skip("vector_scatter_equals_the_portable_one", "no AVX-512");
    };
    let bits = |a: &[PairSum]| a.iter().flat_map(|r| r.0).map(f32::to_bits).collect::<Vec<_>>();
    let portable = scatter_random(|b, acc| scatter::<true, false>(Isa::PORTABLE, b, acc)).0;
    let vector = scatter_random(|b, acc| scatter::<true, true>(isa, b, acc)).0;
    assert!(bits(&portable) == bits(&vector), "vector and portable scatter differ");
    let portable = scatter_random(|b, acc| scatter::<false, false>(Isa::PORTABLE, b, acc)).0;
    let vector = scatter_random(|b, acc| scatter::<false, true>(isa, b, acc)).0;
    assert!(bits(&portable) == bits(&vector), "vector and portable scatter differ without friction");
    assert!(portable.iter().all(|r| r.0[3..] == [0.0; 5]), "no torque sums without friction");
}
