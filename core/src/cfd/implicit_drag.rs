//! The drag on the gas linearised in the gas velocity and stepped implicitly (`coupling.gas_drag`
//! = "implicit"): between couplings the gas feels I(u) = I₀ − a(u − u₀) instead of the held I₀,
//! with I₀ the coupling's interaction force, u₀ the gas velocity it was computed from and
//! a = Σ_p K_p·∂u_s/∂u / V_cell the cell's drag coefficient (K_p = 3πμdεF of each particle: the
//! drag law's secant coefficient, F held at the coupling's Re). The term is stepped by backward
//! Euler after the momentum's other terms (operator splitting):
//!
//!   m^{n+1} = m* − Δt·a·(m^{n+1}/D − u₀)   ⇒   m^{n+1} = (m* + Δt·a·u₀) / (1 + Δt·a/D),
//!
//! D = ρε of the cell, m = ρεu. I₀ stays in the explicit terms, so at u = u₀ the gas gets exactly
//! the coupling's force (what the particles got), and a steady state of the held coupling is one
//! of this. A drag held over T relaxes the gas's velocity error by 1 − T·a/D per coupling, which
//! overshoots once T passes the relaxation time D/a (≈ 60 µs in a bed near U_mf); implicit, by
//! 1/(1 + T·a/D) at any T (docs/BENCHMARKS.md, "What sets off the oscillation; intervals of 80").

/// The gas side of the coupling for `apply`: per cell a (kg m⁻³ s⁻¹) and u₀ (Cartesian), for the
/// first cells of the grid (those up to the bed's top); the cells past them have a = 0.
#[derive(Clone, Copy)]
pub struct ImplicitDrag<'a> {
    pub coef: &'a [f64],
    pub u0: &'a [[f64; 3]],
}

impl<'a> ImplicitDrag<'a> {
    /// The cells c0..c1 (those of them that `self` holds).
    pub fn cells(self, c0: usize, c1: usize) -> ImplicitDrag<'a> {
        let (lo, hi) = (c0.min(self.coef.len()), c1.min(self.coef.len()));
        ImplicitDrag { coef: &self.coef[lo..hi], u0: &self.u0[lo..hi] }
    }
}

/// The implicit drag step of the cells `q` (ρε, ρεu_x, ρεu_y, ρεu_z), `drag` of its first cells.
pub fn apply(q: &mut [[f64; 4]], drag: ImplicitDrag, dt: f64) {
    assert!(drag.coef.len() == drag.u0.len() && drag.coef.len() <= q.len(), "a coefficient per cell");
    for ((s, &a), u0) in q.iter_mut().zip(drag.coef).zip(drag.u0) {
        let k = dt * a;
        let inv = 1.0 / (1.0 + k / s[0]);
        for i in 0..3 {
            s[i + 1] = (s[i + 1] + k * u0[i]) * inv;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gas in a bed of particles at velocity v, no other force: du/dt = −(a/D)(u − v) relaxes
    /// to v; backward Euler gives (u − v)ₙ = (u₀ − v)/(1 + Δt a/D)ⁿ, stable at any Δt.
    #[test]
    fn a_gas_relaxes_to_the_particles_velocity_as_backward_euler_at_any_step() {
        let (d, a, v, u_start) = (0.5, 2000.0, [0.1, -0.05, 0.3], [0.0, 0.2, 1.5]);
        for dt in [1e-6, 1e-4, 1e-2] {
            let mut q = [[d, d * u_start[0], d * u_start[1], d * u_start[2]]];
            // The coupling's state: u₀ = u_start, I₀ = −a(u₀ − v); I₀ is explicit (m* = m + Δt·I₀).
            let i0: Vec<f64> = (0..3).map(|i| -a * (u_start[i] - v[i])).collect();
            for n in 1..=20 {
                for i in 0..3 {
                    q[0][i + 1] += dt * i0[i];
                }
                apply(&mut q, ImplicitDrag { coef: &[a], u0: &[u_start] }, dt);
                let r = (1.0 + dt * a / d).powi(-n);
                for i in 0..3 {
                    let want = v[i] + (u_start[i] - v[i]) * r;
                    let got = q[0][i + 1] / d;
                    assert!((got - want).abs() < 1e-12, "dt {dt}, step {n}, component {i}: {got} vs {want}");
                }
            }
        }
    }

    /// At the coupling's own gas velocity the implicit term adds nothing to the explicit I₀, and
    /// a cell without particles (a = 0, or past the coefficients given) is left alone.
    #[test]
    fn at_the_couplings_velocity_and_without_particles_it_changes_nothing() {
        let u0 = [[0.3, 0.1, 0.9], [1.0, 2.0, 3.0], [-0.5, 0.0, 4.0]];
        let d = [0.48, 1.2, 1.1];
        let mut q: Vec<[f64; 4]> = (0..3).map(|c| [d[c], d[c] * u0[c][0], d[c] * u0[c][1], d[c] * u0[c][2]]).collect();
        let before = q.clone();
        let drag = ImplicitDrag { coef: &[3000.0, 0.0], u0: &u0[..2] };
        apply(&mut q, drag, 6.25e-6);
        assert_eq!(drag.cells(1, 3).coef, &[0.0], "a thread's cells past the given ones hold none");
        for (s, b) in q.iter().zip(&before) {
            for i in 0..4 {
                assert!((s[i] - b[i]).abs() <= 1e-15 * b[i].abs(), "{s:?} vs {b:?}");
            }
        }
    }
}
