//! Determinism and checkpoints: the same case and seed give bit-identical states (also across
//! thread counts: the passes use fixed blocks and fixed summation order), and a serde round trip
//! in the middle of a run continues exactly as the uninterrupted run.

use super::energy::random_gas;
use super::{test_case, with_damping};
use crate::dem::DemSystem;

fn busy_system() -> DemSystem {
    // Frictional, damped, gravity, lid: every code path, with list rebuilds and re-sorts.
    let case = with_damping(test_case(0.008, 0.008, true, 9.81, 1e-6), 0.05, 0.05, 0.3);
    let r = case.particles.diameter_m / 2.0;
    let (x, v) = random_gas(60, 0.004, 0.008, r, 0.6, 11);
    DemSystem::new(&case, x, v)
}

/// The system after `steps` steps, and how many steps had frictional contacts.
fn run_counting(threads: usize, steps: usize) -> (DemSystem, usize) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut s = busy_system();
        let mut frictional = 0;
        for _ in 0..steps {
            s.step();
            frictional += (s.max_coulomb_excess() > f64::NEG_INFINITY) as usize;
        }
        (s, frictional)
    })
}

fn run_in_pool(threads: usize, steps: usize) -> DemSystem {
    run_counting(threads, steps).0
}

fn same_state(a: &DemSystem, b: &DemSystem) -> bool {
    a.ids() == b.ids()
        && a.positions() == b.positions()
        && a.velocities() == b.velocities()
        && a.angular_velocities() == b.angular_velocities()
        && a.nl.shear == b.nl.shear
}

#[test]
fn same_seed_and_threads_give_identical_states() {
    let (a, frictional) = run_counting(2, 6000);
    let b = run_in_pool(2, 6000);
    assert!(frictional > 1000, "too few steps with frictional contacts ({frictional})");
    assert!(a.steps() == 6000 && a.ids() != (0..60).collect::<Vec<u32>>(), "no re-sort exercised");
    assert!(same_state(&a, &b));
    let c = run_in_pool(1, 6000);
    assert!(same_state(&a, &c), "1 and 2 threads differ");
}

#[test]
fn checkpoint_round_trip_continues_identically() {
    let full = run_in_pool(2, 6000);
    let half = run_in_pool(2, 3000);
    let json = serde_json::to_string(&half).unwrap();
    let mut restored: DemSystem = serde_json::from_str(&json).unwrap();
    assert_eq!(restored.steps(), 3000);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    pool.install(|| {
        for _ in 0..3000 {
            restored.step();
        }
    });
    assert_eq!(restored.ids(), full.ids());
    let close = |a: &[[f64; 3]], b: &[[f64; 3]], scale: f64| {
        a.iter().zip(b).all(|(p, q)| (0..3).all(|k| (p[k] - q[k]).abs() <= 1e-12 * scale))
    };
    assert!(close(restored.positions(), full.positions(), 0.01));
    assert!(close(restored.velocities(), full.velocities(), 1.0));
    assert!(close(restored.angular_velocities(), full.angular_velocities(), 1000.0));
}
