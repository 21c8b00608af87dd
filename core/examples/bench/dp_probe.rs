//! The gas's fast pressure oscillations (`bench -- dp-probe`): from the trade-off bed's spin-up
//! state (tradeoff.rs, 0.2 s, 0.6 m/s), each gas time scheme at the default coupling interval
//! runs 0.2 s with the bed's ΔP (bottom layer's mean pressure less the top layer's) read every 4
//! DEM steps (5 µs; Nyquist 100 kHz). Printed per scheme: the gas step, ΔP's mean and standard
//! deviation, the r.m.s. above 5 kHz (no bed motion is that fast: gas-step noise), the dominant
//! frequency of the full record and of it read every 2 ms (the snapshot rate of `-- tradeoff`,
//! where faster oscillations alias to low frequencies). `-- dp-probe 44`: the shipped 44-mm
//! bubbling bed from the coupled bench's 0.3-s state instead.

use crate::coupled::{shipped_case, state_at, FLUIDIZED_AT_S};
use crate::tradeoff::{bed, SPIN_UP_S};
use fluidbed_core::analysis::spectrum::{dominant_frequency, welch};
use fluidbed_core::cfd::TimeScheme;
use fluidbed_core::sim::Simulation;
use serde_json::json;

const WINDOW_S: f64 = 0.2;
const EVERY: u64 = 4;

pub fn run() {
    let shipped = std::env::args().nth(2).as_deref() == Some("44");
    let (reference, start) =
        if shipped { (shipped_case("bubbling-44mm.json"), FLUIDIZED_AT_S) } else { (bed(1), SPIN_UP_S) };
    let state = if shipped {
        state_at(&reference, start, "bubbling-44mm")
    } else {
        state_at(&reference, start, "tradeoff-seed1")
    };
    for scheme in [TimeScheme::Ab3, TimeScheme::ForwardBackward] {
        let mut sim = Simulation::restore(&state).expect("state");
        sim.set_gas_time_scheme(scheme);
        sim.set_end_time(start + WINDOW_S);
        let dt = EVERY as f64 * reference.dem.time_step_s;
        let mut dp = Vec::new();
        while !sim.is_finished() {
            sim.advance(EVERY).expect("stable run");
            let gas = sim.gas().expect("gas");
            let (p, per, nz) = (gas.pressure(), gas.grid().cells_per_layer(), gas.grid().nz);
            let mean = |k: usize| p[k * per..(k + 1) * per].iter().sum::<f64>() / per as f64;
            dp.push(mean(0) - mean(nz - 1));
        }
        let n = dp.len() as f64;
        let m = dp.iter().sum::<f64>() / n;
        let std = (dp.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt();
        let full = welch(&dp, dt, 8192).expect("record");
        let fast = full.band_power(5e3, f64::INFINITY).sqrt();
        let stride = (0.002 / dt).round() as usize;
        let sparse: Vec<f64> = dp.iter().step_by(stride).copied().collect();
        let snap = welch(&sparse, stride as f64 * dt, 32).and_then(|s| dominant_frequency(&s));
        println!(
            "{}",
            json!({"bench": "dp_probe", "scheme": format!("{scheme:?}"), "gas_dt_s": sim.plan().gas_dt_s,
            "interval": reference.coupling.interval_steps, "dp_mean_pa": m, "dp_std_pa": std, "rms_above_5khz_pa": fast,
            "dominant_hz": dominant_frequency(&full), "dominant_hz_every_2ms": snap})
        );
    }
}
