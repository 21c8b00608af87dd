//! Fluidized bed (issue: coupling): the 44-mm bed of 30 mm settled height at U = 0.6 m/s. The
//! time-mean pressure drop across the bed must be within 2% of the bed weight per area less
//! buoyancy (PHYSICS.md 10), plus the gas's own head between the two pressure points. It reads
//! the run of `bubbling` (2 simulated seconds, kept in target/validate-cache), averaging from
//! t = 0.4 s (after the 240-ms ramp and the first bubbles). It also prints the particles' momentum
//! budget over the same window: weight = gas force + plate + tube − d(momentum)/dt.

use crate::common::expected_dp;
use serde_json::json;

pub fn run() -> serde_json::Value {
    let r = crate::bubbling::run_to(crate::bubbling::end_s());
    let t_avg = 0.4;
    let tail: Vec<f64> = r.dp.iter().filter(|(t, _)| *t >= t_avg).map(|x| x.1).collect();
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    let sd = (tail.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / tail.len() as f64).sqrt();
    let case = crate::bubbling::case();
    let (weight, head) = expected_dp(&case, r.particles);
    let want = weight + head;
    let rel = mean / want - 1.0;
    eprintln!("{} particles; mean ΔP over {t_avg} ≤ t ≤ {} s = {mean:.1} Pa (σ = {sd:.1} Pa, {} snapshots); bed weight / area less buoyancy {weight:.1} Pa + gas head {head:.2} Pa = {want:.1} Pa; {:+.2}%", r.particles, r.end_s, tail.len(), rel * 100.0);
    let window: Vec<(f64, f64)> = r.dp.iter().copied().filter(|x| x.0 >= t_avg).collect();
    crate::plots::dp_with_level(&window, want, "docs/img/fluidized_dp.png");
    let mut out = json!({"name": "fluidized", "figure": mean, "reference": want, "rel_err": rel, "std_pa": sd, "bed_weight_pa": weight, "gas_head_pa": head, "particles": r.particles, "t_avg_from_s": t_avg, "end_s": r.end_s});
    let b: Vec<&[f64; 5]> = r.budget.iter().filter(|x| x[0] >= t_avg).collect();
    if b.len() > 1 {
        // shares of the weight N m g, time means over the window
        let weight = r.particles as f64 * case.particle_mass_kg() * case.gravity_m_s2;
        let share = |k: usize| b.iter().map(|x| x[k]).sum::<f64>() / b.len() as f64 / weight;
        let (first, last) = (b[0], b[b.len() - 1]);
        let inertia = (last[4] - first[4]) / (last[0] - first[0]) / weight;
        let (gas, plate, tube) = (share(3), share(1), share(2));
        eprintln!("share of the particles' weight carried, mean over the window: gas {gas:.4}, plate {plate:.4}, tube {tube:.4}; momentum change {inertia:+.4}; unbalanced {:+.4}", gas + plate + tube - inertia - 1.0);
        out["weight_share"] = json!({"gas": gas, "plate": plate, "tube": tube, "momentum_change": inertia});
        let plate_series: Vec<(f64, f64)> = b.iter().map(|x| (x[0], x[1] / weight)).collect();
        let labels = crate::plots::TraceLabels {
            title: "Share of the bed's weight carried by the distributor (mean in red)",
            x: "time t [s]",
            y: "plate force / bed weight [-]",
        };
        crate::plots::series_with_level(&plate_series, plate, &labels, "docs/img/fluidized_plate_share.png");
    }
    out
}
