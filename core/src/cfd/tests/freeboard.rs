//! The freeboard above a porous zone: no odd–even pressure ripple (issue 22 item 6a). The
//! quickstart's gas column (22 mm, 3 annuli × 18 layers, dz = dr) with a fixed zone of ε = 0.45
//! (1.2-mm particles at rest, model-A Beetstra drag) in layers 0–5, fed by the 0.1-s ramp to 0.6 m/s.

use super::support::{layer_mean, solver};
use crate::case::Gas;
use crate::cfd::GasSolver;
use crate::coupling::beta_a;

const MU: f64 = 1.8e-5;
const D: f64 = 1.2e-3;
const NZ: usize = 18;

/// Odd–even amplitude of the layer-to-layer differences of `p` over layers [k0, k1) (as the
/// gas-artefacts stress run measures it).
fn odd_even(p: &[f64], k0: usize, k1: usize) -> f64 {
    let d: Vec<f64> = (k0..k1 - 1).map(|k| p[k + 1] - p[k]).collect();
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let alt: f64 = d.iter().enumerate().map(|(i, x)| if i % 2 == 0 { x - mean } else { mean - x }).sum();
    (alt / d.len() as f64).abs()
}

/// Runs the column to `t_end`; the zone's drag is scaled by `scale(t)` and, in its top layer 5, by
/// `top(t)` as well. Returns the solver and the worst freeboard odd–even amplitude (layers 8 to
/// NZ − 2) over the snapshots every 5 ms from `from`.
fn run(t_end: f64, from: f64, top: impl Fn(f64) -> f64, scale: impl Fn(f64) -> f64) -> (GasSolver, f64) {
    let gas = Gas { superficial_velocity_m_s: 0.6, ramp_time_s: 0.1, viscosity_pa_s: MU, ..Default::default() };
    let dr = 0.011 / 3.0;
    let mut s = solver(gas, 9.81, 3, dr, NZ, dr);
    let per = s.grid().cells_per_layer();
    let n = s.grid().num_cells();
    let dt = s.stable_dt();
    let mut worst: f64 = 0.0;
    let mut next = from;
    let eps: Vec<f64> = (0..n).map(|c| if c / per < 6 { 0.45 } else { 1.0 }).collect();
    s.set_initial_voidage(&eps);
    while s.time() < t_end - 1e-12 {
        let t = s.time();
        let (f5, f) = (top(t), scale(t));
        for (c, &e) in eps.iter().enumerate() {
            let f = if c / per == 5 { f * f5 } else { f };
            let (rho, u) = (s.density(c), s.velocity_cyl(c));
            let speed = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let beta = if e < 1.0 { f * beta_a(MU, D, e, rho * e * speed * D / MU) } else { 0.0 };
            s.interaction_force_mut()[c] = [-beta * u[0], -beta * u[1], -beta * u[2]];
        }
        s.step(dt);
        if s.time() >= next - 1e-12 {
            next += 5e-3;
            let p = s.pressure();
            let layers: Vec<f64> = (0..NZ).map(|k| layer_mean(&s, k, |c| p[c])).collect();
            worst = worst.max(odd_even(&layers, 8, NZ - 1));
        }
    }
    s.check_finite().unwrap();
    (s, worst)
}

#[test]
fn the_freeboard_above_a_steady_zone_has_no_odd_even_ripple() {
    // Before the drag-weighted face pressure and κ_m: 9.62 Pa, the even layers 9.6 Pa low.
    let (s, oe) = run(0.15, 0.1, |_| 1.0, |_| 1.0);
    let (p, per) = (s.pressure(), s.grid().cells_per_layer());
    let layers: Vec<f64> = (0..NZ).map(|k| layer_mean(&s, k, |c| p[c])).collect();
    let gz = |k: usize| (0..per).map(|c| s.pressure_gradient_cyl(k * per + c)[2]).sum::<f64>() / per as f64;
    let bed = (layers[2] - layers[4]) / (2.0 * s.grid().dz);
    eprintln!(
        "steady zone: freeboard odd-even {oe:.3} Pa; -dp/dz {bed:.1} Pa/m in the zone, cell gradients layers 4-7 {:?}; \
         layers {:?}",
        (4..8).map(|k| format!("{:.1}", gz(k))).collect::<Vec<_>>(),
        layers.iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>()
    );
    assert!(oe < 0.5, "freeboard odd-even {oe:.3} Pa");
    // The zone's top cell has its own drag balance as its gradient, the first free cell ~ρg.
    assert!((-gz(5) / bed - 1.0).abs() < 0.02, "top zone cell: {:.1} against {bed:.1} Pa/m", -gz(5));
    assert!(gz(6).abs() < 0.02 * bed, "first free cell: {:.1} Pa/m (zone {bed:.1})", gz(6));
}

#[test]
fn the_freeboard_above_a_varying_zone_has_no_odd_even_ripple() {
    // The zone's drag swings by ±30 % at 20 Hz, and its top layer's between 0 and 1 at 13 Hz.
    let top = |t: f64| 0.5 + 0.5 * (2.0 * std::f64::consts::PI * 13.0 * t).sin();
    let scale = |t: f64| 1.0 + 0.3 * (2.0 * std::f64::consts::PI * 20.0 * t).sin();
    let (_, oe) = run(0.2, 0.1, top, scale);
    eprintln!("varying zone: freeboard odd-even {oe:.3} Pa");
    assert!(oe < 0.5, "freeboard odd-even {oe:.3} Pa");
}
