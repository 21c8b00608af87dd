//! The compressible, volume-averaged gas solver on the cylindrical grid (paper section 2.2, Appendix A).
//!
//! State: the conserved quantities of eq. (A.2) per cell, ρε and ρε·u. Momentum is stored with
//! Cartesian components (ρεu_x, ρεu_y, ρεu_z); a cell's (ρεU_r, ρεU_θ) is their rotation into the
//! cylindrical basis at the cell centre angle, a fixed per-cell map applied at the API
//! (`velocity_cyl`, `interaction_force_mut`). With this, every face flux between cells whose bases
//! differ is an exact vector sum, and the geometric source terms S of eq. (A.12) (ρU_θ²/r, ρU_rU_θ/r,
//! τ_θθ/r, τ_θr/r) are produced by the exact face vector areas instead of centre values.
//!
//! Schemes: central mass fluxes; momentum convection central in r and θ, QUICK+SMART in z
//! (PHYSICS.md 6); pressure −ε∇p (model A, PHYSICS.md 11) by Green–Gauss; viscous stress with μ and
//! bulk viscosity L; gravity ρεg; interaction force I (per unit volume, given from outside);
//! Heun → AB2 → AB3 in time (PHYSICS.md 7). `stable_dt` is the acoustic CFL limit inside AB3's
//! region (stability.rs).
//!
//! Boundaries:
//! - Tube wall (r = R): full slip. No mass, momentum or viscous flux; the wall pressure is the
//!   cell's own pressure (zero normal gradient), so it adds no force in the Green–Gauss sum.
//! - Axis (r = 0): a line of zero area; nothing crosses it. The central annulus' n0 sector cells
//!   exchange mass and momentum through their angular faces (planes from the axis to dr) with
//!   Cartesian components: the paper's "convert the central annulus velocities to x and y" is built
//!   into every face. `axis_velocity(k)` gives the paper's axis value, the x, y average of the
//!   central annulus; no flux uses it because the axis has no area.
//! - Inlet (ghost layer below z = 0): vertical velocity U(t)/ε_inlet (interstitial; U(t) the
//!   superficial velocity ramped linearly from 0 over gas.ramp_time_s), zero radial and angular
//!   velocity. The ghost density is linearly extrapolated from the two layers above, so the face
//!   density is ρ_f = (3ρ₀ − ρ₁)/2, the mass flux ρ_f·U(t)·A_z (i.e. ρ_f·ε_in·U/ε_in), its momentum
//!   flux that times U(t)/ε_in, the face pressure a²ρ_f; no viscous flux. With U = 0 it is a wall.
//! - Outlet (top layer): the characteristic condition of eq. (5)–(7) with the typo mended
//!   (PHYSICS.md 9). The top layer is not updated by fluxes: each step its momentum changes copy the
//!   layer below (as changes of ρU, i.e. divided by that layer's ε and multiplied by its own), and
//!   Δρ = [Δ(ρU_z) − Δt·K·a(ρ − ρ_∞)]/(U_z + a), K = σ(1 − M²)a/H (σ = gas.outlet_relaxation,
//!   ρ_∞ the hydrostatic density of outlet_pressure_pa at the top cell centre). `Outlet::Wall` shuts it.

mod ab3;
mod boundary;
mod geometry;
mod rhs;
mod smart;
mod solver;
mod stability;

#[cfg(test)]
mod tests;

pub use ab3::{ab2_weights, ab3_weights, AB3_IMAGINARY_LIMIT, AB3_REAL_LIMIT};
pub use boundary::{outlet_density_change, ramped_superficial_velocity};
pub use geometry::{horizontal_inverse_spacing, FaceGeometry, HFace, Neighbour};
pub use smart::smart_face;
pub use solver::{GasParams, GasSolver, Outlet};
pub use stability::{case_stable_time_step, cell_stable_dt};
