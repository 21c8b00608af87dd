//! Beetstra, van der Hoef & Kuipers (2007) monodisperse drag, PHYSICS.md 1.1, in the model-A form
//! of PHYSICS.md 11 (the particle also feels −V_p∇p; the gas loses the drag alone).

use super::{DragLaw, RE_GUARD};
use crate::coupling::fast_math::{fast_exp, fast_ln};

/// Dimensionless drag F(ε, Re) = F₀ + F₁ (PHYSICS.md 1.1), Re = ρ_g ε |u − v| d / μ:
/// F₀ = 10φ/ε² + ε²(1 + 1.5√φ),
/// F₁ = 0.413 Re/(24ε²) · (1/ε + 3εφ + 8.4 Re^−0.343) / (1 + 10^(3φ) Re^(−(1+4φ)/2)).
pub fn beetstra_f(eps: f64, re: f64) -> f64 {
    let phi = 1.0 - eps;
    let f0 = 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * phi.max(0.0).sqrt());
    if re < RE_GUARD {
        return f0;
    }
    let f1 = 0.413 * re / (24.0 * eps * eps) * (1.0 / eps + 3.0 * eps * phi + 8.4 * re.powf(-0.343))
        / (1.0 + 10f64.powf(3.0 * phi) * re.powf(-(1.0 + 4.0 * phi) / 2.0));
    f0 + f1
}

/// Model-A interphase coefficient β_A = 18 μ ε φ F / d² (force per volume per slip velocity).
pub fn beta_a(mu: f64, d: f64, eps: f64, re: f64) -> f64 {
    18.0 * mu * eps * (1.0 - eps) * beetstra_f(eps, re) / (d * d)
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Beetstra;

/// F = f0 + b·Re·(c + 8.4 Re^−0.343)/(1 + p10·Re^e1): one ln and two exp per particle.
#[derive(Clone, Copy, Debug, Default)]
pub struct BeetstraCell {
    f0: f64,
    b: f64,
    c: f64,
    p10: f64,
    e1: f64,
}

impl DragLaw for Beetstra {
    type Cell = BeetstraCell;
    fn f(&self, eps: f64, re: f64) -> f64 {
        beetstra_f(eps, re)
    }
    fn cell(&self, eps: f64) -> BeetstraCell {
        let phi = 1.0 - eps;
        BeetstraCell {
            f0: 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * phi.max(0.0).sqrt()),
            b: 0.413 / (24.0 * eps * eps),
            c: 1.0 / eps + 3.0 * eps * phi,
            p10: fast_exp(3.0 * std::f64::consts::LN_10 * phi),
            e1: -(1.0 + 4.0 * phi) / 2.0,
        }
    }
    #[inline(always)]
    fn f_cell(k: &BeetstraCell, re: f64) -> f64 {
        let l = fast_ln(re.max(RE_GUARD));
        let f1 = k.b * re * (k.c + 8.4 * fast_exp(-0.343 * l)) / (1.0 + k.p10 * fast_exp(k.e1 * l));
        if re < RE_GUARD {
            k.f0
        } else {
            k.f0 + f1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coupling::drag::{drag_force, DragModel};
    use std::f64::consts::PI;

    #[test]
    fn fast_form_matches_the_published_one() {
        crate::coupling::drag::tests::fast_form_matches(Beetstra);
    }

    #[test]
    fn reproduces_the_physics_reference_table() {
        let table = [(0.4, [37.846, 41.195, 89.789]), (0.6, [11.813, 13.464, 30.742]), (0.8, [4.194, 5.187, 12.948])];
        for (eps, row) in table {
            for (re, want) in [0.0, 10.0, 100.0].iter().zip(row) {
                let got = beetstra_f(eps, *re);
                assert!((got - want).abs() <= 0.0005, "F({eps}, {re}) = {got}, table {want}");
            }
        }
    }

    #[test]
    fn dilute_stokes_limit() {
        // φ → 0, Re → 0: F → 1 (Stokes drag)
        assert!((beetstra_f(1.0, 0.0) - 1.0).abs() < 1e-15);
        assert!((beetstra_f(1.0 - 1e-10, 1e-9) - 1.0).abs() < 1e-4);
        // and the force is then 3πμ d (u − v)
        // (Re ≈ 7e-7 here; F₁ ~ Re^0.657 adds ≈ 1e-5)
        let f = drag_force(DragModel::Beetstra, 1.8e-5, 1.2, 1e-3, 1.0, 0.1, [0.0, 0.0, 1e-8]);
        assert!((f[2] / (3.0 * PI * 1.8e-5 * 1e-3 * 1e-8) - 1.0).abs() < 1e-4);
    }

    #[test]
    fn beta_a_matches_the_particle_force_per_volume() {
        // β_A·(u−v) = n·F_d with n = φ/V_p
        let (mu, rho, d, eps, w) = (1.8e-5, 1.204, 1.2e-3, 0.45, 0.7);
        let fd = drag_force(DragModel::Beetstra, mu, rho, d, eps, 0.1, [0.0, 0.0, w])[2];
        let vp = PI * d * d * d / 6.0;
        let re = rho * eps * w * d / mu;
        assert!((beta_a(mu, d, eps, re) * w - (1.0 - eps) / vp * fd).abs() < 1e-9 * fd / vp);
    }

    /// U₀ at which drag balances the buoyant weight of a particle at rest in a homogeneous bed.
    fn umf(mu: f64, eps: f64) -> f64 {
        let (rho, rho_p, d, g) = (1.204, 1000.0, 1.2e-3, 9.81);
        let vp = PI * d * d * d / 6.0;
        let excess = |u0: f64| {
            let fd = drag_force(DragModel::Beetstra, mu, rho, d, eps, 0.1, [0.0, 0.0, u0 / eps])[2];
            fd / eps - (rho_p - rho) * vp * g
        };
        let (mut lo, mut hi) = (1e-4, 5.0);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if excess(m) > 0.0 {
                hi = m;
            } else {
                lo = m;
            }
        }
        0.5 * (lo + hi)
    }

    /// U_mf from a force balance at ε_mf (d = 1.2 mm, ρ_p = 1000, ρ_g = 1.204). Model A, steady
    /// homogeneous bed, particles at rest (u = U₀/ε):
    /// gas: ε(−∇p) = n F_d + ε ρ_g g; particle: ρ_p V_p g = V_p(−∇p) + F_d.
    /// Eliminating ∇p: (ρ_p − ρ_g) V_p g = F_d (1 + φ/ε) = F_d / ε — exactly the model-B balance
    /// (particle force F_d/ε against buoyant weight), so models A and B give the same U_mf.
    /// F_d = 3πμ d ε F u = 3πμ d F U₀, Re = ρ_g U₀ d / μ.
    /// PHYSICS.md 10's 0.335 (ε 0.40) and 0.292 (ε 0.38) are reproduced with Sutherland's
    /// μ(293.15 K) = 1.813e-5 (PHYSICS.md 8); with μ = 1.8e-5 the same balance gives 0.336.
    #[test]
    fn minimum_fluidization_velocity_from_force_balance() {
        assert!((umf(1.813e-5, 0.40) - 0.335).abs() < 0.0005, "{}", umf(1.813e-5, 0.40));
        assert!((umf(1.813e-5, 0.38) - 0.292).abs() < 0.001, "{}", umf(1.813e-5, 0.38));
        let u = umf(1.8e-5, 0.40);
        assert!((u - 0.336).abs() < 0.0005, "{u}");
        // the model-A balance solved for −∇p gives the same particle equilibrium
        let (mu, rho, rho_p, d, g, eps) = (1.8e-5, 1.204, 1000.0, 1.2e-3, 9.81, 0.40);
        let vp = PI * d * d * d / 6.0;
        let fd = drag_force(DragModel::Beetstra, mu, rho, d, eps, 0.1, [0.0, 0.0, u / eps])[2];
        let grad = ((1.0 - eps) / vp * fd + eps * rho * g) / eps;
        assert!(((rho_p * vp * g - vp * grad) / fd - 1.0).abs() < 1e-9);
    }
}
