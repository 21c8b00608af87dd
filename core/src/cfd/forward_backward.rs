//! The forward–backward gas step (`gas.time_scheme` = "forward_backward"): the acoustic pair of
//! terms is stepped as Mesinger's forward–backward scheme (Durran, Numerical Methods for Fluid
//! Dynamics, 2nd ed., §3.2.3 and §8.2), the rest of the momentum right-hand side by AB3:
//! 1. the pressure force −ε∇p^n forward (Euler), the other momentum terms (convection, stress,
//!    gravity, interaction force) by Adams–Bashforth from their own history, and the face
//!    corrections F forward (their rates are driven by the pressure mismatch);
//! 2. then the mass fluxes of the new momentum and the new F, with the pressure dissipation of
//!    p^n (rhs.rs), and ρε^{n+1} = ρε^n − Δt ∇·ṁ^{n+1}.
//!
//! For a sound wave of frequency ω this is u^{n+1} = u^n − ωΔt p^n, p^{n+1} = p^n + ωΔt u^{n+1}:
//! neutral (|amplification| = 1, no damping) for ωΔt ≤ 2, against AB3's 0.7236 on the imaginary
//! axis, with a phase error O((ωΔt)²) on waves that the gas's physics does not need resolved
//! in time (the bed's pressure oscillations are ~10 Hz, the cell's acoustic modes ~10⁵ Hz).
//! The gas's dissipations and outlet lower the real edge, so the stable step (stability.rs) uses
//! ωΔt ≤ 1.5 (2.07× AB3's at the same CFL factor; measured edges in docs/VALIDATION.md); the
//! convective and viscous parts keep AB3's bounds. The default scheme: against the paper's
//! every-step coupling a bubbling bed's ΔP and voidage are as accurate as under AB3 at the same
//! coupling interval; being neutral it leaves more of a short pulse behind at the outlet.
//!
//! The mass passes below repeat rhs.rs's face mass flux term by term (the same expressions in
//! the same order); the tests of cfd/tests/forward_backward.rs check them through the steady
//! bed's analytic drop and the mass budget.

use super::params::Outlet;
use super::rhs::{inlet_mass_flux, PrimView, RhsInput, PRESSURE_DISSIPATION};

/// The bound on ωΔt for the acoustic terms (2 for the pure scheme; see the module comment).
pub const FB_ACOUSTIC_LIMIT: f64 = 1.5;

/// ṁ (kg/s) of the axial faces above the cells of layer k (k + 1 < nz) from the momentum of `q`
/// and the corrections of `inp.face_flux`, into slot 0 of each face's row of `axial` (one layer
/// long); the pressure dissipation reads the primitives `pr` (rhs.rs `axial_layer`).
pub fn axial_mass_faces(inp: &RhsInput, q: &[[f64; 4]], pr: &PrimView, k: usize, axial: &mut [[f64; 7]]) {
    let (per, nz, geo, par) = (inp.per, inp.nz, inp.geo, inp.params);
    let (lo, hi) = (k * per, (k + 1) * per);
    let kd = PRESSURE_DISSIPATION / par.sound_speed;
    let (az, dz) = (geo.area_z, inp.dz);
    let corrected = !(k + 2 == nz && par.outlet == Outlet::Characteristic);
    for (c, row) in axial[..per].iter_mut().enumerate() {
        let (i, j) = (lo + c, hi + c);
        let eps_f = 0.5 * (inp.eps[i] + inp.eps[j]);
        let mismatch = (pr.p[j] - pr.p[i]) - 0.5 * (pr.gz[i] + pr.gz[j]) * dz;
        let diss = kd * eps_f * az * mismatch;
        let f = if corrected { inp.face_flux[i] } else { 0.0 };
        row[0] = (0.5 * (q[i][3] + q[j][3]) + f) * az - diss;
    }
}

/// d(ρε)/dt of the cells of layer k (per unit volume) into `out` (one layer long): the horizontal
/// faces' ṁ from the momentum of `qk` (layer k's state) and the corrections of `inp.face_flux`, the axial faces' from
/// `axial` (`axial_mass_faces`), the inlet's from p^n. The characteristic outlet layer gets 0
/// (it follows eq. (5)–(7)).
pub fn mass_layer(inp: &RhsInput, qk: &[[f64; 4]], pr: &PrimView, axial: &[[f64; 7]], k: usize, out: &mut [f64]) {
    let (per, nz, geo, par) = (inp.per, inp.nz, inp.geo, inp.params);
    let out = &mut out[..per];
    out.fill(0.0);
    if k + 1 == nz && par.outlet == Outlet::Characteristic && nz > 1 {
        return;
    }
    let base = k * per;
    let inv_v = 1.0 / geo.volume;
    let kappa_a = PRESSURE_DISSIPATION / par.sound_speed;
    let ff = inp.face_flux_h(k);
    let (eps, p) = (&inp.eps[base..base + per], &pr.p[base..base + per]);
    let (gx, gy, qk) = (&pr.gx[base..base + per], &pr.gy[base..base + per], &qk[..per]);
    for (f, fj) in geo.faces.iter().zip(ff) {
        let (a, b) = (f.a as usize, f.b as usize);
        let eps_f = 0.5 * (eps[a] + eps[b]);
        let mismatch = (p[b] - p[a]) - 0.5 * ((gx[a] + gx[b]) * f.dx + (gy[a] + gy[b]) * f.dy);
        let diss = kappa_a * eps_f * f.s_abs * mismatch;
        let mflux = 0.5 * ((qk[a][1] + qk[b][1]) * f.sx + (qk[a][2] + qk[b][2]) * f.sy) + fj * f.s_abs - diss;
        let d = mflux * inv_v;
        out[a] -= d;
        out[b] += d;
    }
    if k == 0 {
        for (c, r) in out.iter_mut().enumerate() {
            *r += inlet_mass_flux(inp, pr.p, c) * inv_v;
        }
    } else {
        for (r, f) in out.iter_mut().zip(&axial[(k - 1) * per..k * per]) {
            *r += f[0] * inv_v;
        }
    }
    if k + 1 < nz {
        for (r, f) in out.iter_mut().zip(&axial[base..base + per]) {
            *r -= f[0] * inv_v;
        }
    }
}

/// The momentum rows of a right-hand side without the pressure force, d(ρεu)/dt + ε∇p (the part
/// that AB3 steps), and the mass row cleared (the mass is stepped by `mass_layer`).
pub fn without_pressure_force(rhs: &mut [[f64; 4]], eps: &[f64], pr: &PrimView) {
    for (c, r) in rhs.iter_mut().enumerate() {
        let e = eps[c];
        *r = [0.0, r[1] + e * pr.gx[c], r[2] + e * pr.gy[c], r[3] + e * pr.gz[c]];
    }
}

/// The forward pressure step of the momentum: ρεu −= Δt·ε∇p^n.
pub fn add_pressure_force(q: &mut [[f64; 4]], eps: &[f64], pr: &PrimView, dt: f64) {
    for (c, s) in q.iter_mut().enumerate() {
        let e = dt * eps[c];
        s[1] -= e * pr.gx[c];
        s[2] -= e * pr.gy[c];
        s[3] -= e * pr.gz[c];
    }
}
