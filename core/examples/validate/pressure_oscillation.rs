//! Pressure oscillation and bubble eruptions (issue: science, paper section 3.4 and Fig. 9: "the
//! period of oscillations in pressure drop matches the period of time taken for a pair of bubbles
//! to erupt at the top of the bed"). The paper's bed (50 mm, 110 mm settled, ≈ 150k particles for
//! several seconds) does not fit a session on 2 cores, so this reads beds that do:
//! - the 44-mm bubbling bed at 0.6 m/s (the run of `bubbling`, 2 simulated s);
//! - the 160-mm slugging beds of `slug-rise` at 0.54 and 0.60 m/s (1.8 and 2 U_mf, beside the
//!   paper's 0.563 m/s), in the paper's 50-mm tube and in the 44-mm one,
//!
//! each where its run has finished: this never starts them (each is an hour or more).
//!
//! Each run's analysis (accumulated while it ran) gives ΔP's dominant frequency, the eruptions at
//! 0.9 of the bed height per second and their ratio, the dominant frequency of the bed surface's
//! height (which falls once per eruption) and ΔP's over it (ΔP cycles per eruption: ½ is the
//! paper's pair), and ΔP averaged around the eruptions (`analysis::eruption_link`), drawn to
//! docs/img/pressure_oscillation_*.png. Last line: the slugging beds' ΔP cycles per surface cycle
//! against the paper's ½ (the bubbling bed's where no slugging run has finished, with no reference).

use crate::plots::{series_with_level, TraceLabels};
use fluidbed_core::sim::AnalysisReport;
use serde_json::{json, Value};

/// ΔP cycles per eruption in the paper's slugging bed: one ΔP period per pair of eruptions.
const PAPER_CYCLES_PER_ERUPTION: f64 = 0.5;

fn point(label: &str, a: &AnalysisReport, png: &str) -> Value {
    let dp = a.pressure_drop.as_ref();
    let e = a.eruptions.as_ref();
    if let Some(e) = e {
        let pts: Vec<(f64, f64)> = e.link.lag_s.iter().copied().zip(e.link.triggered_dp_pa.iter().copied()).collect();
        let title = format!("{label}: ΔP around {} eruptions at {:.0} mm", e.link.averaged, 1e3 * e.fronts.height_m);
        let labels =
            TraceLabels { title: &title, x: "time from eruption τ [s]", y: "ΔP(t_e + τ) − mean ΔP [Pa]" };
        series_with_level(&pts, 0.0, &labels, png);
    }
    json!({"bed": label, "window_s": [a.series_from_s, a.to_s], "samples": a.series_samples,
        "dp_mean_pa": dp.map(|p| p.mean_pa), "dp_std_pa": dp.map(|p| p.std_pa),
        "dp_dominant_hz": dp.and_then(|p| p.dominant_frequency_hz), "bed_height_m": a.bed_height_m,
        "eruption_height_m": e.map(|e| e.fronts.height_m), "eruptions_per_s": e.map(|e| e.fronts.count.per_second),
        "dp_cycles_per_eruption": e.and_then(|e| e.dp_frequency_per_eruption),
        "surface_hz": e.and_then(|e| e.surface_frequency_hz),
        "dp_cycles_per_surface_cycle": e.and_then(|e| e.dp_frequency_per_surface_cycle),
        "swing_pa": e.map(|e| e.link.swing_pa), "lag_of_dp_max_s": e.map(|e| e.link.lag_of_max_s),
        "lag_of_dp_min_s": e.map(|e| e.link.lag_of_min_s)})
}

pub fn run() -> Value {
    let kept = crate::bubbling::kept_checkpoint(crate::bubbling::end_s());
    let analysis = kept.and_then(|b| fluidbed_core::sim::Simulation::analysis_of_checkpoint(&b, None).ok());
    let bubbling = match analysis {
        Some((_, _, a)) => point("44-mm bed, 30 mm settled, U = 0.6 m/s", &a, "docs/img/pressure_oscillation_44mm.png"),
        None => {
            eprintln!("[pressure-oscillation] the `bubbling` run of this build has not finished; not read");
            json!({"bed": "44-mm bed, 30 mm settled, U = 0.6 m/s", "dp_cycles_per_eruption": null})
        }
    };
    println!("{bubbling}");
    // The paper's 50-mm tube first (its Fig. 9 bed is 50 mm wide), then the 44-mm one; the figure
    // is the paper tube's where one of its runs has finished.
    let mut by_tube = Vec::new();
    for tube in [crate::slug_rise::PAPER_TUBE, crate::slug_rise::BUBBLING_TUBE] {
        let (mut points, mut speeds) = (Vec::new(), Vec::new());
        for u in [0.54, 0.60] {
            match crate::slug_rise::finished_at(u, tube) {
                Some(done) => {
                    let p = point(
                        &format!("{}-mm bed, 160 mm settled, U = {u} m/s", tube.mm),
                        &done.analysis,
                        &format!("docs/img/pressure_oscillation_slug{}_U{u}.png", tube.mm),
                    );
                    println!("{p}");
                    points.push(p);
                    speeds.push(format!("{u} m/s"));
                }
                None => eprintln!(
                    "[pressure-oscillation] the {}-mm slug-rise run at U = {u} m/s has not finished; not read",
                    tube.mm
                ),
            }
        }
        by_tube.push((format!("{}-mm slugging beds at {}", tube.mm, speeds.join(", ")), points));
    }
    let (beds, slugging) = by_tube.into_iter().find(|(_, p)| !p.is_empty()).unwrap_or_default();
    let mean_of = |key: &str| {
        let v: Vec<f64> = slugging.iter().filter_map(|p| p[key].as_f64()).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    match mean_of("dp_cycles_per_surface_cycle") {
        None => json!({"name": "pressure-oscillation", "figure": bubbling["dp_cycles_per_surface_cycle"],
            "reference": null, "rel_err": null, "bed": bubbling["bed"]}),
        Some(figure) => {
            json!({"name": "pressure-oscillation", "figure": figure, "reference": PAPER_CYCLES_PER_ERUPTION,
            "rel_err": figure / PAPER_CYCLES_PER_ERUPTION - 1.0, "dp_cycles_per_counted_eruption": mean_of("dp_cycles_per_eruption"),
            "bed": beds,
            "note": "ΔP's dominant frequency over the bed surface's (one surface fall per eruption), both over the whole window"})
        }
    }
}
