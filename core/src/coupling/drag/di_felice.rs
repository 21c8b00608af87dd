//! Di Felice (1994), as CFDEM's DiFeliceDrag: F_d = ⅛ C_d ρ π d² ε^(2−χ) |u − v|(u − v) with the
//! Dallavalle coefficient C_d = (0.63 + 4.8/√Re)² and χ = 3.7 − 0.65 exp(−(1.5 − log₁₀Re)²/2),
//! Re = ρ ε |u − v| d/μ. In the F form of drag/mod.rs: F = (0.63 √Re + 4.8)² ε^−χ / 24.

use super::{DragLaw, RE_GUARD};
use crate::coupling::fast_math::{fast_exp, fast_ln};
use std::f64::consts::LN_10;

#[derive(Clone, Copy, Debug, Default)]
pub struct DiFelice;

/// ln ε of the cell (ε^−χ = exp(−χ ln ε)).
#[derive(Clone, Copy, Debug, Default)]
pub struct DiFeliceCell {
    ln_eps: f64,
}

/// Di Felice's exponent χ(Re).
pub fn chi(re: f64) -> f64 {
    let l = 1.5 - re.max(RE_GUARD).log10();
    3.7 - 0.65 * (-0.5 * l * l).exp()
}

impl DragLaw for DiFelice {
    type Cell = DiFeliceCell;
    fn f(&self, eps: f64, re: f64) -> f64 {
        let a = 0.63 * re.sqrt() + 4.8;
        a * a * eps.powf(-chi(re)) / 24.0
    }
    fn cell(&self, eps: f64) -> DiFeliceCell {
        DiFeliceCell { ln_eps: fast_ln(eps) }
    }
    #[inline(always)]
    fn f_cell(c: &DiFeliceCell, re: f64) -> f64 {
        let l = 1.5 - fast_ln(re.max(RE_GUARD)) / LN_10;
        let chi = 3.7 - 0.65 * fast_exp(-0.5 * l * l);
        let a = 0.63 * re.sqrt() + 4.8;
        a * a * fast_exp(-chi * c.ln_eps) / 24.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_form_matches_the_published_one() {
        crate::coupling::drag::tests::fast_form_matches(DiFelice);
    }

    #[test]
    fn exponent_has_the_published_shape() {
        // Di Felice (1994), Fig. 4: χ ≈ 3.7 at low and high Re, its minimum 3.05 at Re = 10^1.5.
        assert!((chi(10f64.powf(1.5)) - 3.05).abs() < 1e-12);
        assert!((chi(1e-3) - 3.7).abs() < 1e-3 && (chi(1e6) - 3.7).abs() < 1e-3);
    }

    #[test]
    fn single_sphere_is_dallavalle() {
        // ε = 1: F = C_d Re/24 with C_d = (0.63 + 4.8/√Re)²; C_d(Re = 1000) = 0.6112.
        let f = DiFelice.f(1.0 - f64::EPSILON, 1000.0);
        assert!((f * 24.0 / 1000.0 - 0.6112).abs() < 1e-4, "C_d = {}", f * 24.0 / 1000.0);
    }
}
