//! The contact law: a normal spring–dashpot, a tangential spring with history and a Coulomb
//! limit (PHYSICS.md 2.1-2.3; paper section 2.1 and Table 1), in one generic source
//! (`law_force`) for every style (`contact_styles`: Hertz–Mindlin with Tsuji damping, linear
//! spring–dashpot) and both float types: the pair lanes run it in f32 (`pair_batch`), walls in
//! f64. A new contact model (rolling friction, cohesion) goes into `law_force` or a new `Style`.

use super::contact_styles::{Coeffs, HertzMindlin, LinearSpringDashpot, Style};
use super::real::Real;
use crate::case::{Case, ContactLawChoice, Damping};
use serde::{Deserialize, Serialize};

pub type V3 = [f64; 3];

/// |a − b|², summed (x² + y²) + z².
#[inline(always)]
pub fn dist2(a: V3, b: V3) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// The named contact styles (`case::ContactLawChoice`), one `Style` each (`contact_styles`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
pub enum ContactStyle {
    #[default]
    HertzMindlin,
    LinearSpringDashpot,
}

/// Stiffness and damping prefactors of one kind of contact (pair or wall) in one style.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct ContactLaw {
    pub style: ContactStyle,
    /// Hertz: K_n = (4/3) E* √R* (PHYSICS.md 2.2); linear: k_n.
    pub kn: f64,
    /// η_n = this · δ^{1/4} (Hertz, α_n √(m* K_n), Tsuji); η_n = this (linear).
    pub dn: f64,
    /// Hertz: K_t = 8 G* √R* (PHYSICS.md 2.3), the spring K_t δ^{1/2}; linear: k_t.
    pub kt: f64,
    /// η_t = this · δ^{1/4} (Hertz), η_t = this (linear).
    pub dt: f64,
    /// Sliding friction μ.
    pub mu: f64,
    /// Clamp F_n ≥ 0 (no attraction while the damping pulls); on for every case. Tests turn it
    /// off to compare with the restitution of the unclamped law (PHYSICS.md 2.4).
    pub no_tension: bool,
}

impl ContactLaw {
    /// The case's law for effective radius `r_star`, mass `m_star` and one material.
    pub fn new(case: &Case, r_star: f64, m_star: f64) -> Self {
        let p = &case.particles;
        let (style, kn, kt, an, at) = match p.contact_law {
            ContactLawChoice::HertzMindlin => {
                let (e, nu) = (p.youngs_modulus_pa, p.poisson_ratio);
                // 1/E* = Σ (1-ν²)/E ; 1/G* = Σ 2(2-ν)(1+ν)/E, both sides the same material.
                let e_star = e / (2.0 * (1.0 - nu * nu));
                let g_star = e / (4.0 * (2.0 - nu) * (1.0 + nu));
                let (kn, kt) = (4.0 / 3.0 * e_star * r_star.sqrt(), 8.0 * g_star * r_star.sqrt());
                (ContactStyle::HertzMindlin, kn, kt, p.normal_damping.alpha(), p.tangential_damping.alpha())
            }
            ContactLawChoice::LinearSpringDashpot { normal_stiffness_n_m: k, tangential_stiffness_ratio: ratio } => {
                let a = |d: &Damping| match *d {
                    Damping::TsujiAlpha(a) => a,
                    Damping::Restitution(e) => 2.0 * linear_damping_ratio(e),
                };
                (ContactStyle::LinearSpringDashpot, k, ratio * k, a(&p.normal_damping), a(&p.tangential_damping))
            }
        };
        ContactLaw {
            style,
            kn,
            dn: an * (m_star * kn).sqrt(),
            kt,
            dt: at * (m_star * kt).sqrt(),
            mu: p.sliding_friction,
            no_tension: true,
        }
    }

    /// Elastic energy stored in the normal spring: 2/5 K_n δ^{5/2} (Hertz), ½ k_n δ² (linear).
    pub fn elastic_energy(&self, delta: f64) -> f64 {
        match self.style {
            ContactStyle::HertzMindlin => 0.4 * self.kn * delta * delta * delta.sqrt(),
            ContactStyle::LinearSpringDashpot => 0.5 * self.kn * delta * delta,
        }
    }

    /// The prefactors in the float type of an evaluation.
    #[inline(always)]
    pub(crate) fn coeffs<F: Real>(&self) -> Coeffs<F> {
        Coeffs {
            kn: F::of(self.kn),
            dn: F::of(self.dn),
            kt: F::of(self.kt),
            dt: F::of(self.dt),
            mu: F::of(self.mu),
            no_tension: self.no_tension,
        }
    }
}

/// ζ of a linear spring–dashpot with restitution e: e = exp(−πζ/√(1 − ζ²)), so
/// ζ = −ln e / √(π² + ln² e) (damped harmonic oscillator, e.g. Schäfer, Dippel & Wolf 1996).
pub fn linear_damping_ratio(e: f64) -> f64 {
    let l = e.ln();
    -l / (std::f64::consts::PI.powi(2) + l * l).sqrt()
}

/// One contact evaluated in F: force on i, n × F_t, the new history, the Coulomb excess.
pub(crate) struct Contact<F> {
    pub f: [F; 3],
    pub c: [F; 3],
    pub s: [F; 3],
    /// (|F_t|² − (μ F_n)²) / (μ F_n)² when AUDIT (else zero).
    pub excess: F,
}

/// The contact law of style S in F (PHYSICS.md 2.2–2.3): overlap `delta` > 0 along the unit
/// normal `n` (from i to the partner), `vrel` = v_i − v_partner, `w_sum` = R_i ω_i + R_j ω_j
/// (R_i ω_i for a wall), `s0` the tangential displacement ξ before the step, `h` the time step.
/// Branch free (the Coulomb limit is a select), so the pair lanes vectorise it. FR = false
/// skips the tangential part (μ = 0 gives the same result exactly); AUDIT measures the excess.
#[inline(always)]
pub(crate) fn law_force<S: Style, F: Real, const FR: bool, const AUDIT: bool>(
    c: &Coeffs<F>,
    delta: F,
    n: [F; 3],
    vrel: [F; 3],
    w_sum: [F; 3],
    s0: [F; 3],
    h: F,
) -> Contact<F> {
    let dot = |a: [F; 3], b: [F; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross =
        |a: [F; 3], b: [F; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let vn = dot(vrel, n); // dδ/dt, > 0 while approaching
    let k = S::stiffness(c, delta);
    let fnorm = k.elastic + k.eta_n * vn;
    let fnorm = if c.no_tension { fnorm.max(F::ZERO) } else { fnorm };
    let mut f = [-fnorm * n[0], -fnorm * n[1], -fnorm * n[2]];
    if !FR {
        return Contact { f, c: [F::ZERO; 3], s: s0, excess: F::ZERO };
    }
    // Contact-point slip velocity: v_ij − (v_ij·n)n + (R_i ω_i + R_j ω_j) × n.
    let wn = cross(w_sum, n);
    let vt = [vrel[0] - vn * n[0] + wn[0], vrel[1] - vn * n[1] + wn[1], vrel[2] - vn * n[2] + wn[2]];
    // ξ += v_t h, then projected onto the current tangent plane (PHYSICS.md 2.3).
    let mut s = [s0[0] + vt[0] * h, s0[1] + vt[1] * h, s0[2] + vt[2] * h];
    let sn = dot(s, n);
    s = [s[0] - sn * n[0], s[1] - sn * n[1], s[2] - sn * n[2]];
    let (kt, et) = (k.kt, k.eta_t);
    let ft0 = [-kt * s[0] - et * vt[0], -kt * s[1] - et * vt[1], -kt * s[2] - et * vt[2]];
    let ft2 = dot(ft0, ft0);
    let lim = c.mu * fnorm.abs();
    // Sliding: |F_t| = μ F_n, damping dropped, ξ reset so the spring alone gives F_t. One
    // division for both: q = μF_n / (|F_t| k_t); F_t scales by q k_t, the history is −F_t q.
    let slide = ft2 > lim * lim;
    let q = lim / (ft2.sqrt() * kt);
    let scale = q * kt;
    let mut ft = ft0;
    for a in 0..3 {
        ft[a] = if slide { ft0[a] * scale } else { ft0[a] };
        s[a] = if slide { -ft0[a] * q } else { s[a] };
        f[a] = f[a] + ft[a];
    }
    let excess = if AUDIT {
        let lim2 = lim * lim;
        (dot(ft, ft) - lim2) / lim2.max(F::MIN_POSITIVE)
    } else {
        F::ZERO
    };
    Contact { f, c: cross(n, ft), s, excess }
}

/// Result of one contact evaluation in double precision.
pub struct ContactForce {
    /// Force on particle i.
    pub f: V3,
    /// n × F_t; the torque on each partner is its radius times this.
    pub c: V3,
    /// (|F_t|² − (μ F_n)²) / (μ F_n)², > 0 would break the Coulomb limit (diagnostics; relative,
    /// so that round-off reads the same at every load).
    pub excess: f64,
}

/// `law_force` in double precision for the law's style (walls, and the reference for the pair
/// lanes): `shear` = ξ, updated in place when FRICTION.
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
    let c = law.coeffs::<f64>();
    let out = match law.style {
        ContactStyle::HertzMindlin => {
            law_force::<HertzMindlin, f64, FRICTION, true>(&c, delta, n, vrel, w_sum, *shear, h)
        }
        ContactStyle::LinearSpringDashpot => {
            law_force::<LinearSpringDashpot, f64, FRICTION, true>(&c, delta, n, vrel, w_sum, *shear, h)
        }
    };
    if FRICTION {
        *shear = out.s;
    }
    ContactForce { f: out.f, c: out.c, excess: out.excess }
}
