//! Would an adaptive DEM step pay on the bubbling bed? (`bench -- adaptive-step`)
//!
//! A step chosen from the Hertz contact time of the fastest approach keeps a fixed number of steps
//! per contact: dt(t) ∝ t_c(v(t)) ∝ v(t)^(−1/5) (PHYSICS.md 2.4), v(t) the largest approach speed
//! of the moment, at most twice the fastest particle's speed. Holding the shipped step's accuracy
//! at the fastest moment of a window (v_ref) allows dt(t) = dt·(v_ref/v(t))^(1/5), and the DEM's
//! cost over the window falls by the time mean of dt/dt(t) (steps per simulated second). The bed
//! is the 44-mm bubbling case from its fluidized 0.3-s state (`coupled`'s cache), run at its
//! defaults for `FLUIDBED_ADAPTIVE_S` simulated seconds (0.2), the fastest particle sampled every
//! 40 DEM steps (50 µs). The last line: {"bench":"adaptive_step","dem_cost_ratio":…,…}.

use crate::coupled::{coupled_round, shipped_case, state_at, Tally, FLUIDIZED_AT_S};
use fluidbed_core::sim::Simulation;
use serde_json::json;

pub fn run() {
    let case = shipped_case("bubbling-44mm.json");
    let mut sim = Simulation::restore(&state_at(&case, FLUIDIZED_AT_S, "bubbling-44mm")).expect("cached state");
    let span: f64 = std::env::var("FLUIDBED_ADAPTIVE_S").ok().and_then(|s| s.parse().ok()).unwrap_or(0.2);
    let dt = case.dem.time_step_s;
    let every = 40u64;
    let samples = (span / (every as f64 * dt)).round() as usize;
    let mut v_max = Vec::with_capacity(samples);
    let mut tally = Tally::default();
    for _ in 0..samples {
        coupled_round(&mut sim, every, &mut tally);
        let v2 = sim.dem().velocities().iter().map(|v| v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).fold(0.0, f64::max);
        v_max.push(v2.sqrt());
    }
    let v_ref = v_max.iter().copied().fold(0.0, f64::max);
    // DEM steps with the adaptive step per step of the shipped one, over the window.
    let cost = v_max.iter().map(|&v| (v / v_ref).powf(0.2)).sum::<f64>() / samples as f64;
    v_max.sort_by(f64::total_cmp);
    let pct = |q: f64| v_max[((q * (samples - 1) as f64).round() as usize).min(samples - 1)];
    let steps_per_contact = |v: f64| case.hertz_contact_time_s(2.0 * v) / dt;
    println!(
        "{}",
        json!({"bench": "adaptive_step", "window_s": span, "samples": samples, "particles": sim.dem().len(),
               "fastest_particle_m_s": {"min": pct(0.0), "median": pct(0.5), "p90": pct(0.9), "max": v_ref},
               "steps_per_contact_at_twice_the_fastest": {"max_speed": steps_per_contact(v_ref), "median_speed": steps_per_contact(pct(0.5))},
               "dem_cost_ratio": cost, "dem_speedup": 1.0 / cost})
    );
}
