//! One sphere of the case's particles hitting the distributor plate head-on at a given speed,
//! without gravity: the measured normal restitution and the largest overlap of the impact. The
//! DEM step's accuracy (`bench -- restitution`) and stability (`stress -- dt-sweep`) at that speed.

use super::DemSystem;
use crate::case::{Bed, Case, ExplicitBed};

#[derive(Clone, Copy, Debug)]
pub struct Impact {
    /// Rebound speed over impact speed (NaN if the state was not finite).
    pub restitution: f64,
    /// Largest overlap with the plate as a fraction of d.
    pub max_overlap_fraction: f64,
    /// Whether the sphere left the plate again within the step budget.
    pub rebounded: bool,
}

/// Drop the sphere from 10 steps' flight above the plate at `v0` and step at `dt` until it has
/// been clear of the plate for 5 steps (at most 10⁶ steps).
pub fn plate_impact(case: &Case, dt: f64, v0: f64) -> Impact {
    let mut c = case.clone();
    c.gravity_m_s2 = 0.0;
    c.gas = None;
    c.column.diameter_m = 0.02;
    c.column.height_m = 0.04;
    c.dem.time_step_s = dt;
    let r = c.particles.diameter_m / 2.0;
    let start = [0.0, 0.0, r + 10.0 * v0 * dt];
    c.bed = Bed::Explicit(ExplicitBed { positions_m: vec![start], velocities_m_s: None });
    let mut sys = DemSystem::new(&c, vec![start], vec![[0.0, 0.0, -v0]]);
    let (mut touched, mut apart, mut deepest) = (false, 0, 0.0f64);
    for _ in 0..1_000_000 {
        sys.step();
        let sep = sys.positions()[0][2] - r;
        if !sep.is_finite() {
            break;
        }
        deepest = deepest.max(-sep);
        touched |= sep < 0.0;
        apart = if touched && sep > 0.0 { apart + 1 } else { 0 };
        if apart == 5 {
            break;
        }
    }
    Impact {
        restitution: sys.velocities()[0][2] / v0,
        max_overlap_fraction: deepest / c.particles.diameter_m,
        rebounded: apart == 5,
    }
}
