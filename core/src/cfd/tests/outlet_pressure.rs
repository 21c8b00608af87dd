//! The characteristic outlet holds the pressure it is given (PHYSICS.md 9: the Poinsot–Lele term
//! K a(ρ − ρ_∞) relaxes the mean in H/(σa)); with σ = 0 the column keeps the pressure the inflow ramp
//! pushed it to (issue 22: ~210 Pa in the quickstart column).

use super::support::{layer_mean, solver};
use crate::case::Gas;

/// Top layer's mean pressure less the outlet pressure after a ramp to `u` in 0.1 s, at 0.2 s, in
/// the quickstart's gas column (22 mm, 3 annuli × 18 layers, dz = dr).
fn top_offset_after_ramp(u: f64, sigma: Option<f64>) -> f64 {
    let mut gas = Gas { superficial_velocity_m_s: u, ramp_time_s: 0.1, ..Default::default() };
    if let Some(s) = sigma {
        gas.outlet_relaxation = s;
    }
    let dr = 0.011 / 3.0;
    let mut s = solver(gas, 9.81, 3, dr, 18, dr);
    let dt = s.stable_dt();
    while s.time() < 0.2 {
        s.step(dt);
    }
    s.check_finite().unwrap();
    let p = s.pressure();
    layer_mean(&s, 17, |c| p[c]) - s.params().outlet_pressure
}

#[test]
fn the_default_outlet_holds_the_set_pressure_after_the_inflow_ramp() {
    // A gas column: the top cell's pressure is the outlet pressure plus ρg·dz/2 ≈ 0.02 Pa.
    for u in [0.6, 3.7] {
        let off = top_offset_after_ramp(u, None);
        eprintln!("U = {u} m/s, default σ: top layer {off:+.3} Pa off the outlet pressure");
        assert!(off.abs() < 10.0, "U = {u} m/s: the top layer is {off:.2} Pa off the outlet pressure");
    }
    // Without relaxation the ramp's compression stays: the check above can fail.
    let off = top_offset_after_ramp(0.6, Some(0.0));
    eprintln!("U = 0.6 m/s, σ = 0: top layer {off:+.3} Pa off the outlet pressure");
    assert!(off > 10.0, "σ = 0 left only {off:.2} Pa after the ramp");
}
