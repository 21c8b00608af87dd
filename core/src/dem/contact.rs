//! Contact law: Hertz normal force with Tsuji damping, Mindlin/Tsuji tangential spring with
//! history and a Coulomb limit (PHYSICS.md 2.1-2.3; paper section 2.1 and Table 1).
//! One pure kernel serves particle-particle and particle-wall contacts.

use crate::case::Case;
use serde::{Deserialize, Serialize};

pub type V3 = [f64; 3];

#[inline(always)]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// |a − b|², summed (x² + y²) + z².
#[inline(always)]
pub fn dist2(a: V3, b: V3) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}
#[inline(always)]
pub fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Stiffness and damping prefactors of one kind of contact (pair or wall).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct ContactLaw {
    /// K_n = (4/3) E* √R* (PHYSICS.md 2.2).
    pub kn: f64,
    /// α_n √(m* K_n): η_n = this · δ^{1/4} (Tsuji).
    pub dn: f64,
    /// K_t = 8 G* √R* (PHYSICS.md 2.3).
    pub kt: f64,
    /// α_t √(m* K_t): η_t = this · δ^{1/4}.
    pub dt: f64,
    /// Sliding friction μ.
    pub mu: f64,
    /// Clamp F_n ≥ 0 (no attraction while the damping pulls); on for every case. Tests turn it
    /// off to compare with e(α) of PHYSICS.md 2.4, which is derived without the clamp.
    pub no_tension: bool,
}

impl ContactLaw {
    /// PHYSICS.md 2.1-2.3 for effective radius `r_star`, mass `m_star` and one material.
    pub fn new(case: &Case, r_star: f64, m_star: f64) -> Self {
        let p = &case.particles;
        let (e, nu) = (p.youngs_modulus_pa, p.poisson_ratio);
        // 1/E* = Σ (1-ν²)/E ; 1/G* = Σ 2(2-ν)(1+ν)/E, both sides the same material.
        let e_star = e / (2.0 * (1.0 - nu * nu));
        let g_star = e / (4.0 * (2.0 - nu) * (1.0 + nu));
        let kn = 4.0 / 3.0 * e_star * r_star.sqrt();
        let kt = 8.0 * g_star * r_star.sqrt();
        ContactLaw {
            kn,
            dn: p.normal_damping.alpha() * (m_star * kn).sqrt(),
            kt,
            dt: p.tangential_damping.alpha() * (m_star * kt).sqrt(),
            mu: p.sliding_friction,
            no_tension: true,
        }
    }

    /// Elastic energy stored in the normal spring, 2/5 K_n δ^{5/2}.
    pub fn elastic_energy(&self, delta: f64) -> f64 {
        0.4 * self.kn * delta * delta * delta.sqrt()
    }
}

/// Result of one contact evaluation.
pub struct ContactForce {
    /// Force on particle i.
    pub f: V3,
    /// n × F_t; the torque on each partner is its radius times this.
    pub c: V3,
    /// (|F_t|² − (μ F_n)²) / (μ F_n)², > 0 would break the Coulomb limit (diagnostics; relative,
    /// so that round-off reads the same at every load).
    pub excess: f64,
}

/// Force on particle i from a contact with overlap `delta` > 0 along the unit normal `n`
/// (pointing from i to the partner). `vrel` = v_i − v_partner, `w_sum` = R_i ω_i + R_j ω_j
/// (R_i ω_i for a wall), `shear` = tangential displacement ξ (updated in place), `h` = time step.
/// FRICTION = false skips the tangential part (μ = 0 gives the same result exactly).
#[inline(always)]
pub fn contact_force<const FRICTION: bool>(
    law: &ContactLaw,
    delta: f64,
    n: V3,
    vrel: V3,
    w_sum: V3,
    shear: &mut V3,
    h: f64,
) -> ContactForce {
    let vn = dot(vrel, n); // dδ/dt, > 0 while approaching
    let sd = delta.sqrt();
    let qd = sd.sqrt(); // δ^{1/4} without powf
                        // F_n = K_n δ^{3/2} + α_n √(m* K_n) δ^{1/4} dδ/dt, clamped ≥ 0 (PHYSICS.md 2.2)
    let fnorm = law.kn * delta * sd + law.dn * qd * vn;
    let fnorm = if law.no_tension { fnorm.max(0.0) } else { fnorm };
    let mut f = [-fnorm * n[0], -fnorm * n[1], -fnorm * n[2]];
    if !FRICTION {
        return ContactForce { f, c: [0.0; 3], excess: 0.0 };
    }
    // Contact-point slip velocity: v_ij + (R_i ω_i + R_j ω_j) × n, tangential part.
    let wn = cross(w_sum, n);
    let vt = [vrel[0] - vn * n[0] + wn[0], vrel[1] - vn * n[1] + wn[1], vrel[2] - vn * n[2] + wn[2]];
    // ξ += v_t h, then projected onto the current tangent plane (PHYSICS.md 2.3).
    let mut s = [shear[0] + vt[0] * h, shear[1] + vt[1] * h, shear[2] + vt[2] * h];
    let sn = dot(s, n);
    s = [s[0] - sn * n[0], s[1] - sn * n[1], s[2] - sn * n[2]];
    let kt = law.kt * sd; // K_t δ^{1/2}
    let et = law.dt * qd; // η_t = α_t √(m* K_t) δ^{1/4}
    let mut ft = [-kt * s[0] - et * vt[0], -kt * s[1] - et * vt[1], -kt * s[2] - et * vt[2]];
    let ft2 = dot(ft, ft);
    let lim = law.mu * fnorm.abs();
    if ft2 > lim * lim {
        // Sliding: |F_t| = μ F_n, damping dropped, ξ reset so the spring alone gives F_t.
        // One division for both: q = μF_n / (|F_t| K_t δ^{1/2}); F_t scales by q K_t and the
        // reset history is −F_t,trial q (as the batched kernel).
        let q = lim / (ft2.sqrt() * kt);
        let scale = q * kt;
        s = [-ft[0] * q, -ft[1] * q, -ft[2] * q];
        ft = [ft[0] * scale, ft[1] * scale, ft[2] * scale];
    }
    *shear = s;
    f = [f[0] + ft[0], f[1] + ft[1], f[2] + ft[2]];
    ContactForce { f, c: cross(n, ft), excess: (dot(ft, ft) - lim * lim) / (lim * lim).max(f64::MIN_POSITIVE) }
}
