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

/// How the gas steps in time (`gas.time_scheme`; forward_backward.rs).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum TimeScheme {
    /// The paper's: Heun → AB2 → AB3 on the whole right-hand side (PHYSICS.md 7).
    Ab3,
    /// Forward–backward for the acoustic terms (the pressure force forward, the mass fluxes of the
    /// new momentum backward), AB3 for the rest: a stable step 2.07× AB3's (stability.rs). The
    /// default: against the paper's every-step coupling it is as accurate as AB3 at the same
    /// coupling interval (docs/VALIDATION.md "Forward–backward gas step").
    #[default]
    ForwardBackward,
}

impl TimeScheme {
    pub fn is_default(&self) -> bool {
        *self == TimeScheme::default()
    }
}
