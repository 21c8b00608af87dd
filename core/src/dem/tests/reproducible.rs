//! `dem.reproducible`: the same bits for 1, 2 and 3 threads (a fixed work split), where the
//! default split, which follows the thread count, does give different bits.

use super::checkpoint::same_state;
use super::{test_case, with_damping};
use crate::dem::DemSystem;
use rand::{Rng, SeedableRng};

fn run(threads: usize, reproducible: bool) -> DemSystem {
    // Frictional, damped, under gravity, with a lid; a jittered lattice at contact (about half
    // the neighbours overlap), ~2500 particles so that 16 chunks really split.
    let mut case = with_damping(test_case(0.02, 0.03, true, 9.81, 1e-6), 0.05, 0.05, 0.3);
    case.dem.reproducible = reproducible;
    let d = case.particles.diameter_m;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let mut x = Vec::new();
    for iz in 0..16 {
        for iy in -8..=8 {
            for ix in -8..=8 {
                let p = [ix as f64 * d, iy as f64 * d, d + iz as f64 * d];
                if (p[0] * p[0] + p[1] * p[1]).sqrt() < 0.0098 - d {
                    let mut j = || 0.03 * d * (rng.gen::<f64>() - 0.5);
                    x.push([p[0] + j(), p[1] + j(), p[2] + j()]);
                }
            }
        }
    }
    let v = (0..x.len()).map(|_| [0.05 * rng.gen::<f64>(), 0.0, -0.02 * rng.gen::<f64>()]).collect();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut s = DemSystem::new(&case, x, v);
        for _ in 0..300 {
            s.step();
        }
        s
    })
}

#[test]
fn reproducible_runs_give_the_same_bits_for_any_thread_count() {
    let one = run(1, true);
    assert!(one.touching_pairs().unwrap() > 100, "too few contacts to matter");
    for threads in [2, 3] {
        assert!(same_state(&run(threads, true), &one), "reproducible run on {threads} threads differs from 1 thread");
    }
    // The check can fail: the default split (two chunks per thread) changes the rounding.
    assert!(!same_state(&run(2, false), &run(1, false)), "default runs on 1 and 2 threads agree bit for bit");
}
