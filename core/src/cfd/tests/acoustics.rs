//! Acoustic pulses (speed a ± U, outlet reflection; PHYSICS.md 8, 9) and a swirling flow.

use super::support::{layer_mean, solver};
use crate::case::Gas;
use crate::cfd::{GasSolver, Outlet, TimeScheme};

const NZ: usize = 200;
const DZ: f64 = 0.005;

/// A 1-m tube (3 sector cells per layer) with uniform flow U and a Gaussian density pulse of
/// relative amplitude 1e-3 and standard deviation `width` at z0; `right_going` adds the velocity of a pure up-going wave.
/// `tube_at` stepped by `scheme`.
fn tube_with(scheme: TimeScheme, factor: f64, u: f64, z0: f64, width: f64, right_going: bool) -> (GasSolver, f64) {
    let (mut s, rho0) = tube_at(factor, u, z0, width, right_going);
    s.set_time_scheme(scheme);
    (s, rho0)
}

/// `tube` with the pressure waves at `factor` times the sound speed (`acoustic_speed_factor`).
fn tube_at(factor: f64, u: f64, z0: f64, width: f64, right_going: bool) -> (GasSolver, f64) {
    let gas = Gas {
        superficial_velocity_m_s: u,
        ramp_time_s: 0.0,
        inlet_voidage: 1.0,
        acoustic_speed_factor: factor,
        ..Default::default()
    };
    let mut s = solver(gas, 0.0, 1, 0.01, NZ, DZ);
    let (rho0, a) = (s.density(0), s.params().sound_speed);
    for c in 0..s.grid().num_cells() {
        let z = s.grid().centre_xyz(c)[2];
        let d = 1e-3 * rho0 * (-((z - z0) / width).powi(2) / 2.0).exp();
        let du = if right_going { a * d / rho0 } else { 0.0 };
        s.set_cell(c, rho0 + d, [0.0, 0.0, u + du]);
    }
    (s, rho0)
}

/// Density perturbation per layer.
fn profile(s: &GasSolver, rho0: f64) -> Vec<f64> {
    (0..NZ).map(|k| layer_mean(s, k, |c| s.density(c)) - rho0).collect()
}

/// Position of the largest perturbation within layers [k0, k1), parabola through the peak.
fn peak(p: &[f64], k0: usize, k1: usize) -> f64 {
    let k = (k0..k1).max_by(|&a, &b| p[a].partial_cmp(&p[b]).unwrap()).unwrap();
    let (l, c, r) = (p[k - 1], p[k], p[k + 1]);
    let off = 0.5 * (l - r) / (l - 2.0 * c + r);
    (k as f64 + 0.5 + off) * DZ
}

fn run_to(s: &mut GasSolver, t: f64) {
    let dt = s.stable_dt();
    while s.time() < t - 1e-12 {
        s.step(dt.min(t - s.time()));
    }
}

#[test]
fn acoustic_pulse_travels_at_a_plus_and_minus_u() {
    pulse_speeds(1.0, 20.0, 0.4e-3, 1.0e-3);
}

#[test]
fn with_a_quarter_of_the_sound_speed_a_pulse_travels_at_a_quarter_a_plus_and_minus_u() {
    let a = Gas::default().sound_speed_m_s();
    let s = pulse_speeds(0.25, 5.0, 1.6e-3, 4.0e-3);
    assert!((s / (0.25 * a) - 1.0).abs() < 1e-12, "the solver's wave speed {s} is not a/4 = {}", 0.25 * a);
}

/// Up- and down-going pulse speeds against f·a ± U between times t1 and t2; returns f·a.
fn pulse_speeds(factor: f64, u: f64, t1: f64, t2: f64) -> f64 {
    pulse_speeds_with(TimeScheme::Ab3, factor, u, t1, t2)
}

#[test]
fn stepped_forward_backward_a_pulse_travels_at_a_plus_and_minus_u() {
    pulse_speeds_with(TimeScheme::ForwardBackward, 1.0, 20.0, 0.4e-3, 1.0e-3);
}

fn pulse_speeds_with(scheme: TimeScheme, factor: f64, u: f64, t1: f64, t2: f64) -> f64 {
    let (mut s, rho0) = tube_with(scheme, factor, u, 0.4, 0.03, false);
    let a = s.params().sound_speed;
    run_to(&mut s, t1);
    let p1 = profile(&s, rho0);
    let (up1, down1) = (peak(&p1, 81, 199), peak(&p1, 1, 80));
    run_to(&mut s, t2);
    let p2 = profile(&s, rho0);
    let (up2, down2) = (peak(&p2, 81, 199), peak(&p2, 1, 80));
    let (c_up, c_down) = ((up2 - up1) / (t2 - t1), (down1 - down2) / (t2 - t1));
    assert!((c_up / (a + u) - 1.0).abs() < 0.02, "up-going pulse at {c_up} m/s, want a + U = {}", a + u);
    assert!((c_down / (a - u) - 1.0).abs() < 0.02, "down-going pulse at {c_down} m/s, want a − U = {}", a - u);
    a
}

/// Largest |ρ'| left in the tube after an up-going pulse of amplitude 1e-3ρ0 and width 0.05 m
/// (10 cells; the copy of eq. 7 reflects more of shorter pulses: 1.1 % at 6 cells) started at 0.7 m has
/// met the top and had time to come back to mid-tube, over the pulse amplitude.
fn reflected_fraction(outlet: Outlet) -> f64 {
    reflected_fraction_with(TimeScheme::Ab3, outlet)
}

fn reflected_fraction_with(scheme: TimeScheme, outlet: Outlet) -> f64 {
    let (mut s, rho0) = tube_with(scheme, 1.0, 0.0, 0.7, 0.05, true);
    s.set_outlet(outlet);
    let a = s.params().sound_speed;
    run_to(&mut s, (0.3 + 0.35) / a);
    let p = profile(&s, rho0);
    p.iter().take(190).fold(0.0f64, |m, v| m.max(v.abs())) / (1e-3 * rho0)
}

#[test]
fn characteristic_outlet_reflects_under_one_percent_and_a_shut_end_nearly_all() {
    let open = reflected_fraction(Outlet::Characteristic);
    let shut = reflected_fraction(Outlet::Wall);
    eprintln!("reflected: characteristic outlet {:.3} %, shut end {:.1} %", 100.0 * open, 100.0 * shut);
    assert!(open < 0.01, "outlet reflects {:.3} %", 100.0 * open);
    assert!(shut > 0.9, "shut end reflects only {:.1} %", 100.0 * shut);
}

/// Stepped forward–backward, what is left in the tube after the pulse has met the outlet is 2.6 %
/// of it at the stable step (1.3 % at half of it) against AB3's 0.12 %; most of it is the wake the
/// pulse leaves on its way (`stepped_forward_backward_a_pulse_leaves_a_wake_that_ab3_damps`), not
/// the outlet. Bounded here at 3 % (docs/VALIDATION.md).
#[test]
fn stepped_forward_backward_the_outlet_reflects_under_three_percent() {
    let open = reflected_fraction_with(TimeScheme::ForwardBackward, Outlet::Characteristic);
    eprintln!("forward-backward: characteristic outlet reflects {:.3} %", 100.0 * open);
    assert!(open < 0.03, "outlet reflects {:.3} %", 100.0 * open);
}

#[test]
fn solid_body_rotation_runs_10000_steps_without_growth() {
    // Closed column, no gravity; U_θ = Ωr with the balancing isothermal pressure
    // ρ(r) = ρ0·exp(Ω²r²/(2a²)). The kinetic energy must not grow.
    let gas = Gas { superficial_velocity_m_s: 0.0, ..Default::default() };
    let mut s = solver(gas, 0.0, 3, 0.004, 4, 0.004);
    s.set_outlet(Outlet::Wall);
    let (omega, a) = (100.0, s.params().sound_speed);
    let rho0 = s.density(0);
    let n = s.grid().num_cells();
    for c in 0..n {
        let [x, y, _] = s.grid().centre_xyz(c);
        let r = (x * x + y * y).sqrt();
        s.set_cell(c, rho0 * (omega * omega * r * r / (2.0 * a * a)).exp(), [0.0, omega * r, 0.0]);
    }
    let ke = |s: &GasSolver| {
        (0..n).map(|c| s.density(c) * s.velocity_cyl(c).iter().map(|v| v * v).sum::<f64>()).sum::<f64>()
    };
    let ke0 = ke(&s);
    let dt = s.stable_dt();
    let mut ke_max: f64 = 0.0;
    for step in 0..10_000 {
        s.step(dt);
        if step % 100 == 99 {
            s.check_finite().unwrap();
            ke_max = ke_max.max(ke(&s));
        }
    }
    assert!(ke_max <= 1.01 * ke0, "kinetic energy grew to {} of its start", ke_max / ke0);
    assert!(ke(&s) > 0.5 * ke0, "the rotation died: {} of its start", ke(&s) / ke0);
}

/// The wake a travelling pulse leaves behind it in an open tube, before it meets any end: the
/// forward–backward step does not damp the short waves that the discrete pulse sheds (AB3 damps
/// them a little), so its wake is 1.4% of the pulse against AB3's 0.025% after 0.25 m.
#[test]
fn stepped_forward_backward_a_pulse_leaves_a_wake_that_ab3_damps() {
    let wake = |scheme: TimeScheme| {
        let (mut s, rho0) = tube_with(scheme, 1.0, 0.0, 0.5, 0.05, true);
        s.set_outlet(Outlet::Wall);
        let a = s.params().sound_speed;
        run_to(&mut s, 0.25 / a);
        let p = profile(&s, rho0);
        let peak = p.iter().fold(0.0f64, |m, v| m.max(v.abs())) / (1e-3 * rho0);
        assert!((peak - 1.0).abs() < 0.01, "{scheme:?}: the pulse's peak is {peak} of its start");
        // Layers below 0.55 m: the pulse (at 0.75 m, σ 5 cm) has left them.
        p.iter().take(110).fold(0.0f64, |m, v| m.max(v.abs())) / (1e-3 * rho0)
    };
    let (ab3, fb) = (wake(TimeScheme::Ab3), wake(TimeScheme::ForwardBackward));
    eprintln!("wake behind the pulse: AB3 {:.3} %, forward-backward {:.3} %", 100.0 * ab3, 100.0 * fb);
    assert!(ab3 < 1e-3, "AB3 wake {:.3} %", 100.0 * ab3);
    assert!(fb < 0.02, "forward-backward wake {:.3} %", 100.0 * fb);
}
