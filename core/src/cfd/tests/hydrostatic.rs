//! A quiescent column relaxes to ρ(z) = ρ0·exp(−g z / a²) (PHYSICS.md 8).

use super::support::{layer_mean, solver};
use crate::case::Gas;

#[test]
fn quiescent_column_relaxes_to_the_isothermal_hydrostatic_profile() {
    // Closed bottom (inlet velocity 0), characteristic outlet with relaxation; start from a uniform
    // density, so the column is out of balance by ρ g H/a² and must find the profile itself.
    let gas = Gas { superficial_velocity_m_s: 0.0, outlet_relaxation: 0.25, ..Default::default() };
    let (nz, dz) = (40, 0.0025);
    let mut s = solver(gas, 9.81, 1, 0.005, nz, dz);
    let rho_top = s.params().outlet_pressure / s.params().sound_speed.powi(2);
    for c in 0..s.grid().num_cells() {
        s.set_cell(c, rho_top, [0.0; 3]);
    }
    let dt = s.stable_dt();
    let a2 = s.params().sound_speed.powi(2);
    for _ in 0..20_000 {
        s.step(dt);
    }
    let rho = |k: usize| layer_mean(&s, k, |c| s.density(c));
    let z = |k: usize| (k as f64 + 0.5) * dz;
    let variation = rho(0) - rho(nz - 1);
    let want_variation = rho(nz - 1) * ((9.81 * (z(nz - 1) - z(0)) / a2).exp() - 1.0);
    for k in 0..nz {
        let want = rho(nz - 1) * (9.81 * (z(nz - 1) - z(k)) / a2).exp();
        assert!(
            (rho(k) - want).abs() < 0.02 * want_variation,
            "layer {k}: ρ = {} want {want} (variation {variation:e})",
            rho(k)
        );
    }
    let umax = (0..s.grid().num_cells())
        .map(|c| s.velocity_cyl(c).iter().fold(0.0f64, |m, v| m.max(v.abs())))
        .fold(0.0, f64::max);
    // The initial imbalance drives velocities of order (ρgH/a²/ρ)·a ≈ 3e-3 m/s.
    assert!(umax < 1e-5, "velocities have not decayed: {umax:e} m/s");
}

#[test]
fn pressure_gradient_of_the_initial_state_is_minus_rho_g_everywhere() {
    // The initial state is hydrostatic, so ∇p = (0, 0, −ρg) at every cell centre, the end cells
    // included (inlet ghost extrapolated hydrostatically, outlet face linearly).
    let s = solver(Gas::default(), 9.81, 3, 0.004, 6, 0.004);
    for c in 0..s.grid().num_cells() {
        let g = s.pressure_gradient_cyl(c);
        let want = -s.density(c) * 9.81;
        assert!((g[2] / want - 1.0).abs() < 1e-4, "cell {c}: ∂p/∂z = {} want {want}", g[2]);
        assert!(g[0].abs() < 1e-8 && g[1].abs() < 1e-8, "cell {c}: horizontal gradient {g:?}");
    }
}

#[test]
fn a_slowed_acoustic_speed_keeps_the_outlet_pressure_the_density_and_the_hydrostatic_drop() {
    // p = p_out + c²(ρ − ρ_out), c = a/4: the reported top pressure is the outlet's (half a layer of
    // hydrostatic head below it), the density the air's at p_out, the column's drop ρ g (H − dz).
    let (nz, dz) = (40, 0.0025);
    let gas = Gas { acoustic_speed_factor: 0.25, ..Default::default() };
    let (p_out, rho_out) = (gas.outlet_pressure_pa, gas.outlet_density_kg_m3());
    let s = solver(gas, 9.81, 3, 0.004, nz, dz);
    let p = s.pressure();
    let layer_p = |k: usize| layer_mean(&s, k, |c| p[c]);
    let head = rho_out * 9.81;
    assert!((layer_p(nz - 1) - (p_out + 0.5 * dz * head)).abs() < 1e-3 * dz * head, "top {}", layer_p(nz - 1));
    let drop = layer_p(0) - layer_p(nz - 1);
    assert!((drop / (head * (nz - 1) as f64 * dz) - 1.0).abs() < 1e-3, "drop {drop} Pa");
    for c in 0..s.grid().num_cells() {
        assert!((s.density(c) / rho_out - 1.0).abs() < 1e-3, "cell {c}: ρ = {}", s.density(c));
    }
    // ∇p is −ρg as at the full sound speed.
    for c in 0..s.grid().num_cells() {
        let g = s.pressure_gradient_cyl(c);
        assert!((g[2] / (-s.density(c) * 9.81) - 1.0).abs() < 1e-4, "cell {c}: ∂p/∂z = {}", g[2]);
    }
}

#[test]
fn the_stable_gas_step_grows_as_one_over_the_acoustic_speed_factor() {
    let step = |f: f64| {
        let gas = Gas {
            acoustic_speed_factor: f,
            superficial_velocity_m_s: 0.0,
            time_scheme: crate::cfd::TimeScheme::Ab3,
            ..Default::default()
        };
        solver(gas, 9.81, 5, 0.0044, 20, 0.0022).stable_dt()
    };
    let ratio = step(0.25) / step(1.0);
    // Gas at rest: the acoustic limit scales as 1/f; the viscous part (~1e-4 of it) does not.
    assert!((ratio / 4.0 - 1.0).abs() < 1e-3, "stable step ratio {ratio}, want 4");
}
