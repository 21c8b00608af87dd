//! Bubbling statistics (issue: science): the 44-mm bed at U = 0.6 m/s, from the run of `bubbling`
//! (2 simulated seconds, kept in target/validate-cache), its analysis accumulated while it ran
//! from t = 0.4 s: bubbles per second at 30% of the bed height against the paper's 17 bubbles in
//! 2.1 s (section 3.2, ≈ 8.1 per second), beside the ΔP statistics, the rise velocity and the
//! particle-based velocity map on the axial plane (upflow at the centre, downflow at the wall, as
//! the paper's Fig. 7), drawn to docs/img/bubbling_particle_vz.png and docs/img/bubbling_voidage_mean.png;
//! and the gas through the bubbles against the paper's "roughly 1.5 m/s" (section 3.2, Fig. 4),
//! from the run continued past its end (`gas_through_bubbles`).

use fluidbed_core::output::plot;
use fluidbed_core::sim::fluid_grid;
use serde_json::json;

/// The paper's count: 17 bubbles in 2.1 s.
const PAPER_BUBBLES_PER_S: f64 = 17.0 / 2.1;
/// The paper's gas velocity through a bubble (U = 0.6 m/s through ≈ 40% of the cross-section).
const PAPER_BUBBLE_GAS_M_S: f64 = 1.5;
/// How long the run is continued from its last checkpoint to sample the gas in the bubbles.
const GAS_WINDOW_S: f64 = 0.2;
/// A bubble cell: ε above this (as the bubble count); a dense cell: ε below `DENSE`.
const BUBBLE: f64 = 0.8;
const DENSE: f64 = 0.5;

pub fn run() -> serde_json::Value {
    let r = crate::bubbling::run_to(crate::bubbling::end_s());
    let a = r.analysis.expect("the run kept its analysis (rerun `bubbling` if its cache predates it)");
    let grid = fluid_grid(&crate::bubbling::case());
    let per_s = a.bubbles.as_ref().map(|b| b.count.per_second);
    let vz = a.particle_velocity_map.cell_field(&grid);
    let top = vz.iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(v.abs()));
    let title = format!("particle-based ⟨v_z⟩, {:.1}–{:.1} s", a.from_s, a.to_s);
    let labels = plot::FieldLabels { title: &title, quantity: "⟨v_z⟩ [m/s]", lo: -top, hi: top };
    save("docs/img/bubbling_particle_vz.png", plot::axial_slice(&grid, &vz, &labels).expect("map").encode());
    let eps = a.voidage_map.cell_field(&grid);
    let title = format!("time-averaged voidage, {:.1}–{:.1} s", a.from_s, a.to_s);
    let labels = plot::FieldLabels { title: &title, quantity: "⟨ε⟩ [-]", lo: 0.35, hi: 1.0 };
    save("docs/img/bubbling_voidage_mean.png", plot::axial_slice(&grid, &eps, &labels).expect("map").encode());
    // Centre against wall: the mean ⟨v_z⟩ of the inner and the outer annulus over the lower bed.
    let annulus_mean = |i: usize| {
        let h = a.bed_height_m.unwrap_or(0.0);
        let rows: Vec<f64> = (0..grid.nz)
            .filter(|&k| (k as f64 + 0.5) * grid.dz < 0.8 * h)
            .map(|k| a.particle_velocity_map.value[k * grid.nr + i])
            .filter(|v| v.is_finite())
            .collect();
        rows.iter().sum::<f64>() / rows.len().max(1) as f64
    };
    let (centre, wall) = (annulus_mean(0), annulus_mean(grid.nr - 1));
    let figure = per_s.unwrap_or(f64::NAN);
    json!({"name": "bubbling-stats", "figure": figure, "reference": PAPER_BUBBLES_PER_S,
        "rel_err": figure / PAPER_BUBBLES_PER_S - 1.0, "window_s": [a.from_s, a.to_s], "samples": a.samples,
        "bubbles": a.bubbles, "dp_mean_pa": a.pressure_drop.as_ref().map(|p| p.mean_pa),
        "dp_std_pa": a.pressure_drop.as_ref().map(|p| p.std_pa),
        "dp_dominant_hz": a.pressure_drop.as_ref().and_then(|p| p.dominant_frequency_hz),
        "bed_height_m": a.bed_height_m,
        "rise_velocity_m_s": a.rise_velocity.as_ref().and_then(|x| x.voidage.as_ref()).map(|v| v.velocity_m_s),
        "vz_centre_m_s": centre, "vz_wall_m_s": wall,
        "gas_through_bubbles": gas_through_bubbles(a.bed_height_m.unwrap_or(0.03)),
        "paper_bubble_gas_m_s": PAPER_BUBBLE_GAS_M_S})
}

/// The run continued from its last checkpoint for `GAS_WINDOW_S`: at every 5-ms snapshot the
/// interstitial u_z of the bubble cells (ε > 0.8) and the dense cells (ε < 0.5) below 90% of the
/// time-averaged bed height `bed_m`, pooled over the snapshots: their means, the bubble cells'
/// 90th percentile and how many cells of each were seen. Null if the run has not finished.
fn gas_through_bubbles(bed_m: f64) -> serde_json::Value {
    let Some(bytes) = crate::bubbling::kept_checkpoint(crate::bubbling::end_s()) else {
        return serde_json::Value::Null;
    };
    let mut sim = fluidbed_core::sim::Simulation::restore(&bytes).expect("the kept checkpoint restores");
    let t0 = sim.time();
    sim.set_end_time(t0 + GAS_WINDOW_S);
    let g = sim.grid().clone();
    let cells = ((0.9 * bed_m / g.dz).floor() as usize * g.cells_per_layer()).min(g.num_cells());
    let (mut bubble, mut dense, mut snapshots) = (Vec::new(), Vec::new(), 0);
    while !sim.is_finished() {
        let Some(s) = sim.advance(u64::MAX).expect("the continued run") else { continue };
        let eps = s.voidage.as_ref().expect("voidage field");
        let gas = sim.gas().expect("gas");
        for (c, &e) in eps[..cells].iter().enumerate() {
            let uz = gas.velocity_cyl(c)[2];
            if e > BUBBLE {
                bubble.push(uz);
            } else if e < DENSE {
                dense.push(uz);
            }
        }
        snapshots += 1;
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    bubble.sort_by(f64::total_cmp);
    let p90 = bubble.get((0.9 * bubble.len() as f64) as usize).copied();
    json!({"window_s": [t0, sim.time()], "snapshots": snapshots, "bubble_cells": bubble.len(),
        "bubble_uz_mean_m_s": mean(&bubble), "bubble_uz_p90_m_s": p90,
        "dense_cells": dense.len(), "dense_uz_mean_m_s": mean(&dense)})
}

fn save(path: &str, png: Vec<u8>) {
    std::fs::write(path, png).unwrap_or_else(|e| panic!("{path}: {e}"));
}
