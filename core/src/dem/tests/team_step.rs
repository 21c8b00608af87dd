//! The team step (one broadcast per step, threads sharing chunks and blocks) against the two
//! parallel loops it replaces: the same bits. Systems stepped at once on one pool (nested in a
//! parallel loop, so one holds the team and the other takes the plain loops) neither deadlock
//! nor change their results; on pools with their own team lock, both run as teams. A panic in
//! one thread's chunk reaches the caller instead of leaving the other thread waiting for it.

use super::checkpoint::{busy_system, same_state};
use crate::dem::team_step::PANIC_IN_CHUNK;
use crate::dem::DemSystem;
use crate::team::{solver_pool, TeamLock};
use rayon::prelude::*;
use std::sync::atomic::Ordering;

const STEPS: usize = 1500;

fn take_team_lock() -> TeamLock {
    loop {
        match TeamLock::try_take() {
            Some(l) => break l,
            None => std::thread::yield_now(),
        }
    }
}

/// The busy system after STEPS plain `step()` calls (team or loops, whichever it gets).
fn run_busy() -> DemSystem {
    let mut s = busy_system();
    for _ in 0..STEPS {
        s.step();
    }
    s
}

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap()
}

#[test]
fn team_step_equals_the_plain_passes() {
    pool().install(|| {
        let mut plain = busy_system();
        for _ in 0..STEPS {
            plain.step_with(None);
        }
        // The team lock, held for the whole run (other tests step with plain loops meanwhile).
        let lock = take_team_lock();
        let mut team = busy_system();
        for _ in 0..STEPS {
            team.step_with(Some(&lock));
        }
        drop(lock);
        assert!(plain.list_builds().0 > 1 && plain.list_builds().1 > 1, "no list rebuild or refresh exercised");
        // Every step but the first (Heun) is a multistep one.
        assert!(plain.team_steps() == 0 && team.team_steps() == STEPS as u64 - 1, "team steps {}", team.team_steps());
        assert!(same_state(&plain, &team));
    });
}

#[test]
fn systems_stepped_in_a_parallel_loop_match_one_stepped_alone() {
    let (nested, alone): (Vec<DemSystem>, DemSystem) =
        pool().install(|| ((0..2).into_par_iter().map(|_| run_busy()).collect(), run_busy()));
    assert!(nested.iter().all(|s| same_state(s, &alone)));
}

#[test]
fn a_panic_in_a_chunk_reaches_the_caller_without_a_hang() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let outcome = pool().install(|| {
            let mut s = busy_system();
            // The lock keeps every other test's steps off the team (and off the injected panic).
            let lock = take_team_lock();
            for _ in 0..5 {
                s.step_with(Some(&lock)); // past the Heun start
            }
            PANIC_IN_CHUNK.store(1, Ordering::Relaxed);
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| s.step_with(Some(&lock))));
            PANIC_IN_CHUNK.store(0, Ordering::Relaxed);
            drop(lock);
            r.map_err(|e| e.downcast_ref::<String>().cloned().unwrap_or_default())
        });
        tx.send(outcome).unwrap();
    });
    let outcome = rx.recv_timeout(std::time::Duration::from_secs(120)).expect("the team hung after a chunk panicked");
    let msg = outcome.expect_err("the injected panic did not reach the caller");
    assert!(msg.contains("injected panic in chunk 0"), "{msg}");
}

#[test]
fn systems_on_pools_with_their_own_team_lock_both_run_as_teams() {
    let alone = pool().install(run_busy);
    let pools: Vec<rayon::ThreadPool> = (0..2).map(|_| solver_pool().num_threads(2).build().unwrap()).collect();
    let both: Vec<DemSystem> = std::thread::scope(|sc| {
        let hs: Vec<_> = pools.iter().map(|p| sc.spawn(move || p.install(run_busy))).collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for s in &both {
        assert_eq!(s.team_steps(), STEPS as u64 - 1, "a system on its own pool did not get its team");
        assert!(same_state(s, &alone));
    }
}
