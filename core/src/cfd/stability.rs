//! The largest stable gas step: the acoustic CFL limit inside AB3's stability region
//! (PHYSICS.md 7: |λh| ≤ 0.7236 on the imaginary axis, ≥ −6/11 on the negative real axis).
//!
//! Convective/acoustic spectral radius of a cell (central fluxes). A Fourier mode of the linearised
//! central scheme with wave numbers θ_h, θ_z has λ = i[u·k̃ ± a'|k̃|], k̃ = (sin θ_h·H, sin θ_z/dz),
//! H = (1 + n0/π)/dr the horizontal inverse spacing (Blazek's ½Σ|S|/V, geometry::horizontal_inverse_spacing),
//! so the acoustic part adds in quadrature across directions and the convective part linearly:
//!   λ_c = |u_h|·H + |u_z|/dz + a'·√(H² + 1/dz²)
//! (the plain sum (|u_h| + a')H + (|u_z| + a')/dz over-counts the acoustic part by up to √2). On the
//! 44-mm bubbling grid (dz = dr/2) the gas alone from a fluidized state stays bounded for 80 ms at
//! 1.05× this limit and blows up at 1.08× (`bench -- gas-dt`),
//! with a' = a/√(1 − s₀): the face mass-flux correction (rhs.rs, s₀ = FACE_FLUX_RATE) gives a wave
//! of number θ = kδ the frequency² (a/δ)²[sin²θ + 4s₀ sin⁴(θ/2)], at most (a/δ)²/(1 − s₀) for s₀ ≤ ½.
//! Viscous spectral radius of the compact Laplacian with ν = (4μ/3 + L)/ρ:
//!   λ_v = 2ν·max_c Σ_f (|S_f|/δ_f)/V
//! and dt = cfl·1/(λ_c/0.7236 + λ_v/(6/11)), the min over cells. With the forward–backward scheme
//! (forward_backward.rs) the acoustic part's bound is ωΔt ≤ 1.5 instead of 0.7236 (2 for the pure
//! scheme; the dissipations and the outlet lower the measured edge):
//! dt = cfl·1/(λ_a/1.5 + λ_u/0.7236 + λ_v/(6/11)), λ_a the acoustic and λ_u the convective part of λ_c.

use super::ab3::{AB3_IMAGINARY_LIMIT, AB3_REAL_LIMIT};
use super::forward_backward::FB_ACOUSTIC_LIMIT;
use super::geometry::{horizontal_inverse_spacing, FaceGeometry};
use super::params::TimeScheme;
use super::rhs::FACE_FLUX_RATE;
use crate::case::Case;
use crate::grid::CylGrid;

/// Stable step of one cell state (see the module comment).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn cell_stable_dt(
    u_h: f64,
    u_z: f64,
    a: f64,
    nu: f64,
    dr: f64,
    dz: f64,
    n0: usize,
    laplacian_factor: f64,
    cfl: f64,
    scheme: TimeScheme,
) -> f64 {
    let a = a / (1.0 - FACE_FLUX_RATE).sqrt();
    let h = horizontal_inverse_spacing(dr, n0);
    let (lam_u, lam_a) = (u_h * h + u_z / dz, a * (h * h + 1.0 / (dz * dz)).sqrt());
    let lam_v = 2.0 * nu * laplacian_factor;
    let acoustic_limit = match scheme {
        TimeScheme::Ab3 => AB3_IMAGINARY_LIMIT,
        TimeScheme::ForwardBackward => FB_ACOUSTIC_LIMIT,
    };
    cfl / (lam_a / acoustic_limit + lam_u / AB3_IMAGINARY_LIMIT + lam_v / AB3_REAL_LIMIT)
}

/// The stable gas step a case's inlet flow allows before it runs: gas at the outlet density,
/// speed U/ε_inlet in every direction. `None` when the grid or gas parameters are unusable or
/// the grid is beyond `case::bounds::MAX_CELLS` (validation reports those separately).
pub fn case_stable_time_step(case: &Case) -> Option<f64> {
    let g = case.gas.as_ref()?;
    let (radius, dr, dz, n0) = (case.column.diameter_m / 2.0, case.grid.dr_m, case.grid_dz_m(), case.grid.n0);
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if !(ok(radius) && ok(dr) && ok(dz) && dr <= radius && (1..=64).contains(&n0)) {
        return None;
    }
    // The face geometry below is allocated per cell of a layer: a grid beyond the case bounds
    // (refused by `validate`) must not be built here first (issue 22: 1e4 annuli of 64 cells
    // asked for ~50 GB).
    if n0 as f64 * (radius / dr).round().powi(2) > crate::case::bounds::MAX_CELLS {
        return None;
    }
    let (a, rho) = (g.acoustic_speed_m_s(), g.outlet_density_kg_m3());
    if !(ok(a) && ok(rho) && ok(g.inlet_voidage) && ok(g.cfl_factor)) {
        return None;
    }
    let geo = FaceGeometry::new(&CylGrid::new(radius, 2.0 * dz, dr, dz, n0));
    let u = g.superficial_velocity_m_s.abs() / g.inlet_voidage;
    let nu = (4.0 / 3.0 * g.viscosity_pa_s + g.bulk_viscosity_pa_s) / rho;
    Some(cell_stable_dt(u, u, a, nu, dr, dz, n0, geo.max_laplacian_factor, g.cfl_factor, g.time_scheme))
}
