//! The plan: which parts of the solver a scene needs. Decided once from the case and recorded in
//! the job's metadata; each skip is exact (the same answer, not an approximation).

use crate::case::{Case, Field};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Plan {
    /// Contact detection and particle integration run (false: frozen bed or no particles).
    pub particles_move: bool,
    /// Tangential history and rotation (false when μ = 0: frictionless spheres never spin).
    pub tangential: bool,
    /// The gas solver runs.
    pub gas: bool,
    /// Voidage, drag and the force exchange run (gas and particles both present).
    pub coupling: bool,
    /// The gas time step actually used: its own stable step (or the case's, if smaller), made a
    /// whole fraction of the coupling interval when that interval is longer (`aligned_gas_dt`);
    /// not a multiple of the DEM step; the gas steps whenever the DEM would pass its time
    /// (coupled.rs).
    pub gas_dt_s: Option<f64>,
    /// Gas steps per DEM step on average (gas_dt / DEM dt inverted; below 1 the gas is sub-cycled
    /// at the larger step).
    pub gas_steps_per_dem_step: f64,
    /// DEM steps between recomputations of voidage and drag (the case's `coupling.interval_steps`).
    pub coupling_interval: u64,
    /// A voidage field is computed for snapshots (requested and a grid exists).
    pub voidage_field: bool,
    /// Particle positions go into snapshots.
    pub particle_field: bool,
}

impl Plan {
    pub fn for_case(case: &Case, n_particles: usize, gas_stable_dt: Option<f64>) -> Plan {
        let dt = case.dem.time_step_s;
        let particles_move = n_particles > 0 && !case.dem.frozen;
        let gas = case.gas.is_some();
        let gas_dt = match (gas, gas_stable_dt) {
            (true, Some(stable)) => {
                let user = case.gas.as_ref().and_then(|g| g.time_step_s);
                let cap = user.unwrap_or(stable).min(stable);
                let held = n_particles > 0 && case.coupling.interval_steps > 1;
                Some(if held { aligned_gas_dt(cap, case.coupling.interval_steps as f64 * dt) } else { cap })
            }
            _ => None,
        };
        Plan {
            particles_move,
            tangential: particles_move && case.particles.sliding_friction > 0.0,
            gas,
            coupling: gas && n_particles > 0,
            gas_dt_s: gas_dt,
            gas_steps_per_dem_step: gas_dt.map_or(0.0, |g| dt / g),
            coupling_interval: case.coupling.interval_steps.max(1) as u64,
            voidage_field: case.outputs.fields.contains(&Field::Voidage) || gas,
            particle_field: case.outputs.fields.contains(&Field::Particles),
        }
    }
}

/// The gas step for forces held over coupling intervals of `interval_s`: the largest step not
/// above `cap` that divides the interval into whole steps, when the interval is at least `cap`.
/// Each interval's held voidage and force then act on the gas for exactly the interval: with
/// steps that straddle the couplings the share of the interval each gas step sees beats against
/// the coupling rate, which drove a 15-kHz ΔP oscillation of 10 Pa r.m.s. on the 22-mm bed
/// (docs/VALIDATION.md, "Gas steps in whole fractions of the coupling interval").
pub fn aligned_gas_dt(cap: f64, interval_s: f64) -> f64 {
    if interval_s < cap {
        return cap;
    }
    interval_s / (interval_s / cap).ceil()
}

/// The gas steps that bring the gas to `dem_steps` DEM steps of `dt` with steps of `dt_g`:
/// ⌈dem_steps·dt/dt_g⌉, a count within 1e-6 of a whole number taken as that number (aligned
/// steps land on whole numbers up to rounding).
pub fn gas_steps_due(dem_steps: u64, dt: f64, dt_g: f64) -> u64 {
    let x = dem_steps as f64 * dt / dt_g;
    let whole = x.round();
    if (x - whole).abs() < 1e-6 {
        whole.max(0.0) as u64
    } else {
        x.ceil().max(0.0) as u64
    }
}

impl Plan {
    /// Each part of the solver this plan does not run, and why (for the job's status).
    pub fn skipped(&self, case: &Case) -> Vec<String> {
        let mut out = Vec::new();
        if !self.particles_move {
            out.push(if case.dem.frozen {
                "contacts and particle integration: the bed is frozen (dem.frozen)".to_string()
            } else {
                "contacts and particle integration: no particles".to_string()
            });
        } else if !self.tangential {
            out.push("tangential history and spin: frictionless particles (particles.sliding_friction = 0)".into());
        }
        if !self.gas {
            out.push("gas solver: the case has no gas section".into());
        } else if let Some(g) = self.gas_dt_s.filter(|_| self.gas_steps_per_dem_step < 1.0) {
            out.push(format!(
                "gas steps: sub-cycled at {:.3} µs (stable, in whole fractions of a longer coupling interval), {:.2} gas steps per DEM step",
                g * 1e6,
                self.gas_steps_per_dem_step
            ));
        }
        if self.gas && !self.coupling {
            out.push("voidage, drag and exchange: no particles".into());
        } else if self.coupling && !self.particles_move {
            out.push("voidage and drag per particle: the frozen bed's voidage is computed once and the exchange per cell (O(cells))".into());
        } else if self.coupling && self.coupling_interval > 1 {
            let gas = match case.coupling.gas_voidage {
                crate::case::GasVoidage::Held => "held",
                crate::case::GasVoidage::Interpolated => "interpolated",
                crate::case::GasVoidage::Extrapolated => "extrapolated",
            };
            let pressure = match case.coupling.pressure_force {
                crate::case::PressureForce::Held => "held with it",
                crate::case::PressureForce::GasStep => "following the gas at each of its steps",
                crate::case::PressureForce::IntervalMean => "held at the mean of the gas's over the last interval",
            };
            out.push(format!(
                "voidage and drag: recomputed every {} DEM steps (coupling.interval_steps), the drag held in between, the particles' pressure force {pressure} (coupling.pressure_force) and the gas's voidage {gas} (coupling.gas_voidage)",
                self.coupling_interval
            ));
        }
        if !self.voidage_field {
            out.push("voidage field in snapshots: not in outputs.fields".into());
        }
        if !self.particle_field {
            out.push("particle positions in snapshots: not in outputs.fields".into());
        }
        out
    }
}
