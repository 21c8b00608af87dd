//! Bubbling (issue: coupling): the 44-mm bed at U = 0.6 m/s runs one simulated second with no
//! watchdog stop; voidage maps every 50 ms over the last 0.3 s show the bubbles (cf. paper Fig. 9).

use crate::common::*;
use fluidbed_core::case::Field;
use serde_json::json;

pub fn run() -> serde_json::Value {
    let mut case = load_case("bubbling-44mm.json");
    case.end_time_s = 1.0;
    case.outputs.snapshot_interval_s = 0.005;
    case.outputs.fields = vec![Field::Voidage, Field::Pressure];
    let (sim, snaps) = run_case(case, "bubbling");
    let mut bubble_fraction_max: f64 = 0.0;
    for s in snaps.iter().filter(|s| s.time_s >= 0.7 - 1e-9) {
        let eps = s.voidage.as_ref().unwrap();
        // Cells inside the bed region (below 30 mm) that are nearly empty: bubbles.
        let g = s.grid.grid();
        let k_top = (0.03 / g.dz).floor() as usize;
        let bed: Vec<f64> = eps[..k_top * g.cells_per_layer()].to_vec();
        let f = bed.iter().filter(|&&e| e > 0.8).count() as f64 / bed.len() as f64;
        bubble_fraction_max = bubble_fraction_max.max(f);
        let ms = (s.time_s * 1000.0).round() as i64;
        if ms % 50 == 0 {
            crate::plots::slice(s, eps, 0.35, 1.0, &format!("docs/img/bubbling_voidage_{ms:04}ms.png"));
        }
    }
    crate::plots::pressure_trace(&snaps, "docs/img/bubbling_dp.png", None);
    let tail: Vec<f64> = snaps.iter().filter(|s| s.time_s >= 0.4).filter_map(|s| s.pressure_drop_pa).collect();
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    let want = bed_weight_per_area(sim.case(), sim.dem().len(), sim.case().gas.as_ref().unwrap().outlet_density_kg_m3());
    json!({"name": "bubbling", "figure": mean, "reference": want, "rel_err": mean / want - 1.0,
           "simulated_s": sim.time(), "bubble_cell_fraction_max": bubble_fraction_max, "watchdog_stops": 0})
}
