//! The right-hand side of eq. (A.1) in finite-volume form: d q/dt per unit volume for every cell,
//! q = (ρε, ρεu_x, ρεu_y, ρεu_z). Momentum is carried in Cartesian components on the cylindrical
//! grid (each cell's (U_r, U_θ) is a fixed rotation of them), so fluxes between cells whose
//! cylindrical bases differ (radial neighbours, the central annulus around the axis) are exact
//! vector sums, and the cylindrical source terms S of eq. (A.12) come out of the face vector areas
//! instead of being added as centre values.
//!
//! Per face (vector area S from a to b):
//! - mass flux ṁ = ½(m_a + m_b)·S (central);
//! - convective momentum flux ṁ·u_f, u_f central in r and θ, QUICK+SMART in z (paper 2.2; PHYSICS.md 6);
//! - pressure −ε∇p by Green–Gauss with face value ½(p_a + p_b) + ¼(B_b − B_a)(j_f·d), B = β/ε²
//!   (drag-weighted, `drag_weighted_face_pressure`; zero in drag-free gas), model A (PHYSICS.md 11);
//! - a pressure dissipation in the mass flux against the odd–even decoupling of collocated central
//!   schemes (Rhie–Chow type): ṁ −= (κ/a)ε_f|S|[(p_b − p_a) − ½(∇p_a + ∇p_b)·d], d = x_b − x_a,
//!   ε_f the mean voidage of the two cells (keeps its damping rate 4κa/dz independent of ε), κ = 0.1.
//!   It vanishes for any linear pressure field and scales as κ a dz³∂⁴ρ on smooth waves; without it,
//!   half the acoustic modes of a column with the characteristic outlet are undamped and the
//!   linearly extrapolated inlet pressure makes some grow (semi-discrete eigenvalues; see the report);
//! - on the axial faces a momentum dissipation in the flux of ρεu_z, −κ_m a|S|[(m_b − m_a) −
//!   ½(∇m_a + ∇m_b)·d], m = ρεu_z, ∇m central (linear ghosts beyond the inlet and outlet), κ_m = 0.1:
//!   O(dz³∂³m), the ρεu half of the low-Mach Roe dissipation (cfd/mod.rs);
//! - plus the face correction F·|S| (state, one per face), the Rhie–Chow momentum interpolation whose
//!   steady value is the Darcy flux of the same mismatch (cfd/mod.rs "Face mass flux");
//! - stress ε∇·τ with τ = μ(∇u + ∇uᵀ) + (L − 2μ/3)(∇·u)I; for constant μ, ∇·τ = μ∇²u + (L + μ/3)∇(∇·u),
//!   discretised as the compact face flux μ|S|/δ·(u_b − u_a) + (L + μ/3)·½(D_a + D_b)·S (eq. A.5–A.11).
//!
//! Sources: ρε g (−z) and the interaction force I (eq. A.12).

use super::boundary::ramped_superficial_velocity;
use super::geometry::FaceGeometry;
use super::inlet_jet::InletJet;
use super::params::{GasParams, Outlet};

/// Primitive fields computed from the state before each right-hand side.
#[derive(Clone, Debug, Default)]
pub struct Primitives {
    pub ux: Vec<f64>,
    pub uy: Vec<f64>,
    pub uz: Vec<f64>,
    pub p: Vec<f64>,
    /// ∇·u per cell (finite volume).
    pub div: Vec<f64>,
    /// ∇p per cell (Green–Gauss, Cartesian), the pressure force −ε∇p of the momentum equation.
    pub gx: Vec<f64>,
    pub gy: Vec<f64>,
    pub gz: Vec<f64>,
    /// Interphase coefficient per cell, β = |I|/|u| (0 without interaction force), for the face
    /// mass-flux correction.
    pub beta: Vec<f64>,
    /// β/ε² per cell, which the drag-weighted face pressures read (`drag_weighted_face_pressure`).
    pub beta_over_eps2: Vec<f64>,
}

impl Primitives {
    pub fn new(n: usize) -> Primitives {
        let z = vec![0.0; n];
        Primitives {
            ux: z.clone(),
            uy: z.clone(),
            uz: z.clone(),
            p: z.clone(),
            div: z.clone(),
            gx: z.clone(),
            gy: z.clone(),
            gz: z.clone(),
            beta: z.clone(),
            beta_over_eps2: z,
        }
    }

    /// All fields as slices (an empty slice for a field moved out meanwhile).
    pub fn view(&self) -> PrimView<'_> {
        PrimView {
            ux: &self.ux,
            uy: &self.uy,
            uz: &self.uz,
            p: &self.p,
            div: &self.div,
            gx: &self.gx,
            gy: &self.gy,
            gz: &self.gz,
            beta: &self.beta,
            beta_over_eps2: &self.beta_over_eps2,
        }
    }
}

/// The fields of `Primitives` as the passes read them: borrowed slices, so that a team of threads
/// can read some fields while it still writes others (team_step.rs). The passes over them are in
/// rhs_layers.rs.
#[derive(Clone, Copy)]
pub struct PrimView<'a> {
    pub ux: &'a [f64],
    pub uy: &'a [f64],
    pub uz: &'a [f64],
    pub p: &'a [f64],
    pub div: &'a [f64],
    pub gx: &'a [f64],
    pub gy: &'a [f64],
    pub gz: &'a [f64],
    pub beta: &'a [f64],
    pub beta_over_eps2: &'a [f64],
}

/// Everything the right-hand side reads besides the state.
pub struct RhsInput<'a> {
    pub geo: &'a FaceGeometry,
    pub params: &'a GasParams,
    pub per: usize,
    pub nz: usize,
    pub dz: f64,
    pub eps: &'a [f64],
    /// Interaction force per unit volume, cylindrical (r, θ, z) in each cell's basis.
    pub force: &'a [[f64; 3]],
    /// Face mass-flux corrections (kg m⁻² s⁻¹, module comment): the axial face above each cell
    /// (n values; the top layer's unused), then each layer's horizontal faces (nz × faces).
    pub face_flux: &'a [f64],
    pub time: f64,
    /// A jet through the distributor's inner annuli (inlet_jet.rs), if the case has one.
    pub jet: Option<InletJet>,
}

impl RhsInput<'_> {
    /// Interstitial inlet velocity U(t)/ε_inlet and the superficial inlet velocity U(t) of inlet
    /// cell `c` (the bed's, or a jet's inside its window).
    #[inline]
    pub(super) fn inlet(&self, c: usize) -> (f64, f64) {
        let p = self.params;
        let u_set = self.jet.map_or(p.superficial_velocity, |j| j.velocity(c, self.time, p.superficial_velocity));
        let u = ramped_superficial_velocity(u_set, p.ramp_time, self.time);
        (u / p.inlet_voidage, u)
    }
    /// The horizontal-face corrections of layer k.
    #[inline]
    pub(super) fn face_flux_h(&self, k: usize) -> &[f64] {
        let (n, nf) = (self.per * self.nz, self.geo.faces.len());
        &self.face_flux[n + k * nf..n + (k + 1) * nf]
    }
}

/// Coefficient κ of the pressure dissipation in the mass flux (module comment).
pub const PRESSURE_DISSIPATION: f64 = 0.1;

/// Coefficient κ_m of the momentum dissipation in the axial faces' flux of ρεu_z (module comment);
/// κ_m = κ keeps the outlet's reflection at its smooth level (0.12 %).
pub const MOMENTUM_DISSIPATION: f64 = 0.1;

/// Rate factor s₀ of the face mass-flux correction (module comment): it sets the frequency of the
/// odd–even mode, ω ≤ 2a√s/δ, and raises the acoustic spectral radius of the central scheme to at
/// most a/(δ√(1 − s₀)) (stability.rs); the steady state does not depend on it.
pub const FACE_FLUX_RATE: f64 = 0.1;

/// β = |I|/|u|: the drag coefficient when I = −β(u − v) and the particles are slow (a floor of
/// 1 µm/s on |u|; 0 where there is no force). Written so that a loop over cells vectorises.
#[inline(always)]
pub fn drag_coefficient(f: [f64; 3], u: (f64, f64, f64)) -> f64 {
    let fm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
    let um = (u.0 * u.0 + u.1 * u.1 + u.2 * u.2).sqrt();
    let b = fm / um.max(1e-6);
    if fm > 0.0 {
        b
    } else {
        0.0
    }
}

/// Drag-weighted part of a face pressure, p_f = ½(p_a + p_b) + w (body-force weighting, as
/// Mencinger & Žun 2007 for a discontinuous body force on a collocated grid): w = ¼(G_a − G_b)·d,
/// G = −β j_f/ε² each cell's drag-balance gradient −βu/ε at the face's superficial velocity
/// j_f = ½(ε_a u_a + ε_b u_b) (continuous across a voidage jump), so w = ¼(B_b − B_a)(j_f·d),
/// B = β/ε². Where β or ε jumps (a bed surface) each cell's Green–Gauss gradient is then its own
/// drag balance and no odd–even pressure mode is needed; for smooth B it is O(d²), in drag-free gas 0.
#[inline(always)]
pub fn drag_weighted_face_pressure(b_a: f64, b_b: f64, jf_dot_d: f64) -> f64 {
    0.25 * (b_b - b_a) * jf_dot_d
}

/// Pressure on the inlet face: p·exp(g z/a²) (constant in the hydrostatic state) extrapolated
/// linearly from layers 0 and 1, φ_f = (3p₀ − p₁e)/2 with e = exp(g dz/a²), then p_f = φ_f·√e.
/// Exact for the hydrostatic state and for a linear p (a bed's drag gradient, which a zero-gradient
/// ghost would halve in layer 0). With a single layer the ghost is hydrostatic, p_f = p₀√e.
#[inline]
pub fn inlet_face_pressure(p0: f64, p1: Option<f64>, gravity: f64, dz: f64, a2: f64) -> f64 {
    let e = (gravity * dz / a2).exp();
    match p1 {
        Some(p1) => 0.5 * (3.0 * p0 - p1 * e) * e.sqrt(),
        None => p0 * e.sqrt(),
    }
}

/// Pressure on the top face: a shut top extrapolates hydrostatically as the inlet does; the
/// characteristic outlet extrapolates linearly from the two top layers.
#[inline]
pub fn top_face_pressure(outlet: Outlet, p_top: f64, p_below: f64, gravity: f64, dz: f64, a2: f64) -> f64 {
    match outlet {
        Outlet::Wall => 0.5 * p_top * (1.0 + (-gravity * dz / a2).exp()),
        Outlet::Characteristic => 1.5 * p_top - 0.5 * p_below,
    }
}

/// Rate of change of one face's mass-flux correction F (module comment):
/// dF/dt = −s·[ε_f·m/δ + β_f F/(ρ_f ε_f)], s = s₀/(1 + β_f δ/(ρ_f ε_f a)), m = (p_b − p_a) − ḡ·d.
/// Its steady value is the Darcy flux of the mismatch, F = −(ρ_f ε_f²/β_f)·m/δ.
/// With D = ρ_f ε_f this is −s₀a·(ε_f m D/δ + β_f F)/(D a + β_f δ): one division per face.
#[inline]
pub fn face_flux_rate(eps_f: f64, rho_f: f64, beta_f: f64, mismatch: f64, delta: f64, f: f64, a: f64) -> f64 {
    let s0a = FACE_FLUX_RATE * a;
    // Drag-free gas: no correction (the κ dissipation handles the mode, as the characteristic
    // outlet expects); a correction left from earlier drag decays at s₀a/δ. Both are computed and
    // one is selected, so that a loop over faces vectorises.
    let free = -s0a / delta * f;
    let d = rho_f * eps_f;
    let dragged = -s0a * (eps_f * mismatch * d + beta_f * f * delta) / (delta * (d * a + beta_f * delta));
    if beta_f <= 0.0 {
        free
    } else {
        dragged
    }
}

/// Mass flux (kg/s) into cell i of the bottom layer through the inlet: ṁ = ρ_f·U(t)·A_z, with the
/// face density of the hydrostatic ghost.
#[inline]
pub fn inlet_mass_flux(inp: &RhsInput, p: &[f64], i: usize) -> f64 {
    let (par, a2) = (inp.params, inp.params.sound_speed * inp.params.sound_speed);
    let (_, u_in) = inp.inlet(i);
    let rho_f = inlet_face_pressure(p[i], (inp.nz > 1).then(|| p[i + inp.per]), par.gravity, inp.dz, a2) / a2;
    rho_f * u_in * inp.geo.area_z
}

/// ṁ_in − ṁ_out (kg/s) of the flux-updated cells (mass_budget.rs) at the right-hand side whose
/// pressures are `p` and axial faces `axial`: the inlet, less the faces into the characteristic
/// outlet layer (a shut top has none).
pub fn net_mass_inflow(inp: &RhsInput, p: &[f64], axial: &[[f64; 7]]) -> f64 {
    let per = inp.per;
    let inflow: f64 = (0..per).map(|c| inlet_mass_flux(inp, p, c)).sum();
    if inp.params.outlet == Outlet::Characteristic && inp.nz > 1 {
        inflow - axial[(inp.nz - 2) * per..(inp.nz - 1) * per].iter().map(|f| f[0]).sum::<f64>()
    } else {
        inflow
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn face_rate_equals_its_two_stage_definition() {
        // dF/dt = −s·[ε_f m/δ + relax·F], relax = β/(ρε), s = s₀/(1 + relax·δ/a)
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
        for _ in 0..100_000 {
            let (eps, rho, beta) =
                (rng.gen_range(0.3..1.0), rng.gen_range(0.5..2.0), 10f64.powf(rng.gen_range(-2.0..6.0)));
            let (m, delta, f, a) =
                (rng.gen_range(-50.0..50.0), rng.gen_range(1e-3..1e-2), rng.gen_range(-1.0..1.0), 343.0);
            let relax = beta / (rho * eps);
            let want = -FACE_FLUX_RATE / (1.0 + relax * delta / a) * (eps * m / delta + relax * f);
            let got = face_flux_rate(eps, rho, beta, m, delta, f, a);
            let scale = FACE_FLUX_RATE * (eps * m / delta).abs().max((relax * f).abs()).max(1e-300);
            assert!((got - want).abs() <= 1e-14 * scale, "{got} vs {want}");
        }
        assert_eq!(face_flux_rate(0.5, 1.2, 0.0, 3.0, 0.004, 0.2, 343.0), -FACE_FLUX_RATE * 343.0 / 0.004 * 0.2);
    }
}
