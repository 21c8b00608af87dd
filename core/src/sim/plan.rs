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
    /// DEM steps per gas step (gas sub-cycled at its own stable step), or 1.
    pub dem_steps_per_gas_step: u64,
    /// Gas sub-steps inside one DEM step when the gas step is the smaller one, or 1.
    pub gas_steps_per_dem_step: u64,
    /// The gas time step actually used.
    pub gas_dt_s: Option<f64>,
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
        let (dem_per_gas, gas_per_dem, gas_dt) = match (gas, gas_stable_dt) {
            (true, Some(stable)) => {
                let user = case.gas.as_ref().and_then(|g| g.time_step_s);
                let target = user.unwrap_or(stable).min(stable);
                if target >= dt {
                    let k = (target / dt).floor().max(1.0) as u64;
                    (k, 1, Some(k as f64 * dt))
                } else {
                    let m = (dt / target).ceil().max(1.0) as u64;
                    (1, m, Some(dt / m as f64))
                }
            }
            _ => (1, 1, None),
        };
        Plan {
            particles_move,
            tangential: particles_move && case.particles.sliding_friction > 0.0,
            gas,
            coupling: gas && n_particles > 0,
            dem_steps_per_gas_step: dem_per_gas,
            gas_steps_per_dem_step: gas_per_dem,
            gas_dt_s: gas_dt,
            voidage_field: case.outputs.fields.contains(&Field::Voidage) || gas,
            particle_field: case.outputs.fields.contains(&Field::Particles),
        }
    }
}
