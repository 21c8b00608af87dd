//! Drag laws (paper section 2.3; PHYSICS.md 1 and 11), as named styles chosen in the case
//! (`"drag": {"law": "beetstra"}`). Every law is written in one dimensionless form, normalised by
//! Stokes drag at the cell's voidage:
//!     F_d = 3πμ d ε F(ε, Re) (u − v),   Re = ρ_g ε |u − v| d / μ   (model A, PHYSICS.md 11),
//! so the exchange's per-cell factors (3πμdε, ρε d/μ) are shared and a law supplies only F. Each
//! law gives F twice from one formula: `f` with libm (the published form, for tests and the
//! O(cells) frozen-bed path) and `f_cell` from factors that depend on the cell only (`cell`), with
//! the fast powers of `fast_math` (relative difference ≲ 1e-13, tested per law).

mod beetstra;
mod di_felice;
mod gidaspow;

pub use beetstra::{beetstra_f, beta_a, Beetstra};
pub use di_felice::DiFelice;
pub use gidaspow::Gidaspow;

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Below this Reynolds number the Re-dependent parts of a law are dropped (powers of Re with
/// negative exponents diverge while their products with Re vanish).
pub const RE_GUARD: f64 = 1e-12;

/// A drag law: F(ε, Re) of the module comment.
pub trait DragLaw: Copy + Send + Sync {
    /// Everything in F that depends on ε alone.
    type Cell: Copy + Default + Send + Sync;
    /// F(ε, Re) as published (libm).
    fn f(&self, eps: f64, re: f64) -> f64;
    /// The factors of a cell of voidage `eps` (already clamped to [ε_min, 1)).
    fn cell(&self, eps: f64) -> Self::Cell;
    /// F at `re` from a cell's factors; branch-free so that a block of particles vectorises.
    fn f_cell(c: &Self::Cell, re: f64) -> f64;
}

/// The drag law a case names.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum DragModel {
    /// Beetstra, van der Hoef & Kuipers (2007), the paper's law (PHYSICS.md 1.1).
    #[default]
    Beetstra,
    /// Gidaspow (1994) as MFiX's GIDASPOW and CFDEM's GidaspowDrag: Ergun (1952) for ε ≤ 0.8,
    /// Wen & Yu (1966) above.
    Gidaspow,
    /// Di Felice (1994), as CFDEM's DiFeliceDrag.
    DiFelice,
}

impl DragModel {
    pub fn name(self) -> &'static str {
        match self {
            DragModel::Beetstra => "beetstra",
            DragModel::Gidaspow => "gidaspow",
            DragModel::DiFelice => "di_felice",
        }
    }
    /// F(ε, Re) of the law (libm; for tests and per-cell use).
    pub fn f(self, eps: f64, re: f64) -> f64 {
        match self {
            DragModel::Beetstra => Beetstra.f(eps, re),
            DragModel::Gidaspow => Gidaspow.f(eps, re),
            DragModel::DiFelice => DiFelice.f(eps, re),
        }
    }
}

/// Model-A drag on one particle with ε clamped to [eps_min, 1): F_d = 3πμ d ε F(ε, Re) (u − v),
/// `slip` = u − v (interstitial gas minus particle).
pub fn drag_force(law: DragModel, mu: f64, rho_g: f64, d: f64, eps: f64, eps_min: f64, slip: [f64; 3]) -> [f64; 3] {
    let eps = clamp_voidage(eps, eps_min);
    let w = (slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2]).sqrt();
    let re = rho_g * eps * w * d / mu;
    let c = 3.0 * PI * mu * d * eps * law.f(eps, re);
    [c * slip[0], c * slip[1], c * slip[2]]
}

/// ε as the drag laws see it: clamped to [eps_min, 1 − ε_machine] (PHYSICS.md 1.1).
#[inline]
pub fn clamp_voidage(eps: f64, eps_min: f64) -> f64 {
    eps.clamp(eps_min, 1.0 - f64::EPSILON)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// `f_cell` against `f` over the voidages and Reynolds numbers of fluidized beds and beyond.
    pub fn fast_form_matches<L: DragLaw>(law: L) {
        let mut worst = 0.0f64;
        for &eps in &[0.05, 0.3, 0.36, 0.4, 0.55, 0.6, 0.79, 0.8, 0.81, 0.9, 0.999, 1.0 - f64::EPSILON] {
            let c = law.cell(eps);
            for k in 0..=400 {
                let re = if k == 0 { 0.0 } else { 10f64.powf(-13.0 + 0.045 * k as f64) };
                let (a, b) = (law.f(eps, re), L::f_cell(&c, re));
                worst = worst.max(((a - b) / a).abs());
            }
        }
        assert!(worst < 1e-13, "fast form differs from the published one by {worst:e}");
    }

    #[test]
    fn every_law_has_the_stokes_limit() {
        // A single sphere (ε → 1) in creeping flow: F → 1 within the law's own fit (Di Felice's
        // Dallavalle C_d gives 4.8²/24 = 0.96; Beetstra's 1.5√φ leaves 2e-8 at φ = ε_machine).
        for (law, want, tol) in
            [(DragModel::Beetstra, 1.0, 1e-7), (DragModel::Gidaspow, 1.0, 1e-9), (DragModel::DiFelice, 0.96, 1e-9)]
        {
            let f = law.f(1.0 - f64::EPSILON, 0.0);
            assert!((f - want).abs() < tol, "{}: F = {f}", law.name());
        }
    }
}
