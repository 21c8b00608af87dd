//! The springs and dashpots of each contact style at an overlap δ (`Style`), which the one
//! contact law (`contact::law_force`) is generic over.

use super::real::Real;

/// `ContactLaw`'s prefactors in the float type F.
#[derive(Clone, Copy)]
pub(crate) struct Coeffs<F> {
    pub kn: F,
    pub dn: F,
    pub kt: F,
    pub dt: F,
    pub mu: F,
    pub no_tension: bool,
}

/// Springs and dashpots of a style at overlap δ: F_n = elastic + η_n dδ/dt, F_t = −k_t ξ − η_t v_t.
pub(crate) struct Stiffness<F> {
    pub elastic: F,
    pub eta_n: F,
    pub kt: F,
    pub eta_t: F,
}

/// A contact style: its springs and dashpots at an overlap.
pub(crate) trait Style {
    fn stiffness<F: Real>(c: &Coeffs<F>, delta: F) -> Stiffness<F>;
}

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
