//! A fixed porous zone with Beetstra resistance: Δp/L against the model-A analytic value
//! (PHYSICS.md 1.1, 11): at steady state −ε∇p + I = 0, I = −β_A u, β_A = 18μεφF/d², u = U0/ε, so
//! −dp/dz = 18 μ φ F(ε, Re) U0 / (ε d²), Re = ρ U0 d/μ.

use super::support::{beetstra_f, fixed_bed_gas, layer_mean, solver, step_through_fixed_bed};

#[test]
fn beetstra_helper_reproduces_the_physics_table() {
    for (eps, re, want) in [(0.4, 0.0, 37.846), (0.4, 10.0, 41.195), (0.6, 100.0, 30.742), (0.8, 10.0, 5.187)] {
        assert!((beetstra_f(eps, re) - want).abs() < 2e-3, "F({eps}, {re}) = {}", beetstra_f(eps, re));
    }
}

#[test]
fn porous_zone_pressure_drop_matches_model_a_beetstra() {
    let (u0, d, mu) = (0.2, 1.2e-3, 1.8e-5);
    let (nz, dz) = (40, 0.0025);
    // No gravity (Δp is the resistance alone); the zone starts above the inlet, so ε_in = 1.
    let mut s = solver(fixed_bed_gas(u0, mu), 0.0, 1, 0.005, nz, dz);
    let per = s.grid().cells_per_layer();
    let (k_lo, k_hi) = (12, 28); // ε = 0.4 in layers [12, 28): z from 0.03 to 0.07 m
    let eps: Vec<f64> =
        (0..s.grid().num_cells()).map(|c| if (k_lo..k_hi).contains(&(c / per)) { 0.4 } else { 1.0 }).collect();
    s.set_initial_voidage(&eps);
    let dt = s.stable_dt();
    for _ in 0..12_000 {
        step_through_fixed_bed(&mut s, &eps, d, mu, dt);
    }
    let p = |k: usize| layer_mean(&s, k, |c| s.pressure()[c]);
    // The collocated central scheme leaves an odd–even ripple in p downstream of the ε jumps
    // (the ε = 1 regions have no drag to damp it): average the drops over both parities.
    let (k1, k2) = (k_lo + 2, k_hi - 4);
    let dpdl = 0.5 * ((p(k1) - p(k2)) + (p(k1 + 1) - p(k2 + 1))) / ((k2 - k1) as f64 * dz);
    let rho = layer_mean(&s, (k1 + k2) / 2, |c| s.density(c));
    let (e, phi) = (0.4, 0.6);
    let want = 18.0 * mu * phi * beetstra_f(e, rho * u0 * d / mu) * u0 / (e * d * d);
    eprintln!("porous zone: Δp/L = {dpdl:.1} Pa/m, analytic {want:.1} Pa/m");
    assert!((dpdl / want - 1.0).abs() < 0.03, "Δp/L = {dpdl} Pa/m, analytic {want} Pa/m");
}
