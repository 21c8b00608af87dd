//! `GasSolver`: state, time stepping (Heun → AB2 → AB3, PHYSICS.md 7) and the public API the
//! coupled simulation calls. Boundary and axis decisions are documented in cfd/mod.rs.

use super::ab3::{ab2_weights, ab3_weights, combine};
use super::boundary::{outlet_layer, OutletGeometry};
use super::forward_backward::{add_pressure_force, axial_mass_faces, mass_layer, without_pressure_force};
use super::geometry::FaceGeometry;
use super::implicit_drag::{self, ImplicitDrag};
use super::inlet_jet::InletJet;
use super::mass_budget::{MassBalance, MassBudget};
use super::params::{GasParams, Outlet, TimeScheme};
use super::rhs::{
    drag_coefficient, drag_weighted_face_pressure, inlet_face_pressure, net_mass_inflow, top_face_pressure, Primitives,
    RhsInput,
};
use super::rhs_layers::{axial_layer, gradients_layer, primitives_layer, residual_layer};
use super::stability::cell_stable_dt;
use super::team_step::{fits, team_step, StepInput, StepState};
use super::voidage_ramp::VoidageRamp;
use crate::case::Case;
use crate::grid::CylGrid;
use crate::team::TeamLock;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// What the grid is rebuilt from after a checkpoint.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct GridSpec {
    radius: f64,
    height: f64,
    dr: f64,
    dz: f64,
    n0: usize,
}

/// The complete serialisable state (checkpoints).
#[derive(Clone, Debug, Serialize, Deserialize)]
struct State {
    grid: GridSpec,
    params: GasParams,
    time: f64,
    steps: u64,
    /// Conserved quantities per cell: ρε, ρεu_x, ρεu_y, ρεu_z (Cartesian; see rhs.rs).
    q: Vec<[f64; 4]>,
    eps: Vec<f64>,
    force: Vec<[f64; 3]>,
    /// Right-hand sides of earlier steps (ring; `head` the newest) and the steps between them.
    hist: [Vec<[f64; 4]>; 3],
    hist_h: [f64; 2],
    hist_len: usize,
    head: usize,
    /// Face mass-flux corrections F (rhs.rs, cfd/mod.rs): the axial face above each cell, then each
    /// layer's horizontal faces; and their right-hand sides of earlier steps (same ring as `hist`).
    /// Older checkpoints without them restart F from zero.
    #[serde(default)]
    face_flux: Vec<f64>,
    #[serde(default)]
    hist_face: [Vec<f64>; 3],
    /// `coupling.gas_drag` = "implicit": per cell the drag coefficient a and the gas velocity u₀
    /// (Cartesian) of the last coupling (implicit_drag.rs); empty when the drag is held.
    #[serde(default)]
    drag_coef: Vec<f64>,
    #[serde(default)]
    drag_u0: Vec<[f64; 3]>,
}

/// The volume-averaged compressible gas (paper section 2.2 and Appendix A).
#[derive(Clone, Debug)]
pub struct GasSolver {
    st: State,
    grid: CylGrid,
    geo: FaceGeometry,
    prim: Primitives,
    q_old: Vec<[f64; 4]>,
    face_old: Vec<f64>,
    /// Axial-face fluxes of the current right-hand side (rhs.rs `axial_layer`).
    axial: Vec<[f64; 7]>,
    parallel: bool,
    /// Parallel right-hand sides as one team of threads (team_rhs.rs) rather than four loops.
    team: bool,
    /// Reported minus solver pressure: the case's outlet pressure less the solver's c²ρ_out
    /// (0 at the paper's sound speed; `anchor_pressure`).
    pressure_offset: f64,
    /// The mass budget of the flux-updated cells (mass_budget.rs); checkpointed beside the state.
    budget: MassBudget,
    /// The gas's voidage between couplings when interpolated or extrapolated (voidage_ramp.rs);
    /// checkpointed beside the state.
    ramp: Option<VoidageRamp>,
    /// Per cell (p, β/ε², εu) for `exchange_fields`, which reads each cell's several times.
    face_inputs: Vec<FaceInputs>,
    /// The time scheme (`gas.time_scheme`; set from the case, also on restore).
    scheme: TimeScheme,
    /// d(ρε)/dt of the forward–backward step's mass pass.
    mass_rate: Vec<f64>,
    /// A jet through the distributor (`gas.inlet_jet`; set from the case, also on restore).
    jet: Option<InletJet>,
}

/// What the face pressures of `pressure_gradient_cyl` read of a cell: p, β/ε² and εu (Cartesian).
type FaceInputs = (f64, f64, [f64; 3]);

/// Below this many cells the layers are processed on one thread (the team's hand-offs cost more
/// than they share). `bench -- cfd` on 2 threads, ns per cell-step serial / team: 82 / 114 at 81
/// cells, 68 / 60 at 324, 64 / 50 at 729, 63 / 45 at 1,296 (docs/BENCHMARKS.md, "Scaling").
pub const PARALLEL_MIN_CELLS: usize = 300;

impl GasSolver {
    /// Gas at rest, hydrostatic about `outlet_pressure_pa` at z = height, ε = 1 until set.
    pub fn new(case: &Case, grid: CylGrid) -> GasSolver {
        let g = case.gas.clone().unwrap_or_default();
        let params = GasParams {
            sound_speed: g.acoustic_speed_m_s(),
            viscosity: g.viscosity_pa_s,
            bulk_viscosity: g.bulk_viscosity_pa_s,
            gravity: case.gravity_m_s2,
            superficial_velocity: g.superficial_velocity_m_s,
            ramp_time: g.ramp_time_s,
            inlet_voidage: g.inlet_voidage,
            outlet_relaxation: g.outlet_relaxation,
            // The solver's p = c²ρ at the outlet density, c = f·a (reported pressures add the offset).
            outlet_pressure: g.outlet_pressure_pa * g.acoustic_speed_factor * g.acoustic_speed_factor,
            cfl_factor: g.cfl_factor,
            outlet: Outlet::Characteristic,
        };
        let n = grid.num_cells();
        let spec = GridSpec { radius: grid.radius, height: grid.height, dr: grid.dr, dz: grid.dz, n0: grid.n0 };
        let st = State {
            grid: spec,
            params,
            time: 0.0,
            steps: 0,
            q: vec![[0.0; 4]; n],
            eps: vec![1.0; n],
            force: vec![[0.0; 3]; n],
            hist: [vec![[0.0; 4]; n], vec![[0.0; 4]; n], vec![[0.0; 4]; n]],
            hist_h: [0.0; 2],
            hist_len: 0,
            head: 0,
            face_flux: Vec::new(),
            hist_face: Default::default(),
            drag_coef: Vec::new(),
            drag_u0: Vec::new(),
        };
        let mut s = GasSolver::from_state(st, grid);
        s.scheme = g.time_scheme;
        s.set_inlet_jet(g.inlet_jet.as_ref());
        s.anchor_pressure(g.outlet_pressure_pa);
        for c in 0..n {
            let rho = s.hydrostatic_density(c);
            s.st.q[c] = [rho, 0.0, 0.0, 0.0];
        }
        s
    }

    fn from_state(mut st: State, grid: CylGrid) -> GasSolver {
        let n = grid.num_cells();
        let geo = FaceGeometry::new(&grid);
        let nf = n + grid.nz * geo.faces.len();
        // A forward–backward run keeps one slot of face right-hand sides (`take_face_slot`).
        let slots_fit = st.hist_face.iter().all(|h| h.len() == nf || h.is_empty());
        if st.face_flux.len() != nf || !slots_fit || st.hist_face.iter().all(|h| h.is_empty()) {
            st.face_flux = vec![0.0; nf];
            st.hist_face = [vec![0.0; nf], vec![0.0; nf], vec![0.0; nf]];
        }
        GasSolver {
            st,
            geo,
            prim: Primitives::new(n),
            q_old: vec![[0.0; 4]; n],
            face_old: vec![0.0; nf],
            axial: vec![[0.0; 7]; n],
            parallel: n >= PARALLEL_MIN_CELLS,
            team: true,
            pressure_offset: 0.0,
            budget: MassBudget::default(),
            ramp: None,
            face_inputs: Vec::new(),
            // The checkpoint holds no scheme: the default until set (`Simulation::restore` sets the case's).
            scheme: TimeScheme::default(),
            mass_rate: vec![0.0; n],
            jet: None,
            grid,
        }
    }

    /// ρ(z) = (p_out/a²)·exp(g(H − z)/a²) at the centre of cell c (PHYSICS.md 8).
    pub fn hydrostatic_density(&self, cell: usize) -> f64 {
        let p = &self.st.params;
        let a2 = p.sound_speed * p.sound_speed;
        let z = self.grid.centre_xyz(cell)[2];
        p.outlet_pressure / a2 * (p.gravity * (self.grid.height - z) / a2).exp()
    }

    pub fn grid(&self) -> &CylGrid {
        &self.grid
    }
    pub fn params(&self) -> &GasParams {
        &self.st.params
    }
    /// Change the top boundary (default: characteristic outlet).
    /// Set the inlet's superficial velocity (the ramp, if still running, now leads to this value).
    pub fn set_superficial_velocity(&mut self, u: f64) {
        self.st.params.superficial_velocity = u;
    }
    pub fn set_outlet(&mut self, outlet: Outlet) {
        self.st.params.outlet = outlet;
    }
    /// Process layers on rayon's pool (default: on for grids of 20,000 cells or more).
    pub fn set_parallel(&mut self, on: bool) {
        self.parallel = on;
    }
    /// Run parallel right-hand sides as one team of threads when the pool is free for one (default
    /// on); off, as four parallel loops (the same bits; for benchmarks).
    pub fn set_team(&mut self, on: bool) {
        self.team = on;
    }
    /// Recount the steps taken (`Simulation::set_gas_time_scheme`: the count of the new step's length).
    pub fn set_steps(&mut self, steps: u64) {
        self.st.steps = steps;
    }
    /// The jet through the distributor, from the case's `gas.inlet_jet` (a checkpoint's comes from
    /// its case).
    pub fn set_inlet_jet(&mut self, spec: Option<&crate::case::InletJet>) {
        self.jet = spec.map(|j| InletJet::new(j, &self.grid));
    }
    /// The time scheme (a checkpoint's comes from its case).
    pub fn set_time_scheme(&mut self, scheme: TimeScheme) {
        self.scheme = scheme;
    }
    /// Change the time scheme during a run: the multistep history starts again (Heun, or AB1 for
    /// the forward–backward step's other terms), since the two schemes store different right-hand
    /// sides (the forward–backward history lacks the pressure force), and so does the mass budget.
    pub fn switch_time_scheme(&mut self, scheme: TimeScheme) {
        if scheme != self.scheme {
            self.scheme = scheme;
            self.st.hist_len = 0;
            self.budget = MassBudget::default();
        }
    }
    pub fn time_scheme(&self) -> TimeScheme {
        self.scheme
    }
    /// Slots of face right-hand sides held (tests).
    #[cfg(test)]
    pub(crate) fn face_history_slots(&self) -> usize {
        self.st.hist_face.iter().filter(|h| !h.is_empty()).count()
    }
    pub fn time(&self) -> f64 {
        self.st.time
    }
    /// Completed steps.
    pub fn steps(&self) -> u64 {
        self.st.steps
    }

    /// Initial voidage: set ε and keep each cell's density ρ (the gas mass changes). Use once,
    /// before the run starts; during a run use `set_voidage`.
    pub fn set_initial_voidage(&mut self, eps: &[f64]) {
        assert_eq!(eps.len(), self.st.eps.len(), "one voidage per cell");
        for (c, &e) in eps.iter().enumerate() {
            let f = e / self.st.eps[c];
            self.st.q[c].iter_mut().for_each(|v| *v *= f);
            self.st.eps[c] = e;
        }
        self.budget = MassBudget::default();
    }

    /// Voidage per cell. The gas mass ρεV of each cell is held: ρ = (ρε)/ε_new, so displaced gas
    /// shows as a pressure rise.
    pub fn set_voidage(&mut self, eps: &[f64]) {
        assert_eq!(eps.len(), self.st.eps.len(), "one voidage per cell");
        self.st.eps.copy_from_slice(eps);
        self.ramp = None;
    }
    /// Voidage per cell reached over the `span` seconds from `start` (the coupling's time),
    /// starting from the previous ramp's end (voidage_ramp.rs); each step takes ε at its start.
    pub fn ramp_voidage(&mut self, eps: &[f64], start: f64, span: f64, extrapolated: bool) {
        self.ramp = Some(VoidageRamp::next(self.ramp.take(), &self.st.eps, eps, start, span, extrapolated));
    }
    /// The voidage ramp (checkpoints).
    pub fn voidage_ramp(&self) -> Option<&VoidageRamp> {
        self.ramp.as_ref()
    }
    pub fn set_voidage_ramp(&mut self, ramp: Option<VoidageRamp>) {
        self.ramp = ramp;
    }
    pub fn voidage(&self) -> &[f64] {
        &self.st.eps
    }
    /// Interaction force per unit volume on the gas, cylindrical (r, θ, z) in each cell's basis.
    pub fn interaction_force_mut(&mut self) -> &mut [[f64; 3]] {
        &mut self.st.force
    }

    /// The drag on the gas between couplings (implicit_drag.rs): with `Some(a)` (one coefficient
    /// per cell, kg m⁻³ s⁻¹) the interaction force is I₀ − a(u − u₀) from now on, u₀ the gas
    /// velocity now and I₀ `interaction_force_mut`'s; `None` holds I₀. Only the cells up to the
    /// last one with a > 0 are kept: the freeboard above a bed holds no particle.
    pub fn set_implicit_drag(&mut self, coef: Option<&[f64]>) {
        self.st.drag_coef.clear();
        self.st.drag_u0.clear();
        if let Some(a) = coef {
            assert_eq!(a.len(), self.st.q.len(), "one drag coefficient per cell");
            let n = a.iter().rposition(|&x| x != 0.0).map_or(0, |c| c + 1);
            self.st.drag_coef.extend_from_slice(&a[..n]);
            self.st.drag_u0.extend(self.st.q[..n].iter().map(interstitial_velocity));
        }
    }

    /// Set one cell's density ρ and interstitial velocity (U_r, U_θ, U_z) at its current voidage.
    pub fn set_cell(&mut self, cell: usize, rho: f64, u_cyl: [f64; 3]) {
        let c = cell % self.grid.cells_per_layer();
        let (ux, uy) = self.geo.to_cartesian(c, u_cyl[0], u_cyl[1]);
        let re = rho * self.st.eps[cell];
        self.st.q[cell] = [re, re * ux, re * uy, re * u_cyl[2]];
        self.budget = MassBudget::default();
    }

    /// ρ (not ρε).
    pub fn density(&self, cell: usize) -> f64 {
        self.st.q[cell][0] / self.st.eps[cell]
    }
    /// Interstitial velocity (U_r, U_θ, U_z) in the cell's cylindrical basis.
    pub fn velocity_cyl(&self, cell: usize) -> [f64; 3] {
        let s = self.st.q[cell];
        let (ur, ut) = self.geo.to_cylindrical(cell % self.grid.cells_per_layer(), s[1] / s[0], s[2] / s[0]);
        [ur, ut, s[3] / s[0]]
    }
    /// Interstitial Cartesian velocity (u_x, u_y, u_z).
    pub fn velocity_xyz(&self, cell: usize) -> [f64; 3] {
        interstitial_velocity(&self.st.q[cell])
    }
    /// Velocity on the axis in layer k: the central annulus' velocities converted to x, y and
    /// averaged (paper section 2.2).
    pub fn axis_velocity(&self, k: usize) -> [f64; 3] {
        let n0 = self.grid.n0;
        let mut v = [0.0; 3];
        for j in 0..n0 {
            let u = self.velocity_xyz(self.grid.index(0, j, k));
            (0..3).for_each(|d| v[d] += u[d] / n0 as f64);
        }
        v
    }
    /// Absolute pressure p = ρa² per cell.
    /// Absolute pressure per cell: p = p_out + c²(ρ − ρ_out), c = f·a (`acoustic_speed_factor`).
    pub fn pressure(&self) -> Vec<f64> {
        (0..self.st.q.len()).map(|c| self.pressure_at(c) + self.pressure_offset).collect()
    }
    /// Report pressures about the case's absolute outlet pressure: the solver carries p = c²ρ,
    /// which differs from it by a constant when c is below the sound speed (gradients are the same).
    pub fn anchor_pressure(&mut self, outlet_pressure_pa: f64) {
        self.pressure_offset = outlet_pressure_pa - self.st.params.outlet_pressure;
    }
    /// The solver's pressure c²ρ (without the reported offset).
    #[inline]
    fn pressure_at(&self, cell: usize) -> f64 {
        let a = self.st.params.sound_speed;
        a * a * self.st.q[cell][0] / self.st.eps[cell]
    }
    /// Σ ρεV.
    pub fn total_mass(&self) -> f64 {
        self.st.q.iter().map(|s| s[0]).sum::<f64>() * self.geo.volume
    }

    /// β/ε² of a cell, with β as the primitives have it (rhs.rs `drag_coefficient`).
    fn drag_over_eps2(&self, cell: usize) -> f64 {
        let (s, e) = (self.st.q[cell], self.st.eps[cell]);
        let inv = 1.0 / s[0];
        drag_coefficient(self.st.force[cell], (s[1] * inv, s[2] * inv, s[3] * inv)) / (e * e)
    }

    /// Superficial velocity εu of a cell, Cartesian.
    fn superficial_xyz(&self, cell: usize) -> [f64; 3] {
        let (s, e) = (self.st.q[cell], self.st.eps[cell]);
        let f = e / s[0];
        [s[1] * f, s[2] * f, s[3] * f]
    }

    /// What the face pressures read of `cell`.
    #[inline]
    fn face_inputs_of(&self, cell: usize) -> FaceInputs {
        (self.pressure_at(cell), self.drag_over_eps2(cell), self.superficial_xyz(cell))
    }

    /// ∇p at the cell centre as (∂p/∂r, (1/r)∂p/∂θ, ∂p/∂z): the Green–Gauss gradient of the
    /// momentum equation (rhs.rs `gradients_layer`: wall faces p_c, the ends as documented there).
    pub fn pressure_gradient_cyl(&self, cell: usize) -> [f64; 3] {
        self.gradient_from(cell, |c| self.face_inputs_of(c))
    }

    /// `pressure_gradient_cyl` from the cells' (p, β/ε², εu) as `at` gives them.
    #[inline(always)]
    fn gradient_from(&self, cell: usize, at: impl Fn(usize) -> FaceInputs) -> [f64; 3] {
        let per = self.grid.cells_per_layer();
        let (c, k) = (cell % per, cell / per);
        let base = k * per;
        let (pc, bc, jc) = at(cell);
        let (mut gx, mut gy) = (0.0, 0.0);
        for n in self.geo.neighbours(c) {
            let (pn, bn, jn) = at(base + n.c as usize);
            let jd = 0.5 * ((jc[0] + jn[0]) * n.dx + (jc[1] + jn[1]) * n.dy);
            let dp = 0.5 * (pn - pc) + drag_weighted_face_pressure(bc, bn, jd);
            gx += dp * n.sx;
            gy += dp * n.sy;
        }
        let (nz, par, dz) = (self.grid.nz, &self.st.params, self.grid.dz);
        let a2 = par.sound_speed * par.sound_speed;
        let p_bot = if k == 0 {
            inlet_face_pressure(pc, (nz > 1).then(|| at(cell + per).0), par.gravity, dz, a2)
        } else {
            let (pb, bb, jb) = at(cell - per);
            let jd = 0.5 * (jb[2] + jc[2]) * dz;
            0.5 * (pc + pb) + drag_weighted_face_pressure(bb, bc, jd)
        };
        let p_top = if k + 1 < nz {
            let (pa, ba, ja) = at(cell + per);
            let jd = 0.5 * (jc[2] + ja[2]) * dz;
            0.5 * (pc + pa) + drag_weighted_face_pressure(bc, ba, jd)
        } else {
            let p_below = if k > 0 { at(cell - per).0 } else { pc };
            top_face_pressure(par.outlet, pc, p_below, par.gravity, self.grid.dz, a2)
        };
        let gz = (p_top - p_bot) / self.grid.dz;
        let v = self.geo.volume;
        let (gr, gt) = self.geo.to_cylindrical(c, gx / v, gy / v);
        [gr, gt, gz]
    }

    /// ∇p (Cartesian, per cell) of the state at the start of the last step, as its right-hand
    /// side's momentum equation used it (the Green–Gauss gradient of `pressure_gradient_cyl`).
    pub fn last_step_pressure_gradient(&self) -> (&[f64], &[f64], &[f64]) {
        (&self.prim.gx, &self.prim.gy, &self.prim.gz)
    }

    /// A horizontal Cartesian vector of cell `cell` in the cell's cylindrical basis (r, θ).
    pub fn horizontal_to_cylindrical(&self, cell: usize, x: f64, y: f64) -> (f64, f64) {
        self.geo.to_cylindrical(cell % self.grid.cells_per_layer(), x, y)
    }

    /// Largest stable step for the current state (acoustic CFL inside AB3's region; stability.rs).
    pub fn stable_dt(&self) -> f64 {
        let p = &self.st.params;
        let g = &self.grid;
        let nu_num = 4.0 / 3.0 * p.viscosity + p.bulk_viscosity;
        let mut dt = f64::INFINITY;
        for (c, s) in self.st.q.iter().enumerate() {
            let inv = 1.0 / s[0];
            let uh = (s[1] * s[1] + s[2] * s[2]).sqrt() * inv;
            let nu = nu_num * self.st.eps[c] * inv;
            dt = dt.min(cell_stable_dt(
                uh,
                (s[3] * inv).abs(),
                p.sound_speed,
                nu,
                g.dr,
                g.dz,
                g.n0,
                self.geo.max_laplacian_factor,
                p.cfl_factor,
                self.scheme,
            ));
        }
        dt
    }

    /// NaN/Inf or non-positive density anywhere, with the cell (i, j, k) and the quantity.
    pub fn check_finite(&self) -> Result<(), String> {
        const NAMES: [&str; 4] = ["ρε", "ρεu_x", "ρεu_y", "ρεu_z"];
        // One cheap pass (any NaN makes the sum NaN; min of ρε and ε), the details only on failure.
        let (mut sum, mut min_rho, mut min_eps) = (0.0, f64::INFINITY, f64::INFINITY);
        for (s, &e) in self.st.q.iter().zip(&self.st.eps) {
            sum += s[0] + s[1] + s[2] + s[3] + e;
            min_rho = min_rho.min(s[0]);
            min_eps = min_eps.min(e);
        }
        if sum.is_finite() && min_rho > 0.0 && min_eps > 0.0 {
            return Ok(());
        }
        for (c, s) in self.st.q.iter().enumerate() {
            let (i, j, k) = self.grid.ijk(c);
            for (n, v) in s.iter().enumerate() {
                if !v.is_finite() {
                    return Err(format!(
                        "gas {} = {v} in cell (i={i}, j={j}, k={k}) at t = {:.6e} s",
                        NAMES[n], self.st.time
                    ));
                }
            }
            if s[0] <= 0.0 {
                return Err(format!(
                    "gas density ρε = {} ≤ 0 in cell (i={i}, j={j}, k={k}) at t = {:.6e} s",
                    s[0], self.st.time
                ));
            }
            let e = self.st.eps[c];
            if !(e > 0.0 && e.is_finite()) {
                return Err(format!("voidage ε = {e} in cell (i={i}, j={j}, k={k}) at t = {:.6e} s", self.st.time));
            }
        }
        Ok(())
    }

    /// What the particle–gas exchange reads per cell, in layers 0..layers (parallel over layers):
    /// interstitial velocity (U_r, U_θ, U_z), density ρ and ∇p, the same bits as
    /// `pressure_gradient_cyl` from each cell's face inputs computed once.
    pub fn exchange_fields(
        &mut self,
        layers: usize,
        velocity_cyl: &mut [[f64; 3]],
        density: &mut [f64],
        grad_p_cyl: &mut [[f64; 3]],
    ) {
        let (per, nz) = (self.grid.cells_per_layer(), self.grid.nz);
        let layers = layers.min(nz);
        let n = layers * per;
        // The gradients of layer k read layers k − 1 ..= k + 1.
        let read = (layers + 1).min(nz) * per;
        let mut inputs = std::mem::take(&mut self.face_inputs);
        inputs.resize(read, (0.0, 0.0, [0.0; 3]));
        let rows = layers.div_ceil(rayon::current_num_threads().max(1)).max(1);
        inputs.par_chunks_mut(per).with_min_len(rows).enumerate().for_each(|(k, row)| {
            for (c, f) in row.iter_mut().enumerate() {
                *f = self.face_inputs_of(k * per + c);
            }
        });
        let (velocity_cyl, density, grad_p_cyl) = (&mut velocity_cyl[..n], &mut density[..n], &mut grad_p_cyl[..n]);
        let at = |c: usize| inputs[c];
        (velocity_cyl.par_chunks_mut(per), density.par_chunks_mut(per), grad_p_cyl.par_chunks_mut(per))
            .into_par_iter()
            .with_min_len(rows)
            .enumerate()
            .for_each(|(k, (v, r, g))| {
                for c in 0..per {
                    let cell = k * per + c;
                    v[c] = self.velocity_cyl(cell);
                    r[c] = self.density(cell);
                    g[c] = self.gradient_from(cell, at);
                }
            });
        self.face_inputs = inputs;
    }

    /// Advance by dt: Heun for the first step, then AB2, then AB3 with variable-step weights.
    /// The face corrections F are integrated with the cell state by the same scheme. A multistep
    /// step runs as one team of threads (team_step.rs) when the pool is free for one.
    pub fn step(&mut self, dt: f64) {
        if let Some(r) = &self.ramp {
            r.at(self.st.time, &mut self.st.eps);
        }
        self.start_mass_budget();
        let forward_backward = self.scheme == TimeScheme::ForwardBackward;
        if (self.st.hist_len > 0 || forward_backward)
            && self.parallel
            && self.team
            && fits(self.grid.nz, rayon::current_num_threads())
        {
            if let Some(_team) = TeamLock::try_take() {
                return self.team_step(dt);
            }
        }
        if forward_backward {
            return self.forward_backward_step(dt);
        }
        let (t, newest, f_new, g_new) = self.start_step();
        let net_new = self.net_inflow(t);
        let hl = self.st.hist_len;
        // Heun's predictor (no history: w = [dt]), else AB2 or AB3.
        let (w, m) = self.multistep_weights(dt);
        let (i1, i2) = (self.st.head, (self.st.head + 2) % 3);
        {
            let (h, hf) = (&self.st.hist, &self.st.hist_face);
            let fs = [f_new.as_flattened(), h[i1].as_flattened(), h[i2].as_flattened()];
            let gs = [&g_new[..], &hf[i1][..], &hf[i2][..]];
            combine(self.st.q.as_flattened_mut(), self.q_old.as_flattened(), &fs[..=m], &w[..=m]);
            combine(&mut self.st.face_flux, &self.face_old, &gs[..=m], &w[..=m]);
        }
        if let Some(d) = implicit_drag_of(&self.st.drag_coef, &self.st.drag_u0) {
            implicit_drag::apply(&mut self.st.q, d, dt);
        }
        if hl > 0 {
            self.budget.net += self.multistep_inflow(&w[..=m], net_new);
        }
        self.apply_outlet(dt);
        if hl == 0 {
            // Heun corrector: y1 = y0 + h/2 (f(y0) + f(y*)); its right-hand sides live for this
            // first step only.
            let (mut stage, mut face_stage) = (vec![[0.0; 4]; f_new.len()], vec![0.0; g_new.len()]);
            self.rhs_into(t + dt, &mut stage, &mut face_stage);
            combine(
                self.st.q.as_flattened_mut(),
                self.q_old.as_flattened(),
                &[f_new.as_flattened(), stage.as_flattened()],
                &[0.5 * dt, 0.5 * dt],
            );
            combine(&mut self.st.face_flux, &self.face_old, &[&g_new, &face_stage], &[0.5 * dt, 0.5 * dt]);
            if let Some(d) = implicit_drag_of(&self.st.drag_coef, &self.st.drag_u0) {
                implicit_drag::apply(&mut self.st.q, d, dt);
            }
            let net_stage = self.net_inflow(t + dt);
            self.budget.net += 0.5 * dt * net_new + 0.5 * dt * net_stage;
            self.apply_outlet(dt);
        }
        self.push_history(newest, (f_new, g_new, net_new), dt);
    }

    /// One forward–backward step (forward_backward.rs): the momentum's other terms by AB1 → AB2 →
    /// AB3 from their own history, the pressure force and the face corrections forward, then the
    /// mass from the new fluxes.
    fn forward_backward_step(&mut self, dt: f64) {
        let (t, newest, mut f_new, g_new) = self.start_step();
        without_pressure_force(&mut f_new, &self.st.eps, &self.prim.view());
        let (w, m) = self.multistep_weights(dt);
        let (i1, i2) = (self.st.head, (self.st.head + 2) % 3);
        let h = &self.st.hist;
        let fs = [f_new.as_flattened(), h[i1].as_flattened(), h[i2].as_flattened()];
        combine(self.st.q.as_flattened_mut(), self.q_old.as_flattened(), &fs[..=m], &w[..=m]);
        add_pressure_force(&mut self.st.q, &self.st.eps, &self.prim.view(), dt);
        if let Some(d) = implicit_drag_of(&self.st.drag_coef, &self.st.drag_u0) {
            implicit_drag::apply(&mut self.st.q, d, dt);
        }
        combine(&mut self.st.face_flux, &self.face_old, &[&g_new], &[dt]);
        let (per, nz) = (self.grid.cells_per_layer(), self.grid.nz);
        let inp = state_input(&self.st, &self.geo, &self.grid, t, self.jet);
        let pr = self.prim.view();
        for k in 0..nz - 1 {
            axial_mass_faces(&inp, &self.st.q, &pr, k, &mut self.axial[k * per..(k + 1) * per]);
        }
        for k in 0..nz {
            let qk = &self.st.q[k * per..(k + 1) * per];
            mass_layer(&inp, qk, &pr, &self.axial, k, &mut self.mass_rate[k * per..(k + 1) * per]);
        }
        for (s, (s0, r)) in self.st.q.iter_mut().zip(self.q_old.iter().zip(&self.mass_rate)) {
            s[0] = s0[0] + dt * r;
        }
        self.apply_outlet(dt);
        let net_new = self.net_inflow(t);
        self.budget.net += dt * net_new;
        self.push_history(newest, (f_new, g_new, net_new), dt);
    }

    /// `step` for AB2/AB3 as one team (team_step.rs); the caller holds the pool's `TeamLock`.
    fn team_step(&mut self, dt: f64) {
        let newest = (self.st.head + 1) % 3;
        let mut f_new = std::mem::take(&mut self.st.hist[newest]);
        let mut g_new = self.take_face_slot(newest);
        let (i1, i2) = (self.st.head, (self.st.head + 2) % 3);
        let (w, m) = self.multistep_weights(dt);
        let weights = &w[..=m];
        let (h, hf) = (&self.st.hist, &self.st.hist_face);
        let two = [&h[i1][..], &h[i2][..]];
        let two_face = [&hf[i1][..], &hf[i2][..]];
        let forward_backward = self.scheme == TimeScheme::ForwardBackward;
        let past_face = if forward_backward { &two_face[..0] } else { &two_face[..m] };
        let past = &two[..m];
        let inp = StepInput {
            geo: &self.geo,
            params: &self.st.params,
            outlet: OutletGeometry { per: self.grid.cells_per_layer(), dz: self.grid.dz, height: self.grid.height },
            nz: self.grid.nz,
            eps: &self.st.eps,
            force: &self.st.force,
            drag: implicit_drag_of(&self.st.drag_coef, &self.st.drag_u0),
            time: self.st.time,
            jet: self.jet,
            dt,
            weights,
            forward_backward,
            past,
            past_face,
        };
        let s = StepState {
            q: &mut self.st.q,
            face: &mut self.st.face_flux,
            q_old: &mut self.q_old,
            face_old: &mut self.face_old,
            rhs: &mut f_new,
            rhs_face: &mut g_new,
            prim: &mut self.prim,
            axial: &mut self.axial,
            mass_rate: &mut self.mass_rate,
        };
        team_step(&inp, s);
        // The team's primitives and axial faces are those of this step's right-hand side.
        let net_new = self.net_inflow(self.st.time);
        // The forward–backward step moves the mass forward (its inflow over dt), AB the rest.
        self.budget.net += if forward_backward { dt * net_new } else { self.multistep_inflow(weights, net_new) };
        self.push_history(newest, (f_new, g_new, net_new), dt);
    }

    /// The multistep weights times the step for the history there is (AB1, AB2 or AB3: the newest
    /// right-hand side's, then the past ones'), padded to three, and how many past ones they use.
    fn multistep_weights(&self, dt: f64) -> ([f64; 3], usize) {
        let (h1, h2) = (self.st.hist_h[0], self.st.hist_h[1]);
        match self.st.hist_len {
            0 => ([dt, 0.0, 0.0], 0),
            1 => {
                let [a, b] = ab2_weights(dt, h1).map(|w| w * dt);
                ([a, b, 0.0], 1)
            }
            _ => (ab3_weights(dt, h1, h2).map(|w| w * dt), 2),
        }
    }

    /// The net mass inflow over a multistep step: the weights `w` (times the step, the newest
    /// first) over the newest inflow and the history's, as the cells' state is stepped.
    fn multistep_inflow(&self, w: &[f64], net_new: f64) -> f64 {
        let bh = self.budget.hist;
        let past = [bh[self.st.head], bh[(self.st.head + 2) % 3]];
        w[1..].iter().zip(past).fold(w[0] * net_new, |s, (w, b)| s + w * b)
    }

    /// A serial step's start: the old state saved, the right-hand sides of the current state in
    /// the history's next slots (returned with the time and that slot).
    fn start_step(&mut self) -> (f64, usize, Vec<[f64; 4]>, Vec<f64>) {
        let t = self.st.time;
        self.q_old.copy_from_slice(&self.st.q);
        self.face_old.copy_from_slice(&self.st.face_flux);
        let newest = (self.st.head + 1) % 3;
        let mut f_new = std::mem::take(&mut self.st.hist[newest]);
        let mut g_new = self.take_face_slot(newest);
        self.rhs_into(t, &mut f_new, &mut g_new);
        (t, newest, f_new, g_new)
    }

    /// Storage for the step's face right-hand sides: history slot `newest`, or under the
    /// forward–backward scheme, which reads no past face right-hand side, the newest slot's (so
    /// that one slot is allocated, not three: 16 B per face); zeros where neither is allocated
    /// (the first step after a switch of scheme).
    fn take_face_slot(&mut self, newest: usize) -> Vec<f64> {
        let nf = self.st.face_flux.len();
        let mut g = std::mem::take(&mut self.st.hist_face[newest]);
        if g.len() != nf && self.scheme == TimeScheme::ForwardBackward {
            g = std::mem::take(&mut self.st.hist_face[self.st.head]);
        }
        if g.len() != nf {
            g = vec![0.0; nf];
        }
        g
    }

    /// The step's right-hand sides (cells, faces, net inflow) become the newest of the history,
    /// and the clock moves on by dt.
    fn push_history(&mut self, newest: usize, (f_new, g_new, net_new): (Vec<[f64; 4]>, Vec<f64>, f64), dt: f64) {
        self.budget.hist[newest] = net_new;
        self.st.hist[newest] = f_new;
        self.st.hist_face[newest] = g_new;
        if self.scheme == TimeScheme::ForwardBackward {
            for (k, slot) in self.st.hist_face.iter_mut().enumerate() {
                if k != newest {
                    *slot = Vec::new(); // read by no forward–backward step (`take_face_slot`)
                }
            }
        }
        self.st.head = newest;
        self.st.hist_h = [dt, self.st.hist_h[0]];
        self.st.hist_len = (self.st.hist_len + 1).min(3);
        self.st.time += dt;
        self.st.steps += 1;
    }

    /// Cells updated by fluxes: all but the characteristic outlet layer (mass_budget.rs).
    fn flux_updated_cells(&self) -> usize {
        let (nz, per) = (self.grid.nz, self.grid.cells_per_layer());
        if self.st.params.outlet == Outlet::Characteristic && nz > 1 {
            (nz - 1) * per
        } else {
            nz * per
        }
    }

    /// Gas mass of the flux-updated cells (kg; the cells have equal volumes).
    fn held_mass(&self) -> f64 {
        self.st.q[..self.flux_updated_cells()].iter().map(|s| s[0]).sum::<f64>() * self.grid.cell_volume()
    }

    /// ṁ_in − ṁ_out of the right-hand side just computed (its primitives and axial faces).
    fn net_inflow(&self, t: f64) -> f64 {
        let inp = state_input(&self.st, &self.geo, &self.grid, t, self.jet);
        net_mass_inflow(&inp, &self.prim.p, &self.axial)
    }

    /// Start the budget at the current mass if it is not running; the history's net inflows are
    /// the stored right-hand sides' mass rows summed (a checkpoint without the budget).
    fn start_mass_budget(&mut self) {
        if self.budget.start.is_some() {
            return;
        }
        let (n, v) = (self.flux_updated_cells(), self.grid.cell_volume());
        let hist = std::array::from_fn(|i| self.st.hist[i][..n].iter().map(|s| s[0]).sum::<f64>() * v);
        self.budget = MassBudget { start: Some(self.held_mass()), net: 0.0, hist };
    }

    /// The gas mass budget now: mass held by the flux-updated cells, its change and the net inflow
    /// since the budget started.
    pub fn mass_balance(&self) -> MassBalance {
        self.budget.balance(self.held_mass())
    }
    /// The budget, for checkpoints.
    pub fn mass_budget(&self) -> MassBudget {
        self.budget
    }
    /// Resume the budget of a checkpoint.
    pub fn set_mass_budget(&mut self, b: MassBudget) {
        self.budget = b;
    }

    /// The characteristic outlet layer after an update (`outlet_layer`).
    fn apply_outlet(&mut self, dt: f64) {
        let (nz, per) = (self.grid.nz, self.grid.cells_per_layer());
        if self.st.params.outlet != Outlet::Characteristic || nz < 2 {
            return;
        }
        let lo = (nz - 2) * per;
        let g = OutletGeometry { per, dz: self.grid.dz, height: self.grid.height };
        outlet_layer(&self.st.params, g, &self.st.eps[lo..], &self.q_old[lo..], &mut self.st.q[lo..], dt);
    }

    /// Right-hand sides of the current state (`self.st.q` into `out`, the face corrections into
    /// `out_face`) at time t: four passes over the layers (primitives, gradients, axial faces,
    /// residuals), each parallel over blocks of whole layers, so the bits do not depend on threads.
    fn rhs_into(&mut self, t: f64, out: &mut [[f64; 4]], out_face: &mut [f64]) {
        let per = self.grid.cells_per_layer();
        let nz = self.grid.nz;
        let nf = self.geo.faces.len().max(1);
        let inp = state_input(&self.st, &self.geo, &self.grid, t, self.jet);
        let q = &self.st.q;
        let pr = &mut self.prim;
        // Layers per task: all of them on one thread below the parallel size, else one block per thread.
        let rows = if self.parallel { nz.div_ceil(rayon::current_num_threads().max(1)) } else { nz };
        (
            pr.ux.par_chunks_mut(per),
            pr.uy.par_chunks_mut(per),
            pr.uz.par_chunks_mut(per),
            pr.p.par_chunks_mut(per),
            pr.beta.par_chunks_mut(per),
            pr.beta_over_eps2.par_chunks_mut(per),
        )
            .into_par_iter()
            .with_min_len(rows)
            .enumerate()
            .for_each(|(k, (ux, uy, uz, p, b, bz))| primitives_layer(&inp, q, k, ux, uy, uz, p, b, bz));
        let (mut div, mut gx, mut gy, mut gz) = (
            std::mem::take(&mut pr.div),
            std::mem::take(&mut pr.gx),
            std::mem::take(&mut pr.gy),
            std::mem::take(&mut pr.gz),
        );
        let prr = &*pr;
        (div.par_chunks_mut(per), gx.par_chunks_mut(per), gy.par_chunks_mut(per), gz.par_chunks_mut(per))
            .into_par_iter()
            .with_min_len(rows)
            .enumerate()
            .for_each(|(k, (d, x, y, z))| gradients_layer(&inp, &prr.view(), k, d, x, y, z));
        (pr.div, pr.gx, pr.gy, pr.gz) = (div, gx, gy, gz);
        let pr = &pr.view();
        let (out_fz, out_fh) = out_face.split_at_mut(q.len());
        out_fz[(nz - 1) * per..].fill(0.0);
        let axial = &mut self.axial;
        (axial.par_chunks_mut(per), out_fz.par_chunks_mut(per))
            .into_par_iter()
            .with_min_len(rows)
            .take(nz - 1)
            .enumerate()
            .for_each(|(k, (a, fz))| axial_layer(&inp, q, pr, k, a, fz));
        let axial = &*axial;
        (out.par_chunks_mut(per), out_fh.par_chunks_mut(nf))
            .into_par_iter()
            .with_min_len(rows)
            .enumerate()
            .for_each(|(k, (o, fh))| residual_layer(&inp, q, pr, axial, k, o, fh));
    }
}

/// u = ρεu / ρε of a cell's state (Cartesian).
fn interstitial_velocity(s: &[f64; 4]) -> [f64; 3] {
    [s[1] / s[0], s[2] / s[0], s[3] / s[0]]
}

/// The implicit drag's arrays when `coupling.gas_drag` is "implicit".
fn implicit_drag_of<'a>(coef: &'a [f64], u0: &'a [[f64; 3]]) -> Option<ImplicitDrag<'a>> {
    (!coef.is_empty()).then_some(ImplicitDrag { coef, u0 })
}

/// What the right-hand side reads besides the cells' state, at time t.
fn state_input<'a>(
    st: &'a State,
    geo: &'a FaceGeometry,
    grid: &CylGrid,
    t: f64,
    jet: Option<InletJet>,
) -> RhsInput<'a> {
    RhsInput {
        geo,
        params: &st.params,
        per: grid.cells_per_layer(),
        nz: grid.nz,
        dz: grid.dz,
        eps: &st.eps,
        force: &st.force,
        face_flux: &st.face_flux,
        time: t,
        jet,
    }
}

impl Serialize for GasSolver {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.st.serialize(s)
    }
}

impl<'de> Deserialize<'de> for GasSolver {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let st = State::deserialize(d)?;
        let g = &st.grid;
        let grid = CylGrid::new(g.radius, g.height, g.dr, g.dz, g.n0);
        if grid.num_cells() != st.q.len() {
            return Err(serde::de::Error::custom("gas state does not match its grid"));
        }
        Ok(GasSolver::from_state(st, grid))
    }
}
