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
//! Face mass flux (rhs.rs): ṁ = [½(m_a + m_b) + F]·|S| − (κ/a)ε_f|S|·m, with the pressure mismatch
//! m = (p_b − p_a) − ½(∇p_a + ∇p_b)·d (zero for any linear p and, to O(dz³), for the hydrostatic
//! state). Central fluxes alone leave an odd–even pressure mode: the weak κ = 0.1 dissipation
//! damps it in time, but in a drag-dominated bed the steady state kept it (layer drops alternating
//! ±69 % of the Beetstra value at ε = 0.727, ±90 % at ε = 0.4; cfd/tests/layer_pressure.rs).
//! F is a momentum-interpolation (Rhie–Chow) correction carried as state on every face with its
//! own equation, dF/dt = −s[ε_f m/δ + β_f F/(ρ_f ε_f)] (δ the centre distance, β = |I|/|u| per
//! cell, face values the means): its steady value is the Darcy flux of the mismatch,
//! F = −(ρ_f ε_f²/β_f)·m/δ, i.e. the face flux of the cells' drag balance u = −ε∇p/β, so the steady
//! pressure of a bed is compact and ripple-free whatever the time step. Carried in time, F makes
//! the odd–even mode a wave (as on a staggered grid) instead of a stiff pressure diffusion (the
//! Darcy diffusivity ρa²ε/β, ~250 m²/s in a light bed, is far outside explicit reach):
//! s = s₀/(1 + β_f δ/(ρ_f ε_f a)), s₀ = 0.1, keeps its frequency and its relaxation rate below
//! a/δ; the central scheme's acoustic bound becomes a/√(1 − s₀) (stability.rs). F is antisymmetric
//! per face (mass is conserved to round-off), vanishes in free stream and at rest, decays to zero in
//! drag-free gas (β = 0: there κ and κ_m below handle the mode; with F there the characteristic
//! outlet reflected 1.7–1.9 %), and is off on the face into
//! the outlet layer.
//!
//! Where the drag jumps (a bed surface, a bubble's edge), the central gradient of a cell next to the
//! jump sees half of its neighbour's drag gradient; a free cell cannot balance that, so the steady
//! state used to hold an odd–even mode above a bed (issue 22, item 6a: ±9 Pa in the quickstart's
//! freeboard), which in free gas κ alone decays only over dz·√(a/(8κU)), ~40 layers. Two terms
//! remove it, both zero for smooth fields:
//! - Drag-weighted face pressure in the Green–Gauss gradient (body-force weighting, Mencinger & Žun,
//!   J. Comput. Phys. 221, 2007): p_f = ½(p_a + p_b) + ¼(B_b − B_a)(j_f·d), B = β/ε², j_f the mean
//!   superficial velocity εu (rhs.rs `drag_weighted_face_pressure`). Each cell's gradient is then its
//!   own drag balance −βu/ε, across ε jumps as well; O(d²) for smooth β/ε²; zero in drag-free gas;
//!   independent of the odd–even part of u (it uses the face mean), so the drag still damps that.
//!   `pressure_gradient_cyl` (the particles' −V_p∇p) uses the same face pressures.
//! - Momentum dissipation κ_m on the axial faces' flux of ρεu_z: −κ_m a|S|·[(m_b − m_a) −
//!   ½(∇m_a + ∇m_b)·d] = +¼κ_m a|S|·δ³m (third difference), the ρεu_z half of the low-Mach Roe
//!   dissipation |A| = aI whose ρ half is κ, κ_m = κ = 0.1. With both, the odd–even envelope decays
//!   over dz/(4√(κκ_m)), 2.5 layers, and the outlet reflects 0.12 % instead of 0.87 % (the
//!   dissipation then acts on both characteristics alike). In a bed's steady state ρεu is uniform
//!   (the weighted gradient gives every cell its drag balance), so κ_m leaves the drop alone.
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
//!   velocity. The face pressure extrapolates p·exp(gz/a²) linearly from layers 0 and 1
//!   (rhs.rs `inlet_face_pressure`: exact for the hydrostatic state and for a bed's linear drag
//!   gradient, which the former hydrostatic ghost halved in layer 0), the face density ρ_f = p_f/a²,
//!   the mass flux ρ_f·U(t)·A_z (i.e. ρ_f·ε_in·U/ε_in), its momentum flux that times U(t)/ε_in; no
//!   viscous flux. With U = 0 it is a wall. An inlet voidage below the bed's adds the jet's momentum
//!   flux ρU²(1/ε_in − 1/ε) to layer 0 (in a 0.727 bed fed at ε_in = 0.4: −6 % on the drop of
//!   layers 0–1).
//! - Outlet (top layer): the characteristic condition of eq. (5)–(7) with the typo mended
//!   (PHYSICS.md 9). The top layer is not updated by fluxes: each step its momentum changes copy the
//!   layer below (as changes of ρU, i.e. divided by that layer's ε and multiplied by its own), and
//!   Δρ = [Δ(ρU_z) − Δt·K·a(ρ − ρ_∞)]/(U_z + a), K = σ(1 − M²)a/H (σ = gas.outlet_relaxation,
//!   ρ_∞ the hydrostatic density of outlet_pressure_pa at the top cell centre). `Outlet::Wall` shuts it.

mod ab3;
mod boundary;
mod forward_backward;
mod geometry;
mod implicit_drag;
mod inlet_jet;
mod mass_budget;
mod params;
mod rhs;
mod rhs_layers;
mod smart;
mod solver;
mod stability;
mod team_step;
mod voidage_ramp;

#[cfg(test)]
mod tests;

pub use ab3::{ab2_weights, ab3_weights, AB3_IMAGINARY_LIMIT, AB3_REAL_LIMIT};
pub use boundary::{outlet_density_change, ramped_superficial_velocity};
pub use geometry::{horizontal_inverse_spacing, FaceGeometry, HFace, Neighbour};
pub use inlet_jet::InletJet;
pub use mass_budget::{MassBalance, MassBudget};
pub use params::{GasParams, Outlet, TimeScheme};
pub use rhs::FACE_FLUX_RATE;
pub use smart::smart_face;
pub use solver::{GasSolver, PARALLEL_MIN_CELLS};
pub use stability::{case_stable_time_step, cell_stable_dt};
pub use voidage_ramp::VoidageRamp;
