//! The springs and dashpots of each contact style at an overlap δ (`contact::Style`).

use super::contact::{Coeffs, Stiffness, Style};
use super::real::Real;

/// Hertz normal spring K_n δ^{3/2} with Tsuji damping α_n √(m* K_n) δ^{1/4}; Mindlin tangential
/// spring K_t δ^{1/2} with damping α_t √(m* K_t) δ^{1/4} (PHYSICS.md 2.2–2.3).
pub(crate) struct HertzMindlin;

impl Style for HertzMindlin {
    #[inline(always)]
    fn stiffness<F: Real>(c: &Coeffs<F>, delta: F) -> Stiffness<F> {
        let sd = delta.sqrt();
        let qd = sd.sqrt(); // δ^{1/4} without powf
        Stiffness { elastic: c.kn * delta * sd, eta_n: c.dn * qd, kt: c.kt * sd, eta_t: c.dt * qd }
    }
}

/// Linear spring–dashpot (LAMMPS `gran/hooke/history`): k_n δ, η_n, k_t, η_t constant.
pub(crate) struct LinearSpringDashpot;

impl Style for LinearSpringDashpot {
    #[inline(always)]
    fn stiffness<F: Real>(c: &Coeffs<F>, delta: F) -> Stiffness<F> {
        Stiffness { elastic: c.kn * delta, eta_n: c.dn, kt: c.kt, eta_t: c.dt }
    }
}
