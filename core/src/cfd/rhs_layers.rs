//! The four per-layer passes of the right-hand side (rhs.rs states the scheme): primitives,
//! gradients, axial faces, residuals. They are written for the compiler's vectoriser: every field
//! re-sliced to one layer, the ends of the column (inlet, top) chosen once per layer instead of
//! per cell, the upwind choice of the axial faces as selects, and the horizontal faces computed in
//! blocks into a stack buffer (gathers only) before they are scattered to their cells in face order.
//! Each pass runs compiled for AVX-512 or AVX2 when the CPU has them and `FLUIDBED_KERNEL` allows
//! (`simd::per_isa`); every path gives the same bits (test `every_code_path_gives_the_same_bits`).

use super::geometry::HFace;
use super::params::Outlet;
use super::rhs::{
    drag_coefficient, drag_weighted_face_pressure, face_flux_rate, inlet_face_pressure, inlet_mass_flux,
    top_face_pressure, PrimView, RhsInput, MOMENTUM_DISSIPATION, PRESSURE_DISSIPATION,
};
use super::smart::smart_face;
use crate::simd::per_isa;

/// Horizontal faces per block of the residual pass (a stack buffer of 7 values each).
const FACE_BLOCK: usize = 32;

/// One layer of a cell field (or of a per-cell row array), cut so that its length is `per` to the
/// compiler: the loops over the layer's cells then carry no bounds checks and vectorise.
#[inline(always)]
fn layer<T>(f: &[T], per: usize, k: usize) -> &[T] {
    &f[k * per..(k + 1) * per][..per]
}

/// The in-layer cells of a face, clamped to the layer: a no-op for a grid's faces (each joins two
/// cells of the layer), which lets the compiler drop the bounds checks of the loops over faces and
/// vectorise them with gathers.
#[inline(always)]
fn in_layer(f: &HFace, per: usize) -> (usize, usize) {
    let last = per.saturating_sub(1);
    ((f.a as usize).min(last), (f.b as usize).min(last))
}

/// Fill the primitive fields of layer k from the state (the output slices one layer long).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn primitives_body(
    inp: &RhsInput,
    q: &[[f64; 4]],
    k: usize,
    ux: &mut [f64],
    uy: &mut [f64],
    uz: &mut [f64],
    p: &mut [f64],
    beta: &mut [f64],
    beta_over_eps2: &mut [f64],
) {
    let per = inp.per;
    let a2 = inp.params.sound_speed * inp.params.sound_speed;
    let (q, eps, force) = (layer(q, per, k), layer(inp.eps, per, k), layer(inp.force, per, k));
    let (ux, uy, uz, p, beta) = (&mut ux[..per], &mut uy[..per], &mut uz[..per], &mut p[..per], &mut beta[..per]);
    let beta_over_eps2 = &mut beta_over_eps2[..per];
    for c in 0..per {
        let s = q[c];
        let inv = 1.0 / s[0];
        let (x, y, z) = (s[1] * inv, s[2] * inv, s[3] * inv);
        (ux[c], uy[c], uz[c]) = (x, y, z);
        // Isothermal gas p = ρa², ρ = (ρε)/ε (PHYSICS.md 8).
        p[c] = a2 * s[0] / eps[c];
        // β for the face correction's relaxation and the drag-weighted face pressures.
        beta[c] = drag_coefficient(force[c], (x, y, z));
        beta_over_eps2[c] = beta[c] / (eps[c] * eps[c]);
    }
}

/// ∇·u and ∇p of layer k by Green–Gauss (rhs.rs `gradients_layer`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn gradients_body(
    inp: &RhsInput,
    pr: &PrimView,
    k: usize,
    div: &mut [f64],
    gx: &mut [f64],
    gy: &mut [f64],
    gz: &mut [f64],
) {
    let (per, nz, geo, par) = (inp.per, inp.nz, inp.geo, inp.params);
    let a2 = par.sound_speed * par.sound_speed;
    let l = |f, k| layer(f, per, k);
    let (ux, uy, uz, p) = (l(pr.ux, k), l(pr.uy, k), l(pr.uz, k), l(pr.p, k));
    let (div, gx, gy, gz) = (&mut div[..per], &mut gx[..per], &mut gy[..per], &mut gz[..per]);
    // β/ε² (`drag_weighted_face_pressure`) and ε per cell of this layer and the layers below and
    // above (this layer's at the column's ends, where they are not read).
    let (kb, ka) = (k.max(1) - 1, (k + 1).min(nz - 1));
    let (bz_b, bz_k, bz_a) = (l(pr.beta_over_eps2, kb), l(pr.beta_over_eps2, k), l(pr.beta_over_eps2, ka));
    let (eps, eps_b, eps_a) = (l(inp.eps, k), l(inp.eps, kb), l(inp.eps, ka));
    div.fill(0.0);
    gx.fill(0.0);
    gy.fill(0.0);
    for f in &geo.faces {
        let (a, b) = in_layer(f, per);
        let (wx, wy) = (0.5 * (ux[a] + ux[b]), 0.5 * (uy[a] + uy[b]));
        let flux = wx * f.sx + wy * f.sy;
        div[a] += flux;
        div[b] -= flux;
        // (p_f − p_c)·S_out with p_f = ½(p_a + p_b) + w: ½(p_b − p_a) + w for a, ½(p_b − p_a) − w for b.
        let dp = 0.5 * (p[b] - p[a]);
        let j = 0.5 * ((eps[a] * ux[a] + eps[b] * ux[b]) * f.dx + (eps[a] * uy[a] + eps[b] * uy[b]) * f.dy);
        let w = drag_weighted_face_pressure(bz_k[a], bz_k[b], j);
        gx[a] += (dp + w) * f.sx;
        gy[a] += (dp + w) * f.sy;
        gx[b] += (dp - w) * f.sx;
        gy[b] += (dp - w) * f.sy;
    }
    let (inv_v, az) = (1.0 / geo.volume, geo.area_z);
    let jz = |lo: f64, hi: f64| 0.5 * (lo + hi) * inp.dz;
    let below = (k > 0).then(|| (l(pr.uz, k - 1), l(pr.p, k - 1)));
    let above = (k + 1 < nz).then(|| (l(pr.uz, k + 1), l(pr.p, k + 1)));
    // Face values (w, p) below and above each cell.
    let inlet =
        |c: usize| (inp.inlet(c).0, inlet_face_pressure(p[c], above.map(|(_, pa)| pa[c]), par.gravity, inp.dz, a2));
    let top = |c: usize| {
        let p_below = below.map_or(p[c], |(_, pb)| pb[c]);
        let w = if par.outlet == Outlet::Wall { 0.0 } else { uz[c] };
        (w, top_face_pressure(par.outlet, p[c], p_below, par.gravity, inp.dz, a2))
    };
    let close =
        |bot: &dyn Fn(usize) -> (f64, f64), up: &dyn Fn(usize) -> (f64, f64), div: &mut [f64], gz: &mut [f64]| {
            for c in 0..per {
                let ((w_bot, p_bot), (w_top, p_top)) = (bot(c), up(c));
                div[c] = (div[c] + (w_top - w_bot) * az) * inv_v;
                gz[c] = (p_top - p_bot) * az * inv_v;
            }
        };
    match (below, above) {
        (Some((uzb, pb)), Some((uza, pa))) => {
            // Interior layers: the common case, one vectorisable loop.
            for c in 0..per {
                let (w_bot, w_top) = (0.5 * (uzb[c] + uz[c]), 0.5 * (uz[c] + uza[c]));
                let (j_bot, j_top) = (jz(eps_b[c] * uzb[c], eps[c] * uz[c]), jz(eps[c] * uz[c], eps_a[c] * uza[c]));
                let p_bot = 0.5 * (pb[c] + p[c]) + drag_weighted_face_pressure(bz_b[c], bz_k[c], j_bot);
                let p_top = 0.5 * (p[c] + pa[c]) + drag_weighted_face_pressure(bz_k[c], bz_a[c], j_top);
                div[c] = (div[c] + (w_top - w_bot) * az) * inv_v;
                gz[c] = (p_top - p_bot) * az * inv_v;
            }
        }
        (Some((uzb, pb)), None) => {
            let bot = |c: usize| {
                let j = jz(eps_b[c] * uzb[c], eps[c] * uz[c]);
                (0.5 * (uzb[c] + uz[c]), 0.5 * (pb[c] + p[c]) + drag_weighted_face_pressure(bz_b[c], bz_k[c], j))
            };
            close(&bot, &top, div, gz)
        }
        (None, Some((uza, pa))) => {
            let up = |c: usize| {
                let j = jz(eps[c] * uz[c], eps_a[c] * uza[c]);
                (0.5 * (uz[c] + uza[c]), 0.5 * (p[c] + pa[c]) + drag_weighted_face_pressure(bz_k[c], bz_a[c], j))
            };
            close(&inlet, &up, div, gz)
        }
        (None, None) => close(&inlet, &top, div, gz),
    }
    for c in 0..per {
        gx[c] *= inv_v;
        gy[c] *= inv_v;
    }
}

/// The axial faces above the cells of layer k (k + 1 < nz): per face [ṁ, ṁu_x, ṁu_y, ṁu_z,
/// viscous force on the lower cell (3)] into `out` and dF/dt into `out_fz` (rhs.rs `axial_layer`).
#[inline(always)]
fn axial_body(inp: &RhsInput, q: &[[f64; 4]], pr: &PrimView, k: usize, out: &mut [[f64; 7]], out_fz: &mut [f64]) {
    let (per, nz, geo, par) = (inp.per, inp.nz, inp.geo, inp.params);
    let (lo, hi) = (k, k + 1);
    // Upwind-upwind layers of an upward and a downward face; at the ends the upwind layer itself,
    // for which SMART gives φ_C: first-order upwind.
    let (below, above) = (if k >= 1 { k - 1 } else { k }, if k + 2 < nz { k + 2 } else { k + 1 });
    let two = |f| (layer(f, per, lo), layer(f, per, hi));
    let ((eps_lo, eps_hi), (p_lo, p_hi)) = (two(inp.eps), two(pr.p));
    let ((gz_lo, gz_hi), (b_lo, b_hi), (d_lo, d_hi)) = (two(pr.gz), two(pr.beta), two(pr.div));
    let (q_lo, q_hi) = (layer(q, per, lo), layer(q, per, hi));
    let four = |f| [layer(f, per, below), layer(f, per, lo), layer(f, per, hi), layer(f, per, above)];
    let (vx, vy, vz) = (four(pr.ux), four(pr.uy), four(pr.uz));
    let ff = layer(inp.face_flux, per, lo);
    let km = MOMENTUM_DISSIPATION * par.sound_speed;
    let (out, out_fz) = (&mut out[..per], &mut out_fz[..per]);
    // ρεu_z of the layers below lo and above hi for the momentum dissipation, parked in the first
    // two slots of each face's output row (overwritten below); beyond the ends the linear ghosts
    // 2m_in − m_0 (inlet flux ρ_f U) and 2m_top − m_below. A separate loop keeps the inlet's
    // function calls out of the main loop, which then has no calls or branches.
    for (c, o) in out.iter_mut().enumerate() {
        o[0] = if k >= 1 {
            q[(k - 1) * per + c][3]
        } else {
            2.0 * inlet_mass_flux(inp, pr.p, c) / geo.area_z - q_lo[c][3]
        };
        o[1] = if k + 2 < nz { q[(k + 2) * per + c][3] } else { 2.0 * q_hi[c][3] - q_lo[c][3] };
    }
    let (az, a, dz) = (geo.area_z, par.sound_speed, inp.dz);
    let kd = PRESSURE_DISSIPATION / par.sound_speed;
    // The face into the characteristic outlet layer carries no correction: that layer follows
    // eq. (5)–(7), and a correction there reflects outgoing waves (2 % instead of 0.9 %).
    let corrected = !(k + 2 == nz && par.outlet == Outlet::Characteristic);
    let m = par.viscosity * az / dz;
    let lam_coef = par.bulk_viscosity + par.viscosity / 3.0;
    for c in 0..per {
        let (ghost_below, ghost_above) = (out[c][0], out[c][1]);
        let eps_f = 0.5 * (eps_lo[c] + eps_hi[c]);
        let mismatch = (p_hi[c] - p_lo[c]) - 0.5 * (gz_lo[c] + gz_hi[c]) * dz;
        let diss = kd * eps_f * az * mismatch;
        let f = if corrected { ff[c] } else { 0.0 };
        let mflux = (0.5 * (q_lo[c][3] + q_hi[c][3]) + f) * az - diss;
        let rho_f = 0.5 * (p_lo[c] + p_hi[c]) / (a * a);
        let rate = face_flux_rate(eps_f, rho_f, 0.5 * (b_lo[c] + b_hi[c]), mismatch, dz, f, a);
        out_fz[c] = if corrected { rate } else { 0.0 };
        let up = mflux >= 0.0;
        let (fx, fy, fz) = (upwind_face(up, &vx, c), upwind_face(up, &vy, c), upwind_face(up, &vz, c));
        let lam = lam_coef * 0.5 * (d_lo[c] + d_hi[c]) * az;
        // Momentum mismatch (m_hi − m_lo) − ½(∇m_lo + ∇m_hi)·dz = −¼ × the third difference.
        let mis_m = -0.25 * (ghost_above - 3.0 * q_hi[c][3] + 3.0 * q_lo[c][3] - ghost_below);
        out[c] = [
            mflux,
            mflux * fx,
            mflux * fy,
            mflux * fz - km * az * mis_m,
            m * (vx[2][c] - vx[1][c]),
            m * (vy[2][c] - vy[1][c]),
            m * (vz[2][c] - vz[1][c]) + lam,
        ];
    }
}

/// SMART face value of cell c's axial face from the layers [below, lo, hi, above] of a field: the
/// upwind cell C, its upwind U and downwind D chosen by the direction of the flux.
#[inline(always)]
fn upwind_face(up: bool, v: &[&[f64]; 4], c: usize) -> f64 {
    let (u, cc, d) = if up { (v[0][c], v[1][c], v[2][c]) } else { (v[3][c], v[2][c], v[1][c]) };
    smart_face(u, cc, d)
}

/// d q/dt of every cell of layer k into `out` and dF/dt of its horizontal face corrections into
/// `out_fh` (rhs.rs `residual_layer`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn residual_body(
    inp: &RhsInput,
    q: &[[f64; 4]],
    pr: &PrimView,
    axial: &[[f64; 7]],
    k: usize,
    out: &mut [[f64; 4]],
    out_fh: &mut [f64],
) {
    let (per, nz, geo, par) = (inp.per, inp.nz, inp.geo, inp.params);
    let nf = geo.faces.len();
    let (out, out_fh) = (&mut out[..per], &mut out_fh[..nf]);
    if k + 1 == nz && par.outlet == Outlet::Characteristic && nz > 1 {
        // The outlet layer follows eq. (5)–(7) instead of the fluxes (solver.rs).
        out.fill([0.0; 4]);
        out_fh.fill(0.0);
        return;
    }
    let l = |f| layer(f, per, k);
    let (eps, force, qk) = (l(inp.eps), layer(inp.force, per, k), layer(q, per, k));
    let (ux, uy, uz, p, beta, div) = (l(pr.ux), l(pr.uy), l(pr.uz), l(pr.p), l(pr.beta), l(pr.div));
    let (gx, gy, gz) = (l(pr.gx), l(pr.gy), l(pr.gz));
    let (cos_c, sin_c) = (&geo.cos_c[..per], &geo.sin_c[..per]);
    // Sources: interaction force (cylindrical → Cartesian), gravity ρεg, pressure −ε∇p.
    for c in 0..per {
        let f = force[c];
        let (co, si) = (cos_c[c], sin_c[c]);
        let (fx, fy) = (f[0] * co - f[1] * si, f[0] * si + f[1] * co);
        let e = eps[c];
        out[c] = [0.0, fx - e * gx[c], fy - e * gy[c], f[2] - par.gravity * qk[c][0] - e * gz[c]];
    }
    let inv_v = 1.0 / geo.volume;
    let lam_coef = par.bulk_viscosity + par.viscosity / 3.0;
    let kappa_a = PRESSURE_DISSIPATION / par.sound_speed;
    let a2 = par.sound_speed * par.sound_speed;
    let ff_h = inp.face_flux_h(k);
    // Horizontal faces (central in r and θ): per face ṁ/V and the momentum changes of its two
    // cells, then scattered in face order.
    let mut buf = [[0.0f64; 7]; FACE_BLOCK];
    for ((faces, ff), rates) in
        geo.faces.chunks(FACE_BLOCK).zip(ff_h.chunks(FACE_BLOCK)).zip(out_fh.chunks_mut(FACE_BLOCK))
    {
        for ((f, (fj, rate)), out) in faces.iter().zip(ff.iter().zip(rates.iter_mut())).zip(buf.iter_mut()) {
            let (a, b) = in_layer(f, per);
            let eps_f = 0.5 * (eps[a] + eps[b]);
            let mismatch = (p[b] - p[a]) - 0.5 * ((gx[a] + gx[b]) * f.dx + (gy[a] + gy[b]) * f.dy);
            let diss = kappa_a * eps_f * f.s_abs * mismatch;
            let mflux = 0.5 * ((qk[a][1] + qk[b][1]) * f.sx + (qk[a][2] + qk[b][2]) * f.sy) + fj * f.s_abs - diss;
            let rho_f = 0.5 * (p[a] + p[b]) / a2;
            *rate = face_flux_rate(eps_f, rho_f, 0.5 * (beta[a] + beta[b]), mismatch, f.delta, *fj, par.sound_speed);
            let h = 0.5 * mflux * inv_v;
            let conv = [h * (ux[a] + ux[b]), h * (uy[a] + uy[b]), h * (uz[a] + uz[b])];
            let m = par.viscosity * f.area_over_delta * inv_v;
            let lam = lam_coef * 0.5 * (div[a] + div[b]) * inv_v;
            let v = [m * (ux[b] - ux[a]) + lam * f.sx, m * (uy[b] - uy[a]) + lam * f.sy, m * (uz[b] - uz[a])];
            let (ea, eb) = (eps[a], eps[b]);
            *out = [
                mflux * inv_v,
                ea * v[0] - conv[0],
                ea * v[1] - conv[1],
                ea * v[2] - conv[2],
                conv[0] - eb * v[0],
                conv[1] - eb * v[1],
                conv[2] - eb * v[2],
            ];
        }
        for (f, d) in faces.iter().zip(&buf) {
            let (a, b) = in_layer(f, per);
            let ra = &mut out[a];
            ra[0] -= d[0];
            (ra[1], ra[2], ra[3]) = (ra[1] + d[1], ra[2] + d[2], ra[3] + d[3]);
            let rb = &mut out[b];
            rb[0] += d[0];
            (rb[1], rb[2], rb[3]) = (rb[1] + d[4], rb[2] + d[5], rb[3] + d[6]);
        }
    }
    // Axial faces: bottom and top of this layer (each computed identically by both layers).
    if k == 0 {
        // Inlet: ṁ = ρ_f·U(t)·A_z with the face density of the hydrostatic ghost, momentum
        // flux ṁ·U(t)/ε_in (vertical only), no viscous flux.
        for (c, r) in out.iter_mut().enumerate() {
            let (w_in, _) = inp.inlet(c);
            let m_in = inlet_mass_flux(inp, pr.p, c);
            r[0] += m_in * inv_v;
            r[3] += m_in * w_in * inv_v;
        }
    } else {
        let below = layer(axial, per, k - 1);
        for c in 0..per {
            let (e, f, r) = (eps[c] * inv_v, &below[c], &mut out[c]);
            for n in 0..4 {
                r[n] += f[n] * inv_v;
            }
            for n in 0..3 {
                r[n + 1] -= e * f[n + 4];
            }
        }
    }
    if k + 1 < nz {
        let above = layer(axial, per, k);
        for c in 0..per {
            let (e, f, r) = (eps[c] * inv_v, &above[c], &mut out[c]);
            for n in 0..4 {
                r[n] -= f[n] * inv_v;
            }
            for n in 0..3 {
                r[n + 1] += e * f[n + 4];
            }
        }
    }
}

per_isa!(
    /// Fill the primitive fields of one layer from the state.
    pub fn primitives_layer, primitives_paths, primitives_body,
    (inp: &RhsInput, q: &[[f64; 4]], k: usize, ux: &mut [f64], uy: &mut [f64], uz: &mut [f64], p: &mut [f64], beta: &mut [f64], beta_over_eps2: &mut [f64])
);
per_isa!(
    /// ∇·u and ∇p of one layer's cells by Green–Gauss: (1/V) Σ φ_f S with face means; the tube
    /// wall takes the cell's own values (u·n = 0, p_f = p_c); the ends as in rhs.rs (the inlet
    /// face velocity U/ε_in, a shut top 0, the outlet zero-gradient).
    pub fn gradients_layer, gradients_paths, gradients_body,
    (inp: &RhsInput, pr: &PrimView, k: usize, div: &mut [f64], gx: &mut [f64], gy: &mut [f64], gz: &mut [f64])
);
per_isa!(
    /// The axial faces above the cells of layer k (k + 1 < nz), computed once for both layers they
    /// join: per face [ṁ, ṁu_x, ṁu_y, ṁu_z, viscous force on the lower cell (3)] into `out` and
    /// dF/dt into `out_fz` (one layer long).
    pub fn axial_layer, axial_paths, axial_body,
    (inp: &RhsInput, q: &[[f64; 4]], pr: &PrimView, k: usize, out: &mut [[f64; 7]], out_fz: &mut [f64])
);
per_isa!(
    /// d q/dt of every cell of layer k (per unit volume) into `out` (one layer long), and dF/dt of
    /// the layer's horizontal face corrections into `out_fh`; `axial` holds the axial faces of
    /// `axial_layer` (the one below layer k at index k − 1, the one above at k).
    pub fn residual_layer, residual_paths, residual_body,
    (inp: &RhsInput, q: &[[f64; 4]], pr: &PrimView, axial: &[[f64; 7]], k: usize, out: &mut [[f64; 4]], out_fh: &mut [f64])
);

#[cfg(test)]
#[path = "rhs_layers_tests.rs"]
mod tests;
