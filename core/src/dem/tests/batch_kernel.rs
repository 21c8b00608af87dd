//! The batched pair kernel (fast path, single-precision lanes) evaluates the scalar contact law
//! of `contact::contact_force` (PHYSICS.md 2.2-2.3, double precision): the same forces, torques
//! and histories to ~1e-7 relative; its vector and portable variants agree bit for bit.

use super::{test_case, with_damping};
use crate::dem::batch::{Batch, Entry, PairInputs, CAP};
use crate::dem::contact::contact_force;
use crate::dem::kernel::{Isa, Kernel};
use crate::dem::pair_batch::evaluate;
use crate::dem::pair_scatter::PairSum;
use crate::dem::DemParams;
use rand::{Rng, SeedableRng};

#[test]
fn batched_pair_kernel_matches_the_double_precision_contact_law() {
    // 40 pairs fill five vectors of 8; 37 leave three lanes of the last one to scratch.
    batch_against_scalar_law(40);
    batch_against_scalar_law(37);
}

/// Lanes 0..n hold touching pairs; the lanes past n hold scratch (a zero pair, NaN, a huge
/// overlap, all aimed at history slot 0), which the kernel computes with the rest but must
/// never let into the forces, the histories or the returned maxima.
fn batch_against_scalar_law(n: usize) {
    let case = with_damping(test_case(0.02, 0.02, false, 9.81, 1e-6), 0.1, 0.05, 0.3);
    let p = DemParams::new(&case);
    let r = p.radius;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    let mut u = |s: f64| (rng.gen::<f64>() * 2.0 - 1.0) * s;
    // Particle 2l and 2l+1 touch with a random overlap and random motion; random histories.
    let mut x = Vec::new();
    for l in 0..n {
        let dir = [u(1.0), u(1.0), u(1.0)];
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        // Overlaps up to 1% of d, and every third pair up to 1e-6 d (where δ = d − |r| would
        // lose its digits to cancellation in single precision).
        let dist = 2.0 * r * (1.0 - [0.01, 0.01, 1e-6][l % 3] * rng_frac(l));
        x.push([0.0, 0.0, 0.0]);
        x.push([dir[0] / len * dist, dir[1] / len * dist, dir[2] / len * dist]);
    }
    let v: Vec<[f64; 3]> = (0..2 * n).map(|_| [u(1.0), u(1.0), u(1.0)]).collect();
    let w: Vec<[f64; 3]> = (0..2 * n).map(|_| [u(500.0), u(500.0), u(500.0)]).collect();
    let shear0: Vec<[f32; 3]> = (0..n).map(|_| [u(1e-6) as f32, u(1e-6) as f32, u(1e-6) as f32]).collect();
    // Lane l holds the pair (2l, 2l + 1).
    let filled = || {
        let mut b = Batch::new();
        for l in 0..n {
            let (i, j) = (2 * l, 2 * l + 1);
            let dx = [x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]];
            b.set(l, Entry { k: l, i, j }, dx, dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2], 4.0 * r * r);
        }
        for l in n..CAP {
            let junk = [[0.0; 3], [f64::NAN; 3], [1e-9, 0.0, 0.0]][l % 3];
            b.set(l, Entry { k: 0, i: 0, j: 1 }, junk, junk[0] * junk[0], 4.0 * r * r);
        }
        b.m = n;
        b
    };
    let inp = PairInputs { law: &p.pair, audit: true, r, h: p.dt, v: &v, w: &w };
    let mut batch = filled();
    let mut vector = None;
    if let Some(isa) = Isa::avx512() {
        let mut b2 = filled();
        let mut shear = shear0.clone();
        let maxima = evaluate::<true, true>(isa, &mut b2, &inp, &mut shear, 0);
        vector = Some((b2, shear, maxima));
    } else {
        super::skip("batched_pair_kernel_matches_the_double_precision_contact_law (AVX-512 part)", "no AVX-512");
    }
    let mut shear = shear0.clone();
    let maxima = evaluate::<true, false>(Isa::PORTABLE, &mut batch, &inp, &mut shear, 0);
    if let Some((b2, s2, m2)) = &vector {
        // the AVX-512 gather (`pair_simd::gather8`) gives the same lanes as the portable one
        let valid = |a: &[[f32; CAP]; 3]| a.map(|q| q[..n].to_vec());
        assert_eq!(valid(&b2.f), valid(&batch.f), "vector gather: forces");
        assert_eq!(valid(&b2.c), valid(&batch.c), "vector gather: torques");
        assert_eq!(s2, &shear, "vector gather: histories");
        assert_eq!(m2, &maxima, "vector gather: maxima");
    }
    let (mut slid, mut max_delta, mut max_excess) = (0, 0.0f64, f64::NEG_INFINITY);
    let mut worst = [0.0f64; 3];
    for l in 0..n {
        let (i, j) = (2 * l, 2 * l + 1);
        let dx = [x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]];
        let dist = (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]).sqrt();
        let inv = 1.0 / dist;
        let nrm = [dx[0] * inv, dx[1] * inv, dx[2] * inv];
        let vrel = [v[i][0] - v[j][0], v[i][1] - v[j][1], v[i][2] - v[j][2]];
        let ws = [r * (w[i][0] + w[j][0]), r * (w[i][1] + w[j][1]), r * (w[i][2] + w[j][2])];
        let mut s = shear0[l].map(f64::from);
        let cf = contact_force::<true>(&p.pair, 2.0 * r - dist, nrm, vrel, ws, &mut s, p.dt);
        // Relative to the vector's length (a component may be near zero).
        let err = |a: [f64; 3], b: [f64; 3]| {
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt()
        };
        worst[0] = worst[0].max(err([batch.f[0][l], batch.f[1][l], batch.f[2][l]].map(f64::from), cf.f));
        worst[1] = worst[1].max(err([batch.c[0][l], batch.c[1][l], batch.c[2][l]].map(f64::from), cf.c));
        worst[2] = worst[2].max(err(shear[l].map(f64::from), s));
        slid += (cf.excess > -1e-9) as usize;
        max_delta = max_delta.max(2.0 * r - dist);
        max_excess = max_excess.max(cf.excess);
    }
    // Single precision carries ~6e-8 per operation. Seen: ≤ 4e-7 for the larger overlaps, ≤ 1.5e-6
    // with the tiny ones, whose elastic and damping terms nearly cancel (the error stays ~1e-7
    // of the terms).
    for (what, e) in ["forces", "torques", "histories"].iter().zip(worst) {
        assert!(e < 5e-6, "{what}: largest relative error {e:.2e} against the double-precision law");
    }
    assert!((maxima.0 - max_delta).abs() < 1e-6 * max_delta, "max overlap {} against {max_delta}", maxima.0);
    assert!((maxima.1 - max_excess).abs() < 1e-5, "max Coulomb excess {} against {max_excess}", maxima.1);
    assert!(slid > 0 && slid < n, "both sticking and sliding pairs exercised ({slid} of {n} slid)");
}

fn rng_frac(l: usize) -> f64 {
    ((l * 37 % 41) as f64 + 0.5) / 41.0
}

/// Every kernel path this CPU has (`Kernel::available`: the AVX-512 scan and gather of
/// `pair_simd`, the AVX2 build) gives the portable pair pass's forces, torques, contact flags and
/// histories bit for bit, on a compressed lattice with random motion (both sticking and sliding
/// contacts, histories live and fresh). A path the CPU lacks is reported as skipped.
#[test]
fn vector_pair_pass_equals_the_portable_one() {
    use crate::dem::forces::{pair_pass, Scratch};
    let case = with_damping(test_case(0.02, 0.03, false, 9.81, 1e-6), 0.1, 0.05, 0.3);
    let d = case.particles.diameter_m;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let mut x = Vec::new();
    let a = d; // lattice at contact, jittered: about half the lattice neighbours overlap
    for iz in 0..12 {
        for iy in -7..=7 {
            for ix in -7..=7 {
                let p = [ix as f64 * a, iy as f64 * a, d + iz as f64 * a];
                if (p[0] * p[0] + p[1] * p[1]).sqrt() < 0.0095 - d {
                    let mut j = || 0.03 * d * (rng.gen::<f64>() - 0.5);
                    x.push([p[0] + j(), p[1] + j(), p[2] + j()]);
                }
            }
        }
    }
    let v: Vec<[f64; 3]> = (0..x.len()).map(|_| [0.05 * rng.gen::<f64>(), 0.0, -0.02 * rng.gen::<f64>()]).collect();
    let mut sys = crate::dem::DemSystem::new(&case, x, v);
    for s in sys.w.iter_mut() {
        *s = [300.0 * rng.gen::<f64>(), -200.0 * rng.gen::<f64>(), 100.0];
    }
    for _ in 0..5 {
        sys.step(); // live histories
    }
    // Stale histories behind flags that say "not live" must be ignored: random both.
    for (s, t) in sys.near.list.shear.iter_mut().zip(sys.near.list.touch.iter_mut()) {
        *s = [1e-6 * rng.gen::<f32>(), -1e-6 * rng.gen::<f32>(), 1e-7];
        *t = rng.gen::<bool>() as u8;
    }
    let run = |kernel: Kernel, audit: bool| {
        let mut p = sys.p.clone();
        p.audit = audit;
        let mut nl = sys.near.list.clone();
        let mut sc = Scratch::plan(&nl, sys.x.len(), 3);
        let st = pair_pass::<true>(&p, (&sys.x, &sys.v, &sys.w), &mut nl, &mut sc, kernel);
        (st.overlap, st.coulomb_excess, sc.acc, nl.touch, nl.shear)
    };
    let portable = run(Kernel::Portable, true);
    let touching = portable.3.iter().filter(|&&t| t == 1).count();
    assert!(touching > 1000 && touching < portable.3.len(), "{touching} of {} entries touch", portable.3.len());
    assert!(portable.1 > -1e-6, "some contacts slide (Coulomb excess {})", portable.1);
    let first_diff = |a: Vec<u64>, b: Vec<u64>| a.iter().zip(&b).position(|(x, y)| x != y);
    let flags = |t: &[u8]| t.iter().map(|&f| f as u64).collect::<Vec<_>>();
    let bits = |a: &[PairSum]| a.iter().flat_map(|r| r.0).map(|f| f.to_bits() as u64).collect::<Vec<_>>();
    let bits3 = |a: &[[f32; 3]]| a.iter().flatten().map(|f| f.to_bits() as u64).collect::<Vec<_>>();
    for kernel in Kernel::ALL {
        if !kernel.is_available() {
            super::skip(&format!("vector_pair_pass_equals_the_portable_one ({kernel})"), "the CPU lacks it");
            continue;
        }
        for audit in [true, false] {
            let got = run(kernel, audit);
            let what = format!("{kernel}, audit {audit}");
            assert_eq!(portable.0.to_bits(), got.0.to_bits(), "largest overlap ({what})");
            if audit {
                assert_eq!(portable.1.to_bits(), got.1.to_bits(), "largest Coulomb excess ({what})");
            } else {
                // Without the audit the pair pass skips the Coulomb diagnostic and nothing else.
                assert_eq!(got.1, f64::NEG_INFINITY, "no diagnostic without the audit ({what})");
            }
            assert_eq!(first_diff(flags(&portable.3), flags(&got.3)), None, "contact flags ({what})");
            assert_eq!(
                first_diff(bits(&portable.2), bits(&got.2)),
                None,
                "forces and torques, first difference ({what})"
            );
            assert_eq!(first_diff(bits3(&portable.4), bits3(&got.4)), None, "histories, first difference ({what})");
        }
    }
}
