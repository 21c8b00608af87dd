//! The gas mass budget of the flux-updated cells: every layer but the characteristic outlet layer,
//! which follows eq. (5)–(7) instead of fluxes (a shut top: every layer). For a conservative scheme
//! M(t) − M(t₀) = ∫ (ṁ_in − ṁ_out) dt exactly, with ṁ_in through the inlet face and ṁ_out through
//! the face into the outlet layer, when the integral is taken with the time step's own weights
//! (Heun, AB2, AB3 on the same right-hand sides). What is left over is round-off, or a flux that
//! is not the same number for the two cells it joins — which the watchdog reports.

use serde::{Deserialize, Serialize};

/// The budget since it was started (on the first step, or when a run resumes from a checkpoint
/// that did not hold it). Carried in the checkpoint's `gas_mass_budget` section.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MassBudget {
    /// Mass of the flux-updated cells at the start (kg); `None` until the first step.
    pub start: Option<f64>,
    /// ∫ (ṁ_in − ṁ_out) dt since the start (kg).
    pub net: f64,
    /// ṁ_in − ṁ_out (kg/s) of the right-hand sides in the solver's history ring (same slots).
    pub hist: [f64; 3],
}

/// Where the budget stands: the mass held now, the change since the start and the net inflow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassBalance {
    pub held: f64,
    pub change: f64,
    pub net_inflow: f64,
}

impl MassBalance {
    /// (in − out − change) as a fraction of the mass held.
    pub fn relative_error(&self) -> f64 {
        (self.net_inflow - self.change) / self.held
    }
}

impl MassBudget {
    /// Balance of the budget for the current mass `held`.
    pub fn balance(&self, held: f64) -> MassBalance {
        let start = self.start.unwrap_or(held);
        MassBalance { held, change: held - start, net_inflow: self.net }
    }
}
