//! Fluidized bed (issue: coupling): the 44-mm bed of 30 mm settled height at U = 0.6 m/s. The
//! time-mean pressure drop across the bed must be within 2% of the bed weight per area less
//! buoyancy (PHYSICS.md 10). It reads the same one-second run as `bubbling` (run once, kept in
//! target/validate-cache), averaging from t = 0.4 s (after the 240-ms ramp and first bubbles).

use crate::common::*;
use serde_json::json;

pub fn run() -> serde_json::Value {
    let r = crate::bubbling::one_second_run();
    let t_avg = 0.4;
    let tail: Vec<f64> = r.dp.iter().filter(|(t, _)| *t >= t_avg).map(|x| x.1).collect();
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    let sd = (tail.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / tail.len() as f64).sqrt();
    let case = load_case("bubbling-44mm.json");
    let rho_g = case.gas.as_ref().unwrap().outlet_density_kg_m3();
    let want = bed_weight_per_area(&case, r.particles, rho_g);
    let rel = mean / want - 1.0;
    eprintln!("{} particles; mean ΔP over {t_avg} ≤ t ≤ {} s = {mean:.1} Pa (σ = {sd:.1} Pa, {} snapshots); bed weight / area = {want:.1} Pa; {:+.2}%", r.particles, r.end_s, tail.len(), rel * 100.0);
    json!({"name": "fluidized", "figure": mean, "reference": want, "rel_err": rel, "std_pa": sd, "particles": r.particles, "t_avg_from_s": t_avg, "end_s": r.end_s})
}
