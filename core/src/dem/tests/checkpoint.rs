//! Determinism and checkpoints: the same case, seed and thread count give bit-identical states,
//! and a serde round trip in the middle of a run continues as the uninterrupted run.

use super::energy::random_gas;
use super::{test_case, with_damping};
use crate::dem::DemSystem;

pub(super) fn busy_system() -> DemSystem {
    // Frictional, damped, gravity, lid: every code path, with list rebuilds and re-sorts; more
    // than 512 particles so the pair pass really splits into chunks across the threads.
    let case = with_damping(test_case(0.012, 0.03, true, 9.81, 1e-6), 0.05, 0.05, 0.3);
    let r = case.particles.diameter_m / 2.0;
    let (x, v) = random_gas(600, 0.006, 0.03, r, 0.6, 11);
    let mut s = DemSystem::new(&case, x, v);
    s.set_audit(true); // the Coulomb diagnostic counts the frictional steps
    s
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

pub(super) fn same_state(a: &DemSystem, b: &DemSystem) -> bool {
    a.ids() == b.ids()
        && a.positions() == b.positions()
        && a.velocities() == b.velocities()
        && a.angular_velocities() == b.angular_velocities()
        && a.near.list.shear == b.near.list.shear
}

#[test]
fn same_seed_and_threads_give_identical_states() {
    let (a, frictional) = run_counting(2, 3000);
    let b = run_in_pool(2, 3000);
    assert!(frictional > 1000, "too few steps with frictional contacts ({frictional})");
    assert!(a.steps() == 3000 && a.ids() != (0..600).collect::<Vec<u32>>(), "no re-sort exercised");
    assert!(same_state(&a, &b));
}

#[test]
fn checkpoint_round_trip_continues_identically() {
    let full = run_in_pool(2, 3000);
    let half = run_in_pool(2, 1500);
    // bincode stores f64 bit-exactly (serde_json's default parser may round the last bit).
    let bytes = bincode::serialize(&half).unwrap();
    let mut restored: DemSystem = bincode::deserialize(&bytes).unwrap();
    assert_eq!(restored.steps(), 1500);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    pool.install(|| {
        for _ in 0..1500 {
            restored.step();
        }
    });
    assert!(same_state(&restored, &full), "restored run differs from the uninterrupted one");
    // A JSON round trip keeps the state to round-off.
    let json: DemSystem = serde_json::from_str(&serde_json::to_string(&half).unwrap()).unwrap();
    assert!(json.positions().iter().zip(half.positions()).all(|(p, q)| (0..3).all(|k| (p[k] - q[k]).abs() <= 1e-15)));
}

#[test]
fn the_coulomb_audit_leaves_the_trajectory_unchanged() {
    let audited = run_in_pool(2, 1500);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let plain = pool.install(|| {
        let mut s = busy_system();
        s.set_audit(false);
        for _ in 0..1500 {
            s.step();
        }
        s
    });
    assert!(same_state(&audited, &plain), "the audit changed the trajectory");
}

/// Checkpoints of earlier builds still read: their near list carried each entry's Verlet-list
/// entry (`src`, now dropped) and their history was double precision (now read into single);
/// what this build writes reads back unchanged.
#[test]
fn the_near_list_and_history_of_earlier_checkpoints_still_read() {
    use crate::dem::forces::Past;
    use crate::dem::near_list::NearList;
    use crate::dem::neighbors::NeighborList;
    #[derive(serde::Serialize)]
    struct OldNear {
        list: NeighborList,
        src: Vec<u32>,
    }
    #[derive(serde::Serialize)]
    struct OldPast {
        v: [Vec<[f64; 3]>; 2],
        a: [Vec<[f64; 3]>; 2],
        alpha: [Vec<[f64; 3]>; 2],
    }
    let list =
        NeighborList { offsets: vec![0, 2, 2], nbr: vec![1, 2], shear: vec![[0.5; 3], [0.0; 3]], touch: vec![1, 0] };
    let bytes = bincode::serialize(&OldNear { list: list.clone(), src: vec![0, 3] }).unwrap();
    let near: NearList = bincode::deserialize(&bytes).expect("an old near list reads");
    assert_eq!((&near.list.offsets, &near.list.nbr, &near.list.touch), (&list.offsets, &list.nbr, &list.touch));
    assert_eq!(near.list.shear, list.shear);
    let again: NearList = bincode::deserialize(&bincode::serialize(&near).unwrap()).unwrap();
    assert_eq!((again.list.nbr, again.list.shear), (list.nbr, list.shear));

    let g = 0.1f64; // not a binary fraction: the single-precision value is the nearest to it
    let slot = || [vec![[g, -2.0 * g, 9.81]; 3], vec![[1.0, 0.0, -0.5]; 3]];
    let bytes = bincode::serialize(&OldPast { v: slot(), a: slot(), alpha: slot() }).unwrap();
    let past: Past = bincode::deserialize(&bytes).expect("an old history reads");
    assert_eq!(past.a[0][2], [0.1f32, -0.2, 9.81]);
    assert_eq!(past.alpha[1][0], [1.0f32, 0.0, -0.5]);
    let again: Past = bincode::deserialize(&bincode::serialize(&past).unwrap()).unwrap();
    assert_eq!(again, past, "f32 -> f64 -> f32 keeps every bit");
}
