//! The gas mass budget (cfd/mass_budget.rs): in − out − change of the flux-updated cells closes to
//! round-off through the Heun start, AB2 and AB3, the inflow ramp, a voidage that changes during the
//! run, on one thread and as a team, and across a checkpoint; a wrong budget shows as its error.

use super::support::solver;
use crate::case::Gas;
use crate::cfd::{GasSolver, Outlet};
use crate::team::solver_pool;

/// A 10-layer column with a bed-like voidage in its lower half, a drag-like force, a swirling,
/// rising flow and the inflow ramping up.
pub(super) fn fed_bed(outlet: Outlet) -> GasSolver {
    // AB3: the forward–backward step's budget has its own test (forward_backward.rs).
    let gas = Gas {
        superficial_velocity_m_s: 0.6,
        ramp_time_s: 0.002,
        bulk_viscosity_pa_s: 1e-4,
        time_scheme: crate::cfd::TimeScheme::Ab3,
        ..Default::default()
    };
    let mut s = solver(gas, 9.81, 3, 0.004, 10, 0.004);
    s.set_outlet(outlet);
    s.set_initial_voidage(&bed_voidage(&s, 0));
    for c in 0..s.grid().num_cells() {
        let [x, y, z] = s.grid().centre_xyz(c);
        let rho = s.density(c) * (1.0 + 1e-3 * (200.0 * z).cos());
        s.set_cell(c, rho, [0.3 * (x * 300.0).sin(), 2.0 * (x * x + y * y).sqrt() * 50.0, 0.4 * (y * 200.0).cos()]);
        s.interaction_force_mut()[c] = [10.0 * (c as f64).cos(), 5.0 * (c as f64).sin(), 400.0];
    }
    s
}

/// A voidage that moves with the step: 0.45–0.85 below mid-height, 1 above.
fn bed_voidage(s: &GasSolver, step: usize) -> Vec<f64> {
    let g = s.grid();
    (0..g.num_cells())
        .map(|c| {
            let z = g.centre_xyz(c)[2];
            if z < 0.5 * g.height {
                0.45 + 0.4 * ((c as f64) * 0.37 + step as f64 * 0.02).sin().abs()
            } else {
                1.0
            }
        })
        .collect()
}

/// Steps `s` with a changing voidage; the largest |budget error| seen, checked every step.
pub(super) fn run(s: &mut GasSolver, steps: usize, from: usize) -> f64 {
    let dt = 0.8 * s.stable_dt();
    let mut worst = 0.0f64;
    for n in from..from + steps {
        if n % 5 == 0 {
            let eps = bed_voidage(s, n);
            s.set_voidage(&eps);
        }
        s.step(dt);
        worst = worst.max(s.mass_balance().relative_error().abs());
    }
    s.check_finite().unwrap();
    worst
}

#[test]
fn the_gas_mass_budget_closes_to_round_off_on_one_thread_and_as_a_team() {
    for outlet in [Outlet::Characteristic, Outlet::Wall] {
        let mut serial = fed_bed(outlet);
        serial.set_parallel(false);
        let worst = run(&mut serial, 1500, 0);
        let b = serial.mass_balance();
        eprintln!("{outlet:?}: in − out {:.6e} kg, change {:.6e} kg, worst error {worst:.2e}", b.net_inflow, b.change);
        // The budget is not trivial: the inflow moved a good share of the mass held.
        assert!(b.net_inflow.abs() > 1e-3 * b.held, "{outlet:?}: net inflow {:.3e} kg only", b.net_inflow);
        assert!(worst < 1e-13, "{outlet:?}: budget error {worst:.3e} of the mass held");
        let pool = solver_pool().num_threads(2).build().unwrap();
        let mut team = fed_bed(outlet);
        team.set_parallel(true);
        let worst = pool.install(|| run(&mut team, 1500, 0));
        assert!(worst < 1e-13, "{outlet:?}, team: budget error {worst:.3e} of the mass held");
    }
}

#[test]
fn the_budget_continues_across_a_checkpoint_and_a_wrong_one_shows() {
    let mut a = fed_bed(Outlet::Characteristic);
    run(&mut a, 300, 0);
    let bytes = bincode::serialize(&a).unwrap();
    // The checkpoint holds no scheme (the simulation's restore sets the case's).
    let mut b: GasSolver = bincode::deserialize(&bytes).unwrap();
    b.set_time_scheme(a.time_scheme());
    b.set_mass_budget(a.mass_budget());
    let worst = run(&mut b, 300, 300);
    assert!(worst < 1e-13, "after the resume: budget error {worst:.3e}");
    // Without the budget's section the resumed run starts a budget of its own, which closes too.
    let mut c: GasSolver = bincode::deserialize(&bytes).unwrap();
    c.set_time_scheme(a.time_scheme());
    let worst = run(&mut c, 300, 300);
    assert!(worst < 1e-13, "budget started at the resume: error {worst:.3e}");
    assert!(c.mass_balance().change.abs() < b.mass_balance().change.abs() + b.mass_balance().held);
    // A budget that misses 1e-6 of the mass held reads as that error.
    let mut wrong = b.mass_budget();
    wrong.net += 1e-6 * b.mass_balance().held;
    b.set_mass_budget(wrong);
    let e = b.mass_balance().relative_error();
    assert!((e - 1e-6).abs() < 1e-12, "error {e:.3e}, 1e-6 put in");
}

#[test]
fn a_scheme_switched_during_a_run_starts_its_history_again_and_the_budget_closes() {
    use crate::cfd::TimeScheme;
    for (from, to) in [(TimeScheme::Ab3, TimeScheme::ForwardBackward), (TimeScheme::ForwardBackward, TimeScheme::Ab3)] {
        let mut a = fed_bed(Outlet::Characteristic);
        a.set_time_scheme(from);
        run(&mut a, 200, 0);
        // Kept, the other scheme's history would enter the new steps: the budget shows it.
        let mut kept = a.clone();
        kept.set_time_scheme(to);
        let wrong = run(&mut kept, 200, 200);
        a.switch_time_scheme(to);
        let worst = run(&mut a, 200, 200);
        assert_eq!(a.time_scheme(), to);
        assert!(worst < 1e-13, "{from:?} → {to:?}: budget error {worst:.3e}");
        // (AB3 reads the forward–backward history's momentum without its pressure force.)
        if from == TimeScheme::ForwardBackward {
            assert!(wrong > 1e-9, "the kept history went unseen: {wrong:.3e}");
        }
        eprintln!("{from:?} → {to:?}: history kept {wrong:.2e}, started again {worst:.2e}");
    }
}
