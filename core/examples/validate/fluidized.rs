//! Fluidized bed (issue: coupling): the 44-mm bed at U = 0.6 m/s. The time-mean pressure drop
//! across the bed must be within 2% of the bed weight per area less buoyancy (PHYSICS.md 10).

use crate::common::*;
use serde_json::json;

pub fn run() -> serde_json::Value {
    let mut case = load_case("bubbling-44mm.json");
    let end = 0.8;
    let t_avg = 0.4; // after the 240-ms ramp and the first bubbles
    case.end_time_s = end;
    case.outputs.snapshot_interval_s = 0.005;
    case.outputs.fields = vec![fluidbed_core::case::Field::Pressure];
    let (sim, snaps) = run_case(case, "fluidized");
    let tail: Vec<f64> = snaps.iter().filter(|s| s.time_s >= t_avg).filter_map(|s| s.pressure_drop_pa).collect();
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    let sd = (tail.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / tail.len() as f64).sqrt();
    let g = sim.case().gas.as_ref().unwrap();
    let rho_g = g.outlet_density_kg_m3();
    let want = bed_weight_per_area(sim.case(), sim.dem().len(), rho_g);
    let rel = mean / want - 1.0;
    eprintln!("{} particles; mean ΔP over t ≥ {t_avg} s = {mean:.1} Pa (σ = {sd:.1} Pa, {} snapshots); bed weight / area = {want:.1} Pa; {:+.2}%", sim.dem().len(), tail.len(), rel * 100.0);
    crate::plots::pressure_trace(&snaps, "docs/img/fluidized_dp.png", Some(want));
    json!({"name": "fluidized", "figure": mean, "reference": want, "rel_err": rel, "std_pa": sd, "particles": sim.dem().len(), "t_avg_from_s": t_avg, "end_s": end})
}
