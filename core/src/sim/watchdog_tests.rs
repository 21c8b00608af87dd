//! Tests of the watchdog: each stop names what, where (particle or cell and position), when (time
//! and DEM step) and a parameter to change; no snapshot with a NaN is ever handed out.

use super::*;
use crate::case::{Bed, ExplicitBed, Field};
use crate::sim::{Simulation, Snapshot};

/// DEM only, 44 × 120 mm, d = 1.2 mm, the given particles and velocities (not validated).
fn case(pos: Vec<[f64; 3]>, vel: Vec<[f64; 3]>) -> Case {
    let mut c: Case = serde_json::from_str(
        r#"{"column":{"diameter_m":0.044,"height_m":0.12},"particles":{},"bed":{"generated":{}}}"#,
    )
    .unwrap();
    c.bed = Bed::Explicit(ExplicitBed { positions_m: pos, velocities_m_s: Some(vel) });
    c.end_time_s = 1e-3;
    c.outputs.snapshot_interval_s = 1e-4;
    c.outputs.fields = vec![Field::Voidage, Field::Particles];
    c
}

fn dem_of(c: &Case) -> DemSystem {
    let Bed::Explicit(e) = &c.bed else { unreachable!() };
    DemSystem::new(c, e.positions_m.clone(), e.velocities_m_s.clone().unwrap())
}

fn stop_message(r: Result<(), SimError>) -> String {
    match r {
        Err(SimError::Unstable(m)) => m,
        other => panic!("expected a watchdog stop, got {other:?}"),
    }
}

#[test]
fn a_particle_beyond_the_speed_bound_is_named_with_its_place_and_step() {
    let c = case(vec![[0.0, 0.0, 0.05], [0.01, 0.0, 0.05]], vec![[0.0; 3], [0.0, 0.0, 3.0]]);
    let dem = dem_of(&c);
    let lim = Limits::of(&c);
    // 10× the largest expected impact speed (3 m/s given) is 30 m/s: the bed passes.
    assert!((lim.max_speed - 30.0).abs() < 1e-9, "{}", lim.max_speed);
    check_dem(&dem, &lim, DEM_CHECK_EVERY, 0.0).unwrap();
    let tight = Limits { max_speed: 1.0, ..lim };
    // between the passes over the particles nothing is looked at but the overlap
    check_dem(&dem, &tight, DEM_CHECK_EVERY + 1, 0.0).unwrap();
    let m = stop_message(check_dem(&dem, &tight, 2 * DEM_CHECK_EVERY, 2.5e-4));
    for want in [
        "particle 1 at (1.0000e-2, 0.0000e0, 5.0000e-2) m",
        "moves at 3.000e0 m/s",
        "DEM step 200",
        "t = 2.500000e-4 s",
        "dem.time_step_s",
    ] {
        assert!(m.contains(want), "{want:?} not in {m}");
    }
}

#[test]
fn a_particle_outside_the_tube_has_left_through_the_wall() {
    let c = case(vec![[0.0, 0.0, 0.05], [0.0, 0.0235, 0.05]], vec![[0.0; 3]; 2]);
    let m = stop_message(check_dem(&dem_of(&c), &Limits::of(&c), DEM_CHECK_EVERY, 0.0));
    assert!(m.contains("particle 1") && m.contains("left the column through the tube wall"), "{m}");
    let c = case(vec![[0.0, 0.0, -0.001]], vec![[0.0; 3]]);
    let m = stop_message(check_dem(&dem_of(&c), &Limits::of(&c), DEM_CHECK_EVERY, 0.0));
    assert!(m.contains("through the distributor plate"), "{m}");
}

#[test]
fn a_non_finite_velocity_is_named() {
    let c = case(vec![[0.0, 0.0, 0.05], [0.01, 0.0, 0.05]], vec![[0.0; 3], [f64::NAN, 0.0, 0.0]]);
    let m = stop_message(check_dem(&dem_of(&c), &Limits::of(&c), DEM_CHECK_EVERY, 0.0));
    assert!(m.contains("particle 1") && m.contains("non-finite velocity"), "{m}");
}

#[test]
fn a_deep_overlap_stops_the_run_at_its_first_step_naming_the_particle() {
    // Centres 0.6 d apart: the first step's overlap is 40% of d.
    let mut c = case(vec![[0.0, 0.0, 0.05], [0.00072, 0.0, 0.05]], vec![[0.0; 3]; 2]);
    c.gravity_m_s2 = 0.0;
    let mut sim = Simulation::new(c, None).unwrap();
    let mut snaps: Vec<Snapshot> = Vec::new();
    let m = match sim.run(&mut snaps) {
        Err(SimError::Unstable(m)) => m,
        other => panic!("expected a stop, got {other:?}"),
    };
    assert!(m.contains("particle overlap") && m.contains("DEM step 1)"), "{m}");
    assert!(m.contains("at particle 0 at (") || m.contains("at particle 1 at ("), "{m}");
    assert!(m.contains("particles.youngs_modulus_pa"), "{m}");
    assert_eq!(snaps.len(), 1, "the initial snapshot only");
}

#[test]
fn no_snapshot_holding_a_nan_is_ever_handed_out() {
    let c = case(vec![[0.0, 0.0, 0.05], [0.01, 0.0, 0.05]], vec![[0.0; 3], [0.0, f64::INFINITY, 0.0]]);
    let mut sim = Simulation::new(c, None).unwrap();
    match sim.advance(10) {
        Err(SimError::Unstable(m)) => {
            assert!(m.contains("snapshot 0") && m.contains("velocity") && m.contains("particle 1"), "{m}")
        }
        other => panic!("expected the snapshot to be refused, got {other:?}"),
    }
}

#[test]
fn collapsed_and_non_finite_gas_is_named_by_cell() {
    let mut c = case(vec![[0.0, 0.0, 0.05]], vec![[0.0; 3]]);
    c.gas = Some(Default::default());
    let grid = crate::sim::fluid_grid(&c);
    let mut gas = GasSolver::new(&c, grid);
    let lim = Limits::of(&c);
    check_gas(&gas, &lim, 1e-7, 0.0, 0).unwrap();
    gas.set_cell(40, 1e-3, [0.0; 3]);
    let m = stop_message(check_gas(&gas, &lim, 1e-7, 0.1, 7));
    assert!(m.contains("collapsed") && m.contains("cell 40 (i=") && m.contains("DEM step 7"), "{m}");
    gas.set_cell(41, f64::NAN, [0.0; 3]);
    let m = stop_message(check_gas(&gas, &lim, 1e-7, 0.1, 7));
    assert!(m.contains("NaN") && m.contains("gas.time_step_s"), "{m}");
}

#[test]
fn a_gas_mass_budget_that_does_not_close_stops_the_run() {
    let mut c = case(vec![[0.0, 0.0, 0.05]], vec![[0.0; 3]]);
    c.gas = Some(Default::default());
    let grid = crate::sim::fluid_grid(&c);
    let mut gas = GasSolver::new(&c, grid);
    let lim = Limits::of(&c);
    let dt = 0.5 * gas.stable_dt();
    for _ in 0..50 {
        gas.step(dt);
    }
    check_gas(&gas, &lim, dt, 50.0 * dt, 50).unwrap();
    // A budget missing 1e-8 of the mass held (a flux that would not conserve mass) is stopped.
    let mut b = gas.mass_budget();
    b.net += 1e-8 * gas.mass_balance().held;
    gas.set_mass_budget(b);
    let m = stop_message(check_gas(&gas, &lim, dt, 50.0 * dt, 50));
    assert!(m.contains("gas mass balance off by 1.000e-8") && m.contains("DEM step 50"), "{m}");
}
