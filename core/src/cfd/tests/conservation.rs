//! Free stream, mass conservation, voidage changes, checkpoints.

use super::support::solver;
use crate::case::Gas;
use crate::cfd::{GasSolver, Outlet};

#[test]
fn uniform_upward_flow_stays_uniform_for_1000_steps() {
    // No gravity, ε = 1, inlet voidage 1 (an empty column), no ramp: the exact solution is the
    // initial uniform state ρ0, u = (0, 0, U).
    let u = 0.5;
    let gas = Gas { superficial_velocity_m_s: u, ramp_time_s: 0.0, inlet_voidage: 1.0, ..Default::default() };
    let mut s = solver(gas, 0.0, 3, 0.004, 10, 0.004);
    let rho0 = s.density(0);
    for c in 0..s.grid().num_cells() {
        s.set_cell(c, rho0, [0.0, 0.0, u]);
    }
    let dt = s.stable_dt();
    for _ in 0..1000 {
        s.step(dt);
    }
    for c in 0..s.grid().num_cells() {
        let v = s.velocity_cyl(c);
        assert!((s.density(c) / rho0 - 1.0).abs() < 1e-10, "cell {c}: ρ = {}", s.density(c));
        assert!(v[0].abs() < 1e-10 && v[1].abs() < 1e-10 && (v[2] - u).abs() < 1e-10, "cell {c}: u = {v:?}");
    }
}

/// A closed column (inlet velocity 0, shut top) with gravity, a swirling and rising initial flow
/// and a voidage field that changes every step.
fn stirred_closed_column() -> GasSolver {
    let gas = Gas { superficial_velocity_m_s: 0.0, bulk_viscosity_pa_s: 1e-4, ..Default::default() };
    let mut s = solver(gas, 9.81, 3, 0.004, 8, 0.004);
    s.set_outlet(Outlet::Wall);
    let n = s.grid().num_cells();
    let eps: Vec<f64> = (0..n).map(|c| 0.6 + 0.3 * ((c as f64) * 0.37).sin().abs()).collect();
    s.set_voidage(&eps);
    for c in 0..n {
        let [x, y, z] = s.grid().centre_xyz(c);
        let rho = s.density(c) * (1.0 + 1e-3 * (200.0 * z).cos());
        s.set_cell(c, rho, [0.3 * (x * 300.0).sin(), 2.0 * (x * x + y * y).sqrt() * 50.0, 0.4 * (y * 200.0).cos()]);
    }
    s
}

#[test]
fn closed_column_conserves_gas_mass_to_round_off_every_step() {
    let mut s = stirred_closed_column();
    let n = s.grid().num_cells();
    let dt = s.stable_dt();
    let mut m_prev = s.total_mass();
    for step in 0..300 {
        // Voidage changes in time (mass is held, the pressure responds).
        let eps: Vec<f64> = (0..n).map(|c| 0.6 + 0.3 * ((c as f64) * 0.37 + step as f64 * 0.01).sin().abs()).collect();
        s.set_voidage(&eps);
        s.step(dt);
        let m = s.total_mass();
        assert!(((m - m_prev) / m_prev).abs() < 1e-12, "step {step}: relative mass change {}", (m - m_prev) / m_prev);
        m_prev = m;
    }
    s.check_finite().unwrap();
}

#[test]
fn changing_voidage_holds_cell_mass_and_raises_pressure() {
    // Displaced gas: ρεV held, so p = a²(ρε)/ε rises by ε_old/ε_new.
    let mut s = solver(Gas::default(), 9.81, 2, 0.004, 3, 0.004);
    let n = s.grid().num_cells();
    let (m0, p0) = (s.total_mass(), s.pressure());
    s.set_voidage(&vec![0.5; n]);
    assert_eq!(s.total_mass(), m0);
    for (p, q) in s.pressure().iter().zip(&p0) {
        assert!((p / q - 2.0).abs() < 1e-14);
    }
}

#[test]
fn checkpoint_round_trip_continues_the_run() {
    let mut a = stirred_closed_column();
    let dt = a.stable_dt();
    for _ in 0..5 {
        a.step(dt);
    }
    let json = serde_json::to_string(&a).unwrap();
    let mut b: GasSolver = serde_json::from_str(&json).unwrap();
    for _ in 0..5 {
        a.step(dt);
        b.step(dt);
    }
    assert_eq!(a.time(), b.time());
    // serde_json parses floats to within an ulp (its `float_roundtrip` feature is off), so the
    // continued runs agree to round-off rather than bit for bit.
    for c in 0..a.grid().num_cells() {
        assert!((a.density(c) / b.density(c) - 1.0).abs() < 1e-13);
        let (u, v) = (a.velocity_cyl(c), b.velocity_cyl(c));
        assert!((0..3).all(|d| (u[d] - v[d]).abs() < 1e-12), "{u:?} vs {v:?}");
    }
}

#[test]
fn check_finite_names_the_cell_and_the_quantity() {
    let mut s = solver(Gas::default(), 9.81, 2, 0.004, 3, 0.004);
    assert!(s.check_finite().is_ok());
    let cell = s.grid().index(1, 4, 2);
    s.set_cell(cell, -1.0, [0.0; 3]);
    let e = s.check_finite().unwrap_err();
    assert!(e.contains("i=1, j=4, k=2") && e.contains("density"), "{e}");
}
