//! `stress -- dt-sweep`: the largest stable DEM and gas steps, found by bisection, beside the
//! theoretical limits.
//! - Impacts: one sphere of the paper's particles (cases/bubbling-44mm.json) on the plate at
//!   0.3, 1, 3 and 5 m/s. A step is stable when the sphere rebounds with 0 < e ≤ 1 and its
//!   overlap stays below the watchdog's 0.1 d. Theory: AB3's imaginary-axis limit
//!   |λ dt| ≤ 0.7236 at the stiffest point of the contact, λ = √(k(δ_max)/m*) with the Hertz
//!   stiffness k = 2 E* √R* δ^½ at the impact's peak overlap (PHYSICS.md 2.4, 7).
//! - A settled bed: the quickstart bed (4,850 poured particles, E = 10 MPa), 4,000 steps at
//!   rest. A step is stable when the kinetic energy stays below that of every particle at
//!   1 mm/s and the largest overlap below 0.1 d. Theory: the same limit at the bed's largest
//!   pair overlap after settling at the shipped step.
//! - The gas: the 44-mm grid of cases/bubbling-44mm.json with dz = dr and dz = dr/2 around a
//!   packed bed (ε = 0.4 below 30 mm), fed at 0.6 m/s, 3,000 gas steps. A step is stable when
//!   the state stays finite with the density within 0.5–2× the outlet's and |u| < 50 m/s.
//!   Theory: the solver's own acoustic/AB3 bound (`GasSolver::stable_dt` / `gas.cfl_factor`).
//!
//! A JSON line per search, then `{"stress":"dt-sweep",…}` with every figure.

use fluidbed_core::case::Case;
use fluidbed_core::cfd::{GasSolver, AB3_IMAGINARY_LIMIT};
use fluidbed_core::dem::{build_bed, plate_impact, DemSystem};
use fluidbed_core::sim::fluid_grid;
use serde_json::{json, Value};
use std::path::PathBuf;

fn shipped(name: &str) -> Case {
    let path = format!("{}/../cases/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    Case::parse_str(&text).unwrap_or_else(|r| panic!("{path}: {:?}", r.errors)).0
}

/// The largest `dt` in [lo, hi] with `stable(dt)` (lo stable, hi not), to 1% by bisection on a
/// log scale; None if `lo` is unstable.
fn largest_stable(mut lo: f64, mut hi: f64, stable: &mut dyn FnMut(f64) -> bool) -> Option<f64> {
    if !stable(lo) {
        return None;
    }
    if stable(hi) {
        return Some(hi);
    }
    while hi / lo > 1.01 {
        let mid = (lo * hi).sqrt();
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}

/// AB3's limit for a pair (or sphere and plate, `pair = false`) at overlap δ (m).
fn hertz_limit(case: &Case, delta: f64, pair: bool) -> f64 {
    let p = &case.particles;
    let m = case.particle_mass_kg();
    let (m_star, r_star) = if pair { (m / 2.0, p.diameter_m / 4.0) } else { (m, p.diameter_m / 2.0) };
    let e_star = p.youngs_modulus_pa / (2.0 * (1.0 - p.poisson_ratio * p.poisson_ratio));
    let k = 2.0 * e_star * r_star.sqrt() * delta.sqrt();
    AB3_IMAGINARY_LIMIT / (k / m_star).sqrt()
}

fn impacts(case: &Case) -> Vec<Value> {
    let mut out = Vec::new();
    for v0 in [0.3, 1.0, 3.0, 5.0] {
        let mut stable = |dt: f64| {
            let i = plate_impact(case, dt, v0);
            i.rebounded && i.restitution > 0.0 && i.restitution <= 1.0 && i.max_overlap_fraction < 0.1
        };
        let found = largest_stable(1e-8, 1e-4, &mut stable);
        // The peak overlap of a sphere on the plate (m* = m, R* = R), from energy balance.
        let p = &case.particles;
        let e_star = p.youngs_modulus_pa / (2.0 * (1.0 - p.poisson_ratio * p.poisson_ratio));
        let delta =
            (15.0 * case.particle_mass_kg() * v0 * v0 / (16.0 * (p.diameter_m / 2.0).sqrt() * e_star)).powf(0.4);
        let theory = hertz_limit(case, delta, false);
        let accuracy = found.map(|dt| plate_impact(case, dt, v0).restitution);
        let line = json!({"stress": "dt-sweep", "search": "impact", "impact_m_s": v0, "largest_stable_dt_s": found,
            "theory_dt_s": theory, "ratio": found.map(|f| f / theory), "restitution_there": accuracy,
            "shipped_dt_s": case.dem.time_step_s});
        println!("{line}");
        out.push(line);
    }
    out
}

fn settled_bed() -> Value {
    let mut case = shipped("quickstart.json");
    case.gas = None;
    let cache =
        PathBuf::from(std::env::var("FLUIDBED_BED_CACHE").unwrap_or_else(|_| "target/fluidbed-bed-cache".into()));
    let (x, _) = build_bed(&case, Some(&cache)).expect("the quickstart bed pours");
    let n = x.len();
    let m = case.particle_mass_kg();
    // Settle at the shipped step, then read the largest pair overlap.
    let mut sys = DemSystem::new(&case, x.clone(), vec![[0.0; 3]; n]);
    for _ in 0..2000 {
        sys.step();
    }
    let delta = sys.max_overlap_fraction() * case.particles.diameter_m;
    let settled = sys.positions().to_vec();
    let theory = hertz_limit(&case, delta, true);
    let mut stable = |dt: f64| {
        let mut c = case.clone();
        c.dem.time_step_s = dt;
        let mut s = DemSystem::new(&c, settled.clone(), vec![[0.0; 3]; n]);
        for _ in 0..4000 {
            s.step();
        }
        let ke = s.kinetic_energy();
        ke.is_finite() && ke < 0.5 * m * 1e-6 * n as f64 && s.max_overlap_fraction() < 0.1
    };
    let found = largest_stable(case.dem.time_step_s / 4.0, 1e-3, &mut stable);
    let line = json!({"stress": "dt-sweep", "search": "settled_bed", "particles": n, "largest_overlap_d": delta / case.particles.diameter_m,
        "largest_stable_dt_s": found, "theory_dt_s": theory, "ratio": found.map(|f| f / theory),
        "shipped_dt_s": case.dem.time_step_s});
    println!("{line}");
    line
}

fn gas(dz_per_dr: f64) -> Value {
    let mut case = shipped("bubbling-44mm.json");
    case.grid.dz_m = Some(case.grid.dr_m * dz_per_dr);
    let g = case.gas.as_mut().expect("gas");
    g.ramp_time_s = 0.002;
    let grid = fluid_grid(&case);
    let eps: Vec<f64> = (0..grid.num_cells()).map(|c| if grid.centre_xyz(c)[2] < 0.03 { 0.4 } else { 1.0 }).collect();
    let fresh = || {
        let mut s = GasSolver::new(&case, grid.clone());
        s.set_initial_voidage(&eps);
        s
    };
    let cfl = case.gas.as_ref().expect("gas").cfl_factor;
    let theory = fresh().stable_dt() / cfl;
    let rho_out = case.gas.as_ref().expect("gas").outlet_density_kg_m3();
    let mut stable = |dt: f64| {
        let mut s = fresh();
        for k in 0..3000 {
            s.step(dt);
            if k % 100 == 99 && s.check_finite().is_err() {
                return false;
            }
        }
        s.check_finite().is_ok()
            && (0..grid.num_cells()).all(|c| {
                let (rho, u) = (s.density(c), s.velocity_cyl(c));
                (0.5 * rho_out..2.0 * rho_out).contains(&rho) && u.iter().all(|x| x.abs() < 50.0)
            })
    };
    let found = largest_stable(theory / 8.0, theory * 8.0, &mut stable);
    let line = json!({"stress": "dt-sweep", "search": "gas", "dz_over_dr": dz_per_dr, "cells": grid.num_cells(),
        "largest_stable_dt_s": found, "theory_dt_s": theory, "ratio": found.map(|f| f / theory),
        "shipped_dt_s": theory * cfl});
    println!("{line}");
    line
}

pub fn run() {
    let impacts = impacts(&shipped("bubbling-44mm.json"));
    let bed = settled_bed();
    let gas = [gas(1.0), gas(0.5)];
    let pick =
        |v: &Value| json!({"dt_s": v["largest_stable_dt_s"], "theory_dt_s": v["theory_dt_s"], "ratio": v["ratio"]});
    let by_speed: serde_json::Map<String, Value> =
        impacts.iter().map(|v| (format!("{}", v["impact_m_s"]), pick(v))).collect();
    println!(
        "{}",
        json!({"stress": "dt-sweep", "impact": by_speed, "settled_bed": pick(&bed),
            "gas_dz_dr": pick(&gas[0]), "gas_dz_half_dr": pick(&gas[1])})
    );
}
