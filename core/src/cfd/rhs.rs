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
//! - pressure −ε∇p by Green–Gauss with face value ½(p_a + p_b), model A (PHYSICS.md 11);
//! - a pressure dissipation in the mass flux against the odd–even decoupling of collocated central
//!   schemes (Rhie–Chow type): ṁ −= (κ/a)ε_f|S|[(p_b − p_a) − ½(∇p_a + ∇p_b)·d], d = x_b − x_a,
//!   ε_f the mean voidage of the two cells (keeps its damping rate 4κa/dz independent of ε), κ = 0.05.
//!   It vanishes for any linear pressure field and scales as κ a dz³∂⁴ρ on smooth waves; without it,
//!   half the acoustic modes of a column with the characteristic outlet are undamped and the
//!   linearly extrapolated inlet pressure makes some grow (semi-discrete eigenvalues; see the report);
//! - plus the face correction F·|S| (state, one per face), the Rhie–Chow momentum interpolation whose
//!   steady value is the Darcy flux of the same mismatch (cfd/mod.rs "Face mass flux");
//! - stress ε∇·τ with τ = μ(∇u + ∇uᵀ) + (L − 2μ/3)(∇·u)I; for constant μ, ∇·τ = μ∇²u + (L + μ/3)∇(∇·u),
//!   discretised as the compact face flux μ|S|/δ·(u_b − u_a) + (L + μ/3)·½(D_a + D_b)·S (eq. A.5–A.11).
//!
//! Sources: ρε g (−z) and the interaction force I (eq. A.12).

use super::boundary::ramped_superficial_velocity;
use super::geometry::FaceGeometry;
use super::params::{GasParams, Outlet};
use super::smart::smart_face;

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
            beta: z,
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
        }
    }
}

/// The fields of `Primitives` as the passes read them: borrowed slices, so that a team of threads
/// can read some fields while it still writes others (cfd/team_rhs.rs).
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
}

impl RhsInput<'_> {
    /// Interstitial inlet velocity U(t)/ε_inlet and the inlet mass flux per area factor U(t).
    fn inlet(&self) -> (f64, f64) {
        let p = self.params;
        let u = ramped_superficial_velocity(p.superficial_velocity, p.ramp_time, self.time);
        (u / p.inlet_voidage, u)
    }
    /// The horizontal-face corrections of layer k.
    #[inline]
    fn face_flux_h(&self, k: usize) -> &[f64] {
        let (n, nf) = (self.per * self.nz, self.geo.faces.len());
        &self.face_flux[n + k * nf..n + (k + 1) * nf]
    }
}

/// Fill the primitive fields of one layer from the state.
#[allow(clippy::too_many_arguments)]
pub fn primitives_layer(
    inp: &RhsInput,
    q: &[[f64; 4]],
    k: usize,
    ux: &mut [f64],
    uy: &mut [f64],
    uz: &mut [f64],
    p: &mut [f64],
    beta: &mut [f64],
) {
    let a2 = inp.params.sound_speed * inp.params.sound_speed;
    let base = k * inp.per;
    for c in 0..inp.per {
        let s = q[base + c];
        let inv = 1.0 / s[0];
        ux[c] = s[1] * inv;
        uy[c] = s[2] * inv;
        uz[c] = s[3] * inv;
        // Isothermal gas p = ρa², ρ = (ρε)/ε (PHYSICS.md 8).
        p[c] = a2 * s[0] / inp.eps[base + c];
        // β = |I|/|u|: the drag coefficient when I = −β(u − v) and the particles are slow; only
        // the relaxation of the face correction uses it (a floor of 1 µm/s on |u|).
        let f = inp.force[base + c];
        let fm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        let um = (ux[c] * ux[c] + uy[c] * uy[c] + uz[c] * uz[c]).sqrt();
        beta[c] = if fm > 0.0 { fm / um.max(1e-6) } else { 0.0 };
    }
}

/// Coefficient κ of the pressure dissipation in the mass flux (module comment).
pub const PRESSURE_DISSIPATION: f64 = 0.05;

/// Rate factor s₀ of the face mass-flux correction (module comment): it sets the frequency of the
/// odd–even mode, ω ≤ 2a√s/δ, and raises the acoustic spectral radius of the central scheme to at
/// most a/(δ√(1 − s₀)) (stability.rs); the steady state does not depend on it.
pub const FACE_FLUX_RATE: f64 = 0.1;

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

/// ∇·u and ∇p of one layer's cells by Green–Gauss: (1/V) Σ φ_f S with face means; the tube wall
/// takes the cell's own values (u·n = 0, p_f = p_c); the ends as in the functions above (the inlet
/// face velocity U/ε_in, a shut top 0, the outlet zero-gradient).
#[allow(clippy::too_many_arguments)]
pub fn gradients_layer(
    inp: &RhsInput,
    pr: &PrimView,
    k: usize,
    div: &mut [f64],
    gx: &mut [f64],
    gy: &mut [f64],
    gz: &mut [f64],
) {
    let (per, base, geo, par) = (inp.per, k * inp.per, inp.geo, inp.params);
    let a2 = par.sound_speed * par.sound_speed;
    for c in 0..per {
        div[c] = 0.0;
        gx[c] = 0.0;
        gy[c] = 0.0;
    }
    for f in &geo.faces {
        let (la, lb) = (f.a as usize, f.b as usize);
        let (a, b) = (base + la, base + lb);
        let flux = 0.5 * ((pr.ux[a] + pr.ux[b]) * f.sx + (pr.uy[a] + pr.uy[b]) * f.sy);
        div[la] += flux;
        div[lb] -= flux;
        // (p_f − p_c)·S_out is ½(p_b − p_a)·S for both cells.
        let dp = 0.5 * (pr.p[b] - pr.p[a]);
        gx[la] += dp * f.sx;
        gy[la] += dp * f.sy;
        gx[lb] += dp * f.sx;
        gy[lb] += dp * f.sy;
    }
    let (w_in, _) = inp.inlet();
    let (inv_v, az) = (1.0 / geo.volume, geo.area_z);
    for c in 0..per {
        let i = base + c;
        let (w_bot, p_bot) = if k == 0 {
            (w_in, inlet_face_pressure(pr.p[i], (inp.nz > 1).then(|| pr.p[i + per]), par.gravity, inp.dz, a2))
        } else {
            (0.5 * (pr.uz[i - per] + pr.uz[i]), 0.5 * (pr.p[i - per] + pr.p[i]))
        };
        let (w_top, p_top) = if k + 1 < inp.nz {
            (0.5 * (pr.uz[i] + pr.uz[i + per]), 0.5 * (pr.p[i] + pr.p[i + per]))
        } else {
            let p_below = if k > 0 { pr.p[i - per] } else { pr.p[i] };
            let w = if par.outlet == Outlet::Wall { 0.0 } else { pr.uz[i] };
            (w, top_face_pressure(par.outlet, pr.p[i], p_below, par.gravity, inp.dz, a2))
        };
        div[c] = (div[c] + (w_top - w_bot) * az) * inv_v;
        gx[c] *= inv_v;
        gy[c] *= inv_v;
        gz[c] = (p_top - p_bot) * az * inv_v;
    }
}

/// Rate of change of one face's mass-flux correction F (module comment):
/// dF/dt = −s·[ε_f·m/δ + β_f F/(ρ_f ε_f)], s = s₀/(1 + β_f δ/(ρ_f ε_f a)), m = (p_b − p_a) − ḡ·d.
/// Its steady value is the Darcy flux of the mismatch, F = −(ρ_f ε_f²/β_f)·m/δ.
/// With D = ρ_f ε_f this is −s₀a·(ε_f m D/δ + β_f F)/(D a + β_f δ): one division per face.
#[inline]
pub fn face_flux_rate(eps_f: f64, rho_f: f64, beta_f: f64, mismatch: f64, delta: f64, f: f64, a: f64) -> f64 {
    let s0a = FACE_FLUX_RATE * a;
    if beta_f <= 0.0 {
        // Drag-free gas: no correction (the κ dissipation handles the mode, as the characteristic
        // outlet expects); a correction left from earlier drag decays at s₀a/δ.
        return -s0a / delta * f;
    }
    let d = rho_f * eps_f;
    -s0a * (eps_f * mismatch * d + beta_f * f * delta) / (delta * (d * a + beta_f * delta))
}

/// Mass flux (kg/s) into cell i of the bottom layer through the inlet: ṁ = ρ_f·U(t)·A_z, with the
/// face density of the hydrostatic ghost.
#[inline]
pub fn inlet_mass_flux(inp: &RhsInput, p: &[f64], i: usize) -> f64 {
    let (par, a2) = (inp.params, inp.params.sound_speed * inp.params.sound_speed);
    let (_, u_in) = inp.inlet();
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

/// Fluxes across the axial face between cell `lo` (layer kl) and the cell above it: the convective
/// flux upward [ṁ, ṁu_x, ṁu_y, ṁu_z], the viscous force on `lo` and dF/dt of the face.
#[inline]
fn axial_face(inp: &RhsInput, q: &[[f64; 4]], pr: &PrimView, kl: usize, lo: usize) -> ([f64; 4], [f64; 3], f64) {
    let (per, geo, par) = (inp.per, inp.geo, inp.params);
    let hi = lo + per;
    let az = geo.area_z;
    let eps_f = 0.5 * (inp.eps[lo] + inp.eps[hi]);
    let mismatch = (pr.p[hi] - pr.p[lo]) - 0.5 * (pr.gz[lo] + pr.gz[hi]) * inp.dz;
    let diss = PRESSURE_DISSIPATION / par.sound_speed * eps_f * az * mismatch;
    // The face into the characteristic outlet layer carries no correction: that layer follows
    // eq. (5)–(7), and a correction there reflects outgoing waves (2 % instead of 0.9 %).
    let corrected = !(kl + 2 == inp.nz && par.outlet == Outlet::Characteristic);
    let ff = if corrected { inp.face_flux[lo] } else { 0.0 };
    let mflux = (0.5 * (q[lo][3] + q[hi][3]) + ff) * az - diss;
    let a = par.sound_speed;
    let rho_f = 0.5 * (pr.p[lo] + pr.p[hi]) / (a * a);
    let dff = if corrected {
        face_flux_rate(eps_f, rho_f, 0.5 * (pr.beta[lo] + pr.beta[hi]), mismatch, inp.dz, ff, a)
    } else {
        0.0
    };
    // Upwind cell C, its upwind U (None at the ends: first-order upwind) and downwind D.
    let (c, u, d) = if mflux >= 0.0 {
        (lo, if kl >= 1 { Some(lo - per) } else { None }, hi)
    } else {
        (hi, if kl + 2 < inp.nz { Some(hi + per) } else { None }, lo)
    };
    let face = |v: &[f64]| match u {
        Some(u) => smart_face(v[u], v[c], v[d]),
        None => v[c],
    };
    let conv = [mflux, mflux * face(pr.ux), mflux * face(pr.uy), mflux * face(pr.uz)];
    let m = par.viscosity * az / inp.dz;
    let lam = (par.bulk_viscosity + par.viscosity / 3.0) * 0.5 * (pr.div[lo] + pr.div[hi]) * az;
    let visc = [m * (pr.ux[hi] - pr.ux[lo]), m * (pr.uy[hi] - pr.uy[lo]), m * (pr.uz[hi] - pr.uz[lo]) + lam];
    (conv, visc, dff)
}

/// The axial faces above the cells of layer k (k + 1 < nz), computed once for both layers they
/// join: per face [ṁ, ṁu_x, ṁu_y, ṁu_z, viscous force on the lower cell (3)] into `out` and dF/dt
/// into `out_fz` (one layer long).
pub fn axial_layer(inp: &RhsInput, q: &[[f64; 4]], pr: &PrimView, k: usize, out: &mut [[f64; 7]], out_fz: &mut [f64]) {
    let base = k * inp.per;
    for c in 0..inp.per {
        let (conv, visc, dff) = axial_face(inp, q, pr, k, base + c);
        out[c] = [conv[0], conv[1], conv[2], conv[3], visc[0], visc[1], visc[2]];
        out_fz[c] = dff;
    }
}

#[allow(clippy::needless_range_loop)] // cells are indexed in several arrays at once
/// d q/dt of every cell of layer k (per unit volume) into `out` (one layer long), and dF/dt of the
/// layer's horizontal face corrections into `out_fh`; `axial` holds the axial faces of
/// `axial_layer` (the one below layer k at index k − 1, the one above at k).
pub fn residual_layer(
    inp: &RhsInput,
    q: &[[f64; 4]],
    pr: &PrimView,
    axial: &[[f64; 7]],
    k: usize,
    out: &mut [[f64; 4]],
    out_fh: &mut [f64],
) {
    let (per, geo, par) = (inp.per, inp.geo, inp.params);
    let base = k * per;
    if k + 1 == inp.nz && par.outlet == Outlet::Characteristic && inp.nz > 1 {
        // The outlet layer follows eq. (5)–(7) instead of the fluxes (solver.rs).
        out.iter_mut().for_each(|r| *r = [0.0; 4]);
        out_fh.iter_mut().for_each(|r| *r = 0.0);
        return;
    }
    // Sources: interaction force (cylindrical → Cartesian), gravity ρεg, pressure −ε∇p.
    for c in 0..per {
        let i = base + c;
        let f = inp.force[i];
        let (fx, fy) = geo.to_cartesian(c, f[0], f[1]);
        let e = inp.eps[i];
        out[c] = [0.0, fx - e * pr.gx[i], fy - e * pr.gy[i], f[2] - par.gravity * q[i][0] - e * pr.gz[i]];
    }
    let inv_v = 1.0 / geo.volume;
    let lam_coef = par.bulk_viscosity + par.viscosity / 3.0;
    let kappa_a = PRESSURE_DISSIPATION / par.sound_speed;
    let a2 = par.sound_speed * par.sound_speed;
    let ff_h = inp.face_flux_h(k);
    // Horizontal faces (central in r and θ).
    for (n, f) in geo.faces.iter().enumerate() {
        let (la, lb) = (f.a as usize, f.b as usize);
        let (a, b) = (base + la, base + lb);
        let eps_f = 0.5 * (inp.eps[a] + inp.eps[b]);
        let mismatch = (pr.p[b] - pr.p[a]) - 0.5 * ((pr.gx[a] + pr.gx[b]) * f.dx + (pr.gy[a] + pr.gy[b]) * f.dy);
        let diss = kappa_a * eps_f * f.s_abs * mismatch;
        let mflux = 0.5 * ((q[a][1] + q[b][1]) * f.sx + (q[a][2] + q[b][2]) * f.sy) + ff_h[n] * f.s_abs - diss;
        let rho_f = 0.5 * (pr.p[a] + pr.p[b]) / a2;
        out_fh[n] =
            face_flux_rate(eps_f, rho_f, 0.5 * (pr.beta[a] + pr.beta[b]), mismatch, f.delta, ff_h[n], par.sound_speed);
        let h = 0.5 * mflux * inv_v;
        let conv = [mflux * inv_v, h * (pr.ux[a] + pr.ux[b]), h * (pr.uy[a] + pr.uy[b]), h * (pr.uz[a] + pr.uz[b])];
        let m = par.viscosity * f.area_over_delta * inv_v;
        let lam = lam_coef * 0.5 * (pr.div[a] + pr.div[b]) * inv_v;
        let v =
            [m * (pr.ux[b] - pr.ux[a]) + lam * f.sx, m * (pr.uy[b] - pr.uy[a]) + lam * f.sy, m * (pr.uz[b] - pr.uz[a])];
        let (ea, eb) = (inp.eps[a], inp.eps[b]);
        let ra = &mut out[la];
        ra[0] -= conv[0];
        for n in 0..3 {
            ra[n + 1] += ea * v[n] - conv[n + 1];
        }
        let rb = &mut out[lb];
        rb[0] += conv[0];
        for n in 0..3 {
            rb[n + 1] += conv[n + 1] - eb * v[n];
        }
    }
    // Axial faces: bottom and top of this layer (each computed identically by both layers).
    let (w_in, _) = inp.inlet();
    for c in 0..per {
        let i = base + c;
        let e = inp.eps[i] * inv_v;
        let r = &mut out[c];
        if k == 0 {
            // Inlet: ṁ = ρ_f·U(t)·A_z with the face density of the hydrostatic ghost, momentum
            // flux ṁ·U(t)/ε_in (vertical only), no viscous flux.
            let m_in = inlet_mass_flux(inp, pr.p, i);
            r[0] += m_in * inv_v;
            r[3] += m_in * w_in * inv_v;
        } else {
            let f = &axial[i - per];
            for n in 0..4 {
                r[n] += f[n] * inv_v;
            }
            for n in 0..3 {
                r[n + 1] -= e * f[n + 4];
            }
        }
        if k + 1 < inp.nz {
            let f = &axial[i];
            for n in 0..4 {
                r[n] -= f[n] * inv_v;
            }
            for n in 0..3 {
                r[n + 1] += e * f[n + 4];
            }
        }
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
