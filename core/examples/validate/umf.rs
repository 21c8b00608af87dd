//! Minimum fluidization by the paper's procedure (section 3.4): U lowered slowly from above U_mf
//! until the pressure drop starts to fall. U_mf is where the fixed-bed branch (ΔP ∝ U through
//! the lowest points) meets the fluidized plateau; reference 0.30 m/s (measured, paper).

use crate::common::*;
use serde_json::json;

pub fn run() -> serde_json::Value {
    let mut case = load_case("bubbling-44mm.json");
    // A narrower, shallower bed than the bubbling case (22 mm, 20 mm settled; the paper's
    // particles and contacts): U_mf is a property of particles and gas, and this is 6× cheaper.
    case.column.diameter_m = 0.022;
    case.column.height_m = 0.066;
    case.grid.dr_m = 0.011 / 3.0;
    case.voidage = fluidbed_core::case::Voidage::SquareGrid { box_side_m: None, split: fluidbed_core::case::BoxSplit::Cuboid, cube_side_factor: 1.0 };
    case.bed = fluidbed_core::case::Bed::Generated(fluidbed_core::case::GeneratedBed { settled_height_m: Some(0.02), count: None, seed: 2 });
    let speeds: Vec<f64> = (0..=12).map(|i| 0.45 - 0.025 * i as f64).collect();
    let (hold, settle) = (0.1, 0.05); // per stage: hold time, of which the first part is discarded
    let g = case.gas.as_mut().unwrap();
    g.superficial_velocity_m_s = speeds[0];
    g.ramp_time_s = 0.05;
    case.outputs.snapshot_interval_s = 0.005;
    case.outputs.fields = vec![fluidbed_core::case::Field::Pressure];
    case.end_time_s = 0.15 + hold * (speeds.len() - 1) as f64;
    let mut sim = fluidbed_core::sim::Simulation::new(case, Some(&bed_cache())).expect("build");
    let n = sim.dem().len();
    let want_weight = bed_weight_per_area(sim.case(), n, sim.case().gas.as_ref().unwrap().outlet_density_kg_m3());
    let mut stage_start = 0.0;
    let mut stage = 0usize;
    let mut acc: Vec<f64> = Vec::new();
    let mut points = Vec::new();
    let first_end = 0.15;
    while !sim.is_finished() {
        let s = match sim.advance(u64::MAX).expect("run") {
            Some(s) => s,
            None => continue,
        };
        let stage_end = if stage == 0 { first_end } else { stage_start + hold };
        if s.time_s > stage_end - (hold - settle) - 1e-9 {
            acc.extend(s.pressure_drop_pa);
        }
        if s.time_s >= stage_end - 1e-9 {
            let dp = acc.iter().sum::<f64>() / acc.len().max(1) as f64;
            eprintln!("U = {:.3} m/s: ΔP = {dp:.1} Pa ({:.3} of bed weight)", speeds[stage], dp / want_weight);
            points.push((speeds[stage], dp));
            acc.clear();
            stage += 1;
            stage_start = stage_end;
            if stage < speeds.len() {
                sim.set_superficial_velocity(speeds[stage]);
            }
        }
    }
    let umf = intersect(&points, want_weight);
    crate::plots::umf_curve(&points, want_weight, umf, "docs/img/umf.png");
    let reference = 0.30;
    eprintln!("{n} particles, bed weight/area {want_weight:.1} Pa: U_mf = {umf:.3} m/s (reference {reference})");
    json!({"name": "umf", "figure": umf, "reference": reference, "rel_err": umf / reference - 1.0, "bed_weight_pa": want_weight,
           "points": points.iter().map(|(u, p)| json!({"u_m_s": u, "dp_pa": p})).collect::<Vec<_>>()})
}

/// Intersection of the plateau (mean of points above 95% of the weight) with the fixed-bed line
/// ΔP = a·U + b·U² fitted (least squares) to the points below 85% of the plateau.
fn intersect(points: &[(f64, f64)], weight: f64) -> f64 {
    let high: Vec<f64> = points.iter().filter(|p| p.1 >= 0.95 * weight).map(|p| p.1).collect();
    let plateau = if high.is_empty() { weight } else { high.iter().sum::<f64>() / high.len() as f64 };
    // the fixed-bed branch: below the lowest fluidized speed only (the first stage, still
    // starting up, can read low too)
    let u_fluid = points.iter().filter(|p| p.1 >= 0.95 * weight).map(|p| p.0).fold(f64::INFINITY, f64::min);
    let low: Vec<(f64, f64)> = points.iter().copied().filter(|p| p.0 < u_fluid && p.1 < 0.85 * plateau).collect();
    // Normal equations for ΔP = a U + b U².
    let (mut s11, mut s12, mut s22, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(u, p) in &low {
        s11 += u * u;
        s12 += u * u * u;
        s22 += u.powi(4);
        r1 += u * p;
        r2 += u * u * p;
    }
    let det = s11 * s22 - s12 * s12;
    let (a, b) = if low.len() >= 2 && det.abs() > 0.0 { ((r1 * s22 - r2 * s12) / det, (s11 * r2 - s12 * r1) / det) } else { (r1 / s11.max(1e-300), 0.0) };
    // Solve a U + b U² = plateau for the positive root.
    if b.abs() < 1e-12 {
        plateau / a
    } else {
        (-a + (a * a + 4.0 * b * plateau).sqrt()) / (2.0 * b)
    }
}
