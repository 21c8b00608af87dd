//! Minimum fluidization by the paper's procedure (section 3.4): "U was slowly decreased from
//! above U_mf until the pressure drop across the bed began to decrease". The bed is fluidized at
//! 0.45 m/s (1.5× the measured U_mf), then U is lowered in steps of 0.025 m/s, each held 0.1 s.
//! U_mf is where the fixed-bed branch (ΔP = aU + bU² through the points below the plateau)
//! meets the plateau; reference 0.30 m/s (measured, paper). Default bed: the paper's particles
//! in a 22-mm column, 20 mm settled (6× cheaper than the paper's 44-mm, 30-mm bed), with fluid
//! layers half as tall as the cells are wide (dz = dr/2 = 1.83 mm = 1.5 d): with dz = dr the
//! partly filled cell at the bed surface leaves ~10% of the bed's weight with a third of its
//! drag and U_mf comes out 20% high (docs/VALIDATION.md).
//! `FLUIDBED_UMF="column_mm=44,height_mm=30,seed=1,start=0.36,step=0.02,stages=8"` changes the
//! bed and the sweep (any subset of the keys; also `hold`, seconds per stage, and `dz_over_dr`,
//! the fluid layer height over the radial spacing, and `sublayers`, the case's
//! `coupling.drag_voidage_sublayers`, and `pressure_gas_step` or `pressure_mean`, 1 for the
//! case's `coupling.pressure_force` "gas_step" or "interval_mean", 0 for the case's own, and
//! `interval`, the case's `coupling.interval_steps`, and `density`, the particles' density, the
//! DEM step scaled with it as the Hertz contact time, ρ^(2/5)).
//! `umf-paper-cells` runs the same sweep with dz = dr, the drag voidage on 8 sub-layers per cell
//! and the pressure force following the gas.

use crate::common::*;
use fluidbed_core::case::PressureForce;
use serde_json::json;

/// The sweep and bed, from `FLUIDBED_UMF` over the defaults.
struct Sweep {
    column_mm: f64,
    height_mm: f64,
    seed: u64,
    start: f64,
    step: f64,
    stages: usize,
    hold: f64,
    /// Fluid layer height over the radial spacing (1 = the paper's cells, dz = dr).
    dz_over_dr: f64,
    /// `coupling.drag_voidage_sublayers` (None: the case's).
    sublayers: Option<u32>,
    /// `coupling.pressure_force` (None: the case's).
    pressure_force: Option<PressureForce>,
    /// `gas.time_scheme` "ab3", the paper's (else the case's).
    ab3: bool,
    /// `coupling.interval_steps` (None: the case's).
    interval: Option<u32>,
    /// The particles' density (kg/m³; None: the case's), the DEM step scaled with the Hertz
    /// contact time, which goes as ρ^(2/5).
    density: Option<f64>,
    /// The gas's voidage and the drag on it held between couplings (`coupling.gas_voidage` and
    /// `gas_drag` "held"; else the case's).
    gas_held: bool,
}

impl Sweep {
    /// The shipped sweep: layers half as tall as the cells are wide.
    fn shipped() -> Sweep {
        Sweep {
            column_mm: 22.0,
            height_mm: 20.0,
            seed: 2,
            start: 0.45,
            step: 0.025,
            stages: 11,
            hold: 0.1,
            dz_over_dr: 0.5,
            sublayers: None,
            pressure_force: None,
            ab3: false,
            interval: None,
            density: None,
            gas_held: false,
        }
    }

    /// `base` with the keys of `FLUIDBED_UMF` over it.
    fn from_env(base: Sweep) -> Sweep {
        let mut s = base;
        for kv in std::env::var("FLUIDBED_UMF").unwrap_or_default().split(',').filter(|t| !t.is_empty()) {
            let (k, v) = kv.split_once('=').unwrap_or_else(|| panic!("FLUIDBED_UMF: '{kv}' is not key=value"));
            let x: f64 = v.parse().unwrap_or_else(|_| panic!("FLUIDBED_UMF: '{v}' is not a number"));
            match k {
                "column_mm" => s.column_mm = x,
                "height_mm" => s.height_mm = x,
                "seed" => s.seed = x as u64,
                "start" => s.start = x,
                "step" => s.step = x,
                "stages" => s.stages = x as usize,
                "hold" => s.hold = x,
                "dz_over_dr" => s.dz_over_dr = x,
                "sublayers" => s.sublayers = Some(x as u32),
                "pressure_gas_step" => s.pressure_force = (x != 0.0).then_some(PressureForce::GasStep),
                "pressure_mean" => s.pressure_force = (x != 0.0).then_some(PressureForce::IntervalMean),
                "ab3" => s.ab3 = x != 0.0,
                "interval" => s.interval = Some(x as u32),
                "density" => s.density = Some(x),
                _ => panic!("FLUIDBED_UMF: unknown key '{k}' (column_mm, height_mm, seed, start, step, stages, hold, dz_over_dr, sublayers, pressure_gas_step, pressure_mean, ab3, interval, density)"),
            }
        }
        s
    }
}

pub fn run() -> serde_json::Value {
    sweep(Sweep::from_env(Sweep::shipped()), "umf", "docs/img/umf.png")
}

/// The same sweep on the paper's cells (dz = dr) with the drag voidage on 8 sub-layers per cell
/// (`coupling.drag_voidage_sublayers`) and the particles' pressure force held at the mean of the
/// gas's gradient over the last interval (`coupling.pressure_force` = "interval_mean": the pressure
/// impulse the gas felt, one interval late), as `cases/bubbling-44mm-paper-cells.json`, with which
/// the fluidized bed on these cells also meets its target (docs/VALIDATION.md "U_mf with the
/// paper's cells" and "The pressure force between couplings"), at a coupling interval of 10 (at
/// 20 this sweep reads +5.9%) with the gas's voidage and drag held between couplings.
pub fn run_paper_cells() -> serde_json::Value {
    let base = Sweep {
        dz_over_dr: 1.0,
        sublayers: Some(8),
        pressure_force: Some(PressureForce::IntervalMean),
        interval: Some(10),
        gas_held: true,
        ..Sweep::shipped()
    };
    sweep(Sweep::from_env(base), "umf-paper-cells", "docs/img/umf_paper_cells.png")
}

fn sweep(sw: Sweep, name: &str, docs_png: &str) -> serde_json::Value {
    let mut case = load_case("bubbling-44mm.json");
    if sw.column_mm != 44.0 {
        // a narrower column: keep three rings per radius
        case.column.diameter_m = sw.column_mm / 1000.0;
        case.grid.dr_m = case.column.diameter_m / 2.0 / 3.0;
        // (the shipped case's voidage: its boxes and cube are set by d, not by the column)
    }
    if let Some(how) = sw.pressure_force {
        case.coupling.pressure_force = how;
    }
    if let Some(n) = sw.sublayers {
        case.coupling.drag_voidage_sublayers = n;
    }
    if let Some(n) = sw.interval {
        case.coupling.interval_steps = n;
    }
    if sw.gas_held {
        case.coupling.gas_voidage = fluidbed_core::case::GasVoidage::Held;
        case.coupling.gas_drag = fluidbed_core::case::GasDrag::Held;
    }
    if sw.ab3 {
        case.gas.as_mut().expect("gas").time_scheme = fluidbed_core::cfd::TimeScheme::Ab3;
    }
    if let Some(rho) = sw.density {
        case.dem.time_step_s *= (rho / case.particles.density_kg_m3).powf(0.4);
        case.particles.density_kg_m3 = rho;
    }
    let dz = sw.dz_over_dr * case.grid.dr_m;
    case.grid.dz_m = Some(dz);
    let layers = case.column.height_m / dz;
    if sw.column_mm != 44.0 || sw.height_mm != 30.0 || (layers - layers.round()).abs() > 1e-9 {
        // a column three bed heights tall (at least 66 mm), a whole number of layers
        case.column.height_m = ((3.0 * sw.height_mm / 1000.0).max(0.066) / dz).round() * dz;
    }
    case.bed = fluidbed_core::case::Bed::Generated(fluidbed_core::case::GeneratedBed {
        settled_height_m: Some(sw.height_mm / 1000.0),
        count: None,
        seed: sw.seed,
    });
    let speeds: Vec<f64> = (0..sw.stages).map(|i| sw.start - sw.step * i as f64).collect();
    let (hold, settle) = (sw.hold, sw.hold / 2.0); // per stage: hold time, of which the first half is discarded
    let g = case.gas.as_mut().unwrap();
    g.superficial_velocity_m_s = speeds[0];
    g.ramp_time_s = 0.05;
    case.outputs.snapshot_interval_s = 0.005;
    case.outputs.fields = vec![fluidbed_core::case::Field::Pressure];
    case.end_time_s = 0.15 + hold * (speeds.len() - 1) as f64;
    let pressure_force = case.coupling.pressure_force;
    let mut sim = fluidbed_core::sim::Simulation::new(case, Some(&bed_cache())).expect("build");
    let n = sim.dem().len();
    let want_weight = bed_weight_per_area(sim.case(), n, sim.case().gas.as_ref().unwrap().outlet_density_kg_m3());
    let mut stage_start = 0.0;
    let mut stage = 0usize;
    let mut acc: Vec<f64> = Vec::new();
    let mut points = Vec::new();
    let mut voidages = Vec::new();
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
            let eps = core_voidage(&sim);
            eprintln!(
                "U = {:.3} m/s: ΔP = {dp:.1} Pa ({:.3} of bed weight), bed voidage {eps:.3}",
                speeds[stage],
                dp / want_weight
            );
            points.push((speeds[stage], dp));
            voidages.push(eps);
            acc.clear();
            stage += 1;
            stage_start = stage_end;
            if stage < speeds.len() {
                sim.set_superficial_velocity(speeds[stage]);
            }
        }
    }
    let umf = intersect(&points, want_weight);
    // A sweep other than the shipped one draws its curve under target/, not over the docs' figure.
    let png = match std::env::var("FLUIDBED_UMF") {
        Ok(v) if !v.is_empty() => format!("target/umf-{}.png", v.replace([',', '='], "_")),
        _ => docs_png.to_string(),
    };
    crate::plots::umf_curve(&points, want_weight, umf, &png);
    let reference = 0.30;
    eprintln!("{n} particles, bed weight/area {want_weight:.1} Pa: U_mf = {umf:.3} m/s (reference {reference})");
    json!({"name": name, "figure": umf, "dz_over_dr": sw.dz_over_dr, "drag_voidage_sublayers": sw.sublayers.unwrap_or(1), "pressure_force": pressure_force, "reference": reference, "rel_err": umf / reference - 1.0, "bed_weight_pa": want_weight, "bed_voidage": voidages,
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
    let (a, b) = if low.len() >= 2 && det.abs() > 0.0 {
        ((r1 * s22 - r2 * s12) / det, (s11 * r2 - s12 * r1) / det)
    } else {
        (r1 / s11.max(1e-300), 0.0)
    };
    // Solve a U + b U² = plateau for the positive root.
    if b.abs() < 1e-12 {
        plateau / a
    } else {
        (-a + (a * a + 4.0 * b * plateau).sqrt()) / (2.0 * b)
    }
}

/// Voidage of the bed's core: particle volume between one diameter above the plate and one
/// below the bed top, over the column's cross-section (wall zone included).
fn core_voidage(sim: &fluidbed_core::sim::Simulation) -> f64 {
    use fluidbed_core::coupling::voidage::sphere_box::sphere_slab_volume;
    let r = sim.dem().radius();
    let (lo, hi) = (2.0 * r, bed_top_m(sim) - 2.0 * r);
    let solid: f64 = sim.dem().positions().iter().map(|p| sphere_slab_volume(p[2], r, lo, hi)).sum();
    let area = std::f64::consts::PI * (sim.case().column.diameter_m / 2.0).powi(2);
    1.0 - solid / (area * (hi - lo))
}
