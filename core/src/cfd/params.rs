//! The gas parameters and the top boundary, read by the solver and by its right-hand side.

use serde::{Deserialize, Serialize};

/// Top boundary of the gas.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub enum Outlet {
    /// Characteristic outlet of the paper's eq. (5)–(7) (PHYSICS.md 9), optional relaxation σ.
    Characteristic,
    /// A shut top: full-slip wall (tests: closed column, fully reflecting end).
    Wall,
}

/// Gas parameters in SI units, taken from the case's `gas` section.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GasParams {
    pub sound_speed: f64,
    pub viscosity: f64,
    pub bulk_viscosity: f64,
    pub gravity: f64,
    pub superficial_velocity: f64,
    pub ramp_time: f64,
    pub inlet_voidage: f64,
    pub outlet_relaxation: f64,
    pub outlet_pressure: f64,
    pub cfl_factor: f64,
    pub outlet: Outlet,
}
