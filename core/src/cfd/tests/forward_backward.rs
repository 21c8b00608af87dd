//! The forward–backward gas step (forward_backward.rs): its stable step against the real edge, a
//! bed's steady pressure drop against the analytic momentum balance, the same bits on one thread
//! and as a team, and the mass budget closed to round-off.

use super::mass_budget::{fed_bed, run};
use super::support::case_with;
use super::team::{state_bits, stirred_bed};
use crate::case::Gas;
use crate::cfd::{GasSolver, Outlet, TimeScheme};
use crate::grid::CylGrid;
use crate::team::solver_pool;
use std::sync::atomic::Ordering;

/// The 22-mm column of validation.rs with a bed-like voidage 0.45 and a downward interaction force
/// of 500 N/m³ on the gas in its lowest 30 mm.
fn bed_column(scheme: TimeScheme) -> GasSolver {
    let gas = Gas { superficial_velocity_m_s: 0.6, ramp_time_s: 0.0, time_scheme: scheme, ..Gas::default() };
    let case = case_with(gas, 9.81, 0.022, 0.12);
    let mut s = GasSolver::new(&case, CylGrid::new(0.022, 0.12, 0.0044, case.grid_dz_m(), 3));
    let n = s.grid().num_cells();
    let eps: Vec<f64> = (0..n).map(|c| if s.grid().centre_xyz(c)[2] < BED_TOP { 0.45 } else { 1.0 }).collect();
    s.set_initial_voidage(&eps);
    for (c, f) in s.interaction_force_mut().iter_mut().enumerate() {
        if eps[c] < 1.0 {
            *f = [0.0, 0.0, -500.0];
        }
    }
    s
}

const BED_TOP: f64 = 0.03;

/// Bounded for 6,000 steps at `factor` × the estimated limit (without the CFL factor)?
fn bounded_at(factor: f64) -> bool {
    let mut s = bed_column(TimeScheme::ForwardBackward);
    let dt = factor * s.stable_dt() / s.params().cfl_factor;
    (0..6000).all(|_| {
        s.step(dt);
        s.check_finite().is_ok()
    })
}

/// The estimate (ωΔt ≤ 1.5 for the acoustic part, stability.rs) brackets the real edge as AB3's
/// does: bounded at the limit, blown up at 1.35× it; and the step is 2.07× AB3's.
#[test]
fn the_forward_backward_stable_step_brackets_the_real_limit_at_twice_ab3s() {
    assert!(bounded_at(1.0), "unstable at the estimated limit");
    assert!(!bounded_at(1.35), "still bounded at 1.35× the estimated limit");
    let (fb, ab3) = (bed_column(TimeScheme::ForwardBackward).stable_dt(), bed_column(TimeScheme::Ab3).stable_dt());
    assert!(fb / ab3 > 2.0, "forward-backward step {fb:e} s, AB3 {ab3:e} s");
}

/// Steady state of the bed column: ε dp/dz = I_z − ερg, so across the bed's layers the drop is
/// (500/0.45 + ρg)·Δz, the same fixed point for either scheme.
#[test]
fn stepped_forward_backward_a_bed_holds_its_analytic_pressure_drop() {
    let mut s = bed_column(TimeScheme::ForwardBackward);
    let dt = s.stable_dt();
    while s.time() < 0.08 {
        s.step(dt);
    }
    let (per, dz) = (s.grid().cells_per_layer(), s.grid().dz);
    let p = s.pressure();
    let layer = |k: usize| p[k * per..(k + 1) * per].iter().sum::<f64>() / per as f64;
    // Layers 1 and 5 lie inside the 30-mm bed (dz = 2.2 mm), away from its ends.
    let (k1, k2) = (1, 5);
    assert!((k2 as f64 + 1.0) * dz < BED_TOP);
    let rho = s.density(k1 * per);
    let want = (500.0 / 0.45 + rho * 9.81) * (k2 - k1) as f64 * dz;
    let got = layer(k1) - layer(k2);
    eprintln!("bed drop {got:.4} Pa, analytic {want:.4} Pa");
    assert!((got / want - 1.0).abs() < 1e-3, "drop {got} Pa against {want} Pa");
}

#[test]
fn stepped_forward_backward_a_team_of_threads_steps_the_same_bits_as_one_thread() {
    for outlet in [Outlet::Characteristic, Outlet::Wall] {
        let mut serial = stirred_bed(outlet);
        serial.set_time_scheme(TimeScheme::ForwardBackward);
        serial.set_parallel(false);
        let dt = 0.8 * serial.stable_dt();
        for _ in 0..120 {
            serial.step(dt);
        }
        let pool = solver_pool().num_threads(2).build().unwrap();
        let mut team = stirred_bed(outlet);
        team.set_time_scheme(TimeScheme::ForwardBackward);
        team.set_parallel(true);
        let before = super::super::team_step::TEAM_STEPS.load(Ordering::Relaxed);
        pool.install(|| (0..120).for_each(|_| team.step(dt)));
        let ran = super::super::team_step::TEAM_STEPS.load(Ordering::Relaxed) - before;
        assert!(ran >= 120, "{outlet:?}: {ran} team steps of 120");
        assert!(state_bits(&team) == state_bits(&serial), "{outlet:?}: the bits differ");
    }
}

#[test]
fn stepped_forward_backward_the_gas_mass_budget_closes_to_round_off() {
    for outlet in [Outlet::Characteristic, Outlet::Wall] {
        let mut serial = fed_bed(outlet);
        serial.set_time_scheme(TimeScheme::ForwardBackward);
        serial.set_parallel(false);
        let worst = run(&mut serial, 750, 0);
        let b = serial.mass_balance();
        // Against the shut top the inflow stays in the column (through the outlet it mostly leaves).
        if outlet == Outlet::Wall {
            assert!(b.net_inflow.abs() > 1e-3 * b.held, "{outlet:?}: net inflow {:.3e} kg only", b.net_inflow);
        }
        assert!(worst < 1e-13, "{outlet:?}: budget error {worst:.3e} of the mass held");
        let pool = solver_pool().num_threads(2).build().unwrap();
        let mut team = fed_bed(outlet);
        team.set_time_scheme(TimeScheme::ForwardBackward);
        team.set_parallel(true);
        let worst = pool.install(|| run(&mut team, 750, 0));
        assert!(worst < 1e-13, "{outlet:?}, team: budget error {worst:.3e} of the mass held");
    }
}

/// The forward–backward step reads no past face right-hand side: it holds one slot of them, AB3
/// three; a switch either way steps on with what the new scheme needs, the gas state finite.
#[test]
fn a_forward_backward_run_holds_one_slot_of_face_right_hand_sides() {
    let mut s = bed_column(TimeScheme::ForwardBackward);
    let dt = 0.5 * s.stable_dt();
    let mut slots = vec![];
    for (scheme, steps) in [(TimeScheme::ForwardBackward, 5), (TimeScheme::Ab3, 5), (TimeScheme::ForwardBackward, 2)] {
        s.switch_time_scheme(scheme);
        for _ in 0..steps {
            s.step(dt);
        }
        slots.push(s.face_history_slots());
        assert!(s.check_finite().is_ok(), "{scheme:?}");
    }
    assert_eq!(slots, [1, 3, 1]);
}
