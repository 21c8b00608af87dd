//! Inlet ramp and the characteristic outlet relation (paper section 2.2, eq. 5–7; PHYSICS.md 9).

use super::params::GasParams;

/// Superficial inlet velocity at time t: a linear ramp from 0 to `u_set` over `ramp_time`
/// (paper: 240 ms); a zero ramp time means the full value from t = 0.
#[inline]
pub fn ramped_superficial_velocity(u_set: f64, ramp_time: f64, t: f64) -> f64 {
    if ramp_time > 0.0 {
        u_set * (t / ramp_time).clamp(0.0, 1.0)
    } else {
        u_set
    }
}

/// Density change of an outlet cell from its change of vertical momentum ρU_z over a step:
/// Δρ = [Δ(ρU_z) − Δt·K·a(ρ − ρ_∞)]/(U_z + a), K = σ(1 − M²)a/L (PHYSICS.md 9: the paper's
/// eq. 5–6 with the printed typo "2U²a⁴" mended to "3U²a⁴" reduce to the σ = 0 form).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn outlet_density_change(
    d_rho_uz: f64,
    uz: f64,
    a: f64,
    rho: f64,
    rho_inf: f64,
    sigma: f64,
    length: f64,
    dt: f64,
) -> f64 {
    let mach2 = (uz / a).powi(2);
    let k = sigma * (1.0 - mach2).max(0.0) * a / length;
    (d_rho_uz - dt * k * a * (rho - rho_inf)) / (uz + a)
}

/// The grid numbers the outlet update needs.
#[derive(Clone, Copy)]
pub struct OutletGeometry {
    pub per: usize,
    pub dz: f64,
    pub height: f64,
}

/// The characteristic outlet layer after an update (paper eq. 5–7, PHYSICS.md 9): its momentum
/// changes copy the layer below (as ρU, i.e. divided by that layer's ε), and
/// Δρ = [Δ(ρU_z) − Δt K a(ρ − ρ_∞)]/(U_z + a). `eps`, `q_old` and `q` start at the layer below
/// the outlet (two layers each); only the outlet layer of `q` is written.
pub fn outlet_layer(p: &GasParams, g: OutletGeometry, eps: &[f64], q_old: &[[f64; 4]], q: &mut [[f64; 4]], dt: f64) {
    let per = g.per;
    let a = p.sound_speed;
    // Relaxation target: the hydrostatic density at the outlet cell centre.
    let rho_inf = p.outlet_pressure / (a * a) * (p.gravity * 0.5 * g.dz / (a * a)).exp();
    for c in 0..per {
        let (below, top) = (c, per + c);
        let (eb, et) = (eps[below], eps[top]);
        let old = q_old[top];
        let mut new = old;
        for n in 1..4 {
            new[n] = old[n] + et * (q[below][n] - q_old[below][n]) / eb;
        }
        let d_rho_uz = (new[3] - old[3]) / et;
        let d_rho = outlet_density_change(
            d_rho_uz,
            old[3] / old[0],
            a,
            old[0] / et,
            rho_inf,
            p.outlet_relaxation,
            g.height,
            dt,
        );
        new[0] = old[0] + et * d_rho;
        q[top] = new;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's printed ratio σ₁σ₂/σ₃ of eq. (6), with s5's U²a⁴ coefficient given as `c`
    /// (printed 2; PHYSICS.md 9 shows it must be 3).
    fn paper_eq6_ratio(u: f64, a: f64, c: f64) -> f64 {
        let s1 =
            u.powi(5) + u.powi(4) * a - 2.0 * u.powi(3) * a * a - 2.0 * u * u * a.powi(3) + u * a.powi(4) + a.powi(5);
        let s2 =
            u.powi(5) - u.powi(4) * a - 2.0 * u.powi(3) * a * a + 2.0 * u * u * a.powi(3) + u * a.powi(4) - a.powi(5);
        let s5 = u.powi(6) - 3.0 * u.powi(4) * a * a + c * u * u * a.powi(4) - a.powi(6);
        let s6 = 2.0 * u.powi(4) * a - 4.0 * u * u * a.powi(3) + 2.0 * a.powi(5);
        let s3 = s2 * s5 + s6 * s5;
        s1 * s2 / s3
    }

    #[test]
    fn ramp_reaches_the_set_velocity_at_the_ramp_time() {
        assert_eq!(ramped_superficial_velocity(0.6, 0.24, 0.0), 0.0);
        assert!((ramped_superficial_velocity(0.6, 0.24, 0.12) - 0.3).abs() < 1e-15);
        assert_eq!(ramped_superficial_velocity(0.6, 0.24, 1.0), 0.6);
        assert_eq!(ramped_superficial_velocity(0.6, 0.0, 0.0), 0.6);
    }

    #[test]
    fn paper_eq6_with_the_typo_mended_is_one_over_u_plus_a() {
        // PHYSICS.md 9: with s5 = (U² − a²)³ the ratio is exactly 1/(U + a); as printed it is off
        // by about −(U/a)².
        let a = 290.1;
        for u in [0.1, 0.5, 3.0, 20.0] {
            let mended = paper_eq6_ratio(u, a, 3.0);
            assert!((mended * (u + a) - 1.0).abs() < 1e-12, "U={u}: {}", mended * (u + a));
            assert_eq!(outlet_density_change(1.0, u, a, 1.2, 1.2, 0.0, 1.0, 1e-6), 1.0 / (u + a));
        }
        let printed = paper_eq6_ratio(0.5, a, 2.0) * (0.5 + a) - 1.0;
        assert!((printed + (0.5f64 / a).powi(2)).abs() < 1e-7, "printed form off by {printed}");
    }

    #[test]
    fn relaxation_pulls_the_density_toward_ambient() {
        let d = outlet_density_change(0.0, 0.0, 290.0, 1.3, 1.2, 0.25, 0.1, 1e-5);
        // Δρ = −Δt·σ a²/L·(ρ−ρ∞)/a = −1e-5·0.25·290/0.1·0.1
        assert!((d + 1e-5 * 0.25 * 290.0 / 0.1 * 0.1).abs() < 1e-12);
    }
}
