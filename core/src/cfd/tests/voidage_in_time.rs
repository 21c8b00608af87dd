//! The gas's voidage between couplings (cfd/voidage_ramp.rs): each cell's gas mass ρεV is held,
//! so p = c²(ρε)/ε follows ε. Set at once (held), a uniform change from ε₀ to ε₁ moves the
//! pressure by the whole p₀(ε₀/ε₁ − 1) in one step; interpolated over n steps, by p₀ε₀ times the
//! change of 1/ε over one n-th of the way per step, to the same end value.

use super::support::solver;
use crate::case::Gas;
use crate::cfd::GasSolver;

const E0: f64 = 0.5;
const E1: f64 = 0.6;

/// The pressure of a cell low in a tall, still column without gravity (far from the outlet's
/// waves) before ε₁ is applied by `apply`, and after each of `steps` gas steps.
fn bottom_pressures(apply: impl Fn(&mut GasSolver, f64), steps: usize) -> (f64, Vec<f64>) {
    let gas = Gas { superficial_velocity_m_s: 0.0, ..Default::default() };
    let mut s = solver(gas, 0.0, 2, 0.004, 60, 0.004);
    let n = s.grid().num_cells();
    s.set_initial_voidage(&vec![E0; n]);
    let dt = s.stable_dt();
    let cell = s.grid().cells_per_layer() + 1;
    s.step(dt);
    let p0 = s.pressure()[cell];
    apply(&mut s, dt);
    let p = (0..steps)
        .map(|_| {
            s.step(dt);
            s.pressure()[cell]
        })
        .collect();
    (p0, p)
}

#[test]
fn a_held_voidage_steps_the_pressure_and_an_interpolated_one_ramps_it_to_the_same_value() {
    let n = 10;
    let (p0, held) = bottom_pressures(|s, _| s.set_voidage(&vec![E1; s.grid().num_cells()]), n + 2);
    let want = p0 * E0 / E1;
    assert!((held[0] / want - 1.0).abs() < 1e-9, "held: {} Pa after one step, want {want} Pa", held[0]);
    let (q0, ramped) = bottom_pressures(
        |s, dt| {
            let t = s.time();
            s.ramp_voidage(&vec![E1; s.grid().num_cells()], t, n as f64 * dt, false)
        },
        n + 2,
    );
    assert_eq!(p0, q0);
    let end = *ramped.last().unwrap();
    assert!((end / want - 1.0).abs() < 1e-9, "interpolated: {end} Pa at the end, want {want} Pa");
    // The largest step: 1/ε changes most on the first n-th, from ε₀ to ε₀ + (ε₁ − ε₀)/n.
    let bound = p0 * E0 * (1.0 / E0 - 1.0 / (E0 + (E1 - E0) / n as f64));
    let mut last = p0;
    for (k, &p) in ramped.iter().enumerate() {
        assert!((p - last).abs() <= bound * (1.0 + 1e-9), "step {k}: {} Pa, bound {bound} Pa", p - last);
        last = p;
    }
    assert!(bound < 0.12 * (p0 - want), "each step moves about a tenth of the held step");
}
