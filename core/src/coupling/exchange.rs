//! Particle–gas force exchange (paper section 2.3; model A of PHYSICS.md 11).
//!
//! Each particle feels −V_p∇p + F_d, with F_d the case's drag law (drag/) built on the gas velocity,
//! density, voidage and pressure gradient of the cell holding its centre. The cylindrical gas
//! vectors are turned into Cartesian ones at the particle's own angle (paper: "converted to
//! rectangular velocities at the position of the particle"). The gas in that cell receives
//! I = −Σ F_d / V_cell, given in the cylindrical components of the cell centre's basis (the basis
//! in which the finite-volume solver holds that cell's momentum): this keeps Σ_particles F_d =
//! −Σ_cells R(θ_c)·I·V_cell to round-off, whereas the particle's basis would rotate each
//! contribution by up to half a cell width (±60° in the central annulus).
//!
//! Drag voidage on sub-layers (case `coupling.drag_voidage_sublayers` = n > 1; `DragCells`): the
//! drag law reads the voidage ε_s of the sub-layer (height dz/n) holding the particle's centre and
//! the interstitial velocity u_s = (ε_c/ε_s)·u_c, the cell's gas flux ε_c·u_c taken as uniform over
//! the cell; the gas still loses the drag in its cell, and each particle gets its sub-cell's share
//! of the pressure drop (sublayer_pressure.rs). For n = 1, ε_s = ε_c and u_s = u_c: the paper's
//! model, the same bits.

#[cfg(test)]
use super::drag::beetstra_f;
use super::drag::{clamp_voidage, drag_force, Beetstra, DiFelice, DragLaw, DragModel, Gidaspow};
use super::sublayer_pressure::{add_sublayer_pressure, SubLayerDrag};
use crate::buffers::resize_reused;
use crate::grid::CylGrid;
use crate::simd::per_isa;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Gas state per fluid cell, as the exchange reads it.
pub struct GasAtCells<'a> {
    /// Interstitial gas velocity (U_r, U_θ, U_z).
    pub velocity_cyl: &'a [[f64; 3]],
    pub density: &'a [f64],
    /// (∂p/∂r, (1/r)∂p/∂θ, ∂p/∂z).
    pub grad_p_cyl: &'a [[f64; 3]],
    pub voidage: &'a [f64],
    /// The fields hold values in layers 0..layers, at least every layer that holds a particle
    /// centre (`layers_with_particles`); the exchange reads and writes no layer above.
    pub layers: usize,
}

/// The fluid layers from the bottom up to the one holding the highest particle centre: what the
/// exchange reads (0 without particles). The freeboard above a bed holds no particle.
pub fn layers_with_particles(grid: &CylGrid, pos: &[[f64; 3]]) -> usize {
    let top = pos.iter().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
    if top.is_finite() {
        grid.locate_k(top) + 1
    } else {
        0
    }
}

/// Cylindrical (radial, angular, axial) components at angle θ → Cartesian.
#[inline]
pub fn cyl_to_cart(v: [f64; 3], cos: f64, sin: f64) -> [f64; 3] {
    [v[0] * cos - v[1] * sin, v[0] * sin + v[1] * cos, v[2]]
}

/// Cartesian → cylindrical components at angle θ.
#[inline]
pub fn cart_to_cyl(v: [f64; 3], cos: f64, sin: f64) -> [f64; 3] {
    [v[0] * cos + v[1] * sin, -v[0] * sin + v[1] * cos, v[2]]
}

/// The fluid cell that drag sub-cell `s` lies in, on a grid of `m` sub-layers per fluid layer of
/// `per` cells (sub-layers keep the layer's cells).
#[inline]
pub(crate) fn fluid_cell(s: usize, per: usize, m: usize) -> usize {
    (s / per / m) * per + s % per
}

/// (cos θ, sin θ) of the particle's angle; 1, 0 on the axis.
#[inline]
pub(crate) fn angle_of(x: f64, y: f64) -> (f64, f64) {
    let r = (x * x + y * y).sqrt();
    if r > 0.0 {
        let inv = 1.0 / r;
        (x * inv, y * inv)
    } else {
        (1.0, 0.0)
    }
}

/// Where the drag law reads its voidage: the fluid grid itself (`sublayers` 1, `voidage` the
/// cells'), or a grid of `sublayers` layers per fluid layer and the same cells in each layer
/// (`voidage` one value per sub-cell).
#[derive(Clone, Copy)]
pub struct DragCells<'a> {
    pub grid: &'a CylGrid,
    pub sublayers: usize,
    pub voidage: &'a [f64],
}

impl<'a> DragCells<'a> {
    /// The fluid cells themselves (the paper's model).
    pub fn cells(grid: &'a CylGrid, voidage: &'a [f64]) -> DragCells<'a> {
        DragCells { grid, sublayers: 1, voidage }
    }
}

/// Drag law and fluid constants of the exchange.
#[derive(Clone, Copy, Debug)]
pub struct ExchangeParams {
    pub law: DragModel,
    /// Gas viscosity μ, the lower clamp of ε in the drag law, the particle diameter d.
    pub mu: f64,
    pub eps_min: f64,
    pub d: f64,
}

/// Particles per chunk of the particle pass; each chunk sums its drag on the gas into its own
/// buffer row of `CHUNKS`, added in a fixed order, so the result does not depend on threads.
const CHUNKS: usize = 4;
/// Particles handled together in the drag law's evaluation (a block the compiler vectorises).
const BLOCK: usize = 8;

/// What a particle reads of its cell: the gas vectors (cell basis), the drag law's factors,
/// 3πμdε and ρεd/μ, and the cell's basis (cos θ_c, sin θ_c).
#[derive(Clone, Copy, Default)]
struct CellTable<C> {
    u_cyl: [f64; 3],
    grad_cyl: [f64; 3],
    k: f64,
    re_per_w: f64,
    /// ∂u_s/∂u_c: the drag velocity per cell velocity (1 on the fluid cells, ε_c/ε_s on sub-layers).
    u_per_cell_u: f64,
    basis: (f64, f64),
    law: C,
}

/// The exchange's work arrays and per-cell basis angles, allocated once per run.
pub struct Exchange {
    /// (cos θ_c, sin θ_c) of each in-layer cell's centre angle.
    cell_basis: Vec<(f64, f64)>,
    /// Cell of each particle's centre (also the next call's hint).
    cell_of: Vec<u32>,
    /// Frozen beds: per cell, particle count and Σcos, Σsin of (θ_p − θ_c) (see `frozen_cell_forces`).
    frozen: Vec<(f64, f64, f64)>,
    /// Per-cell tables of the three laws (only the case's law is filled), refreshed each call.
    tables: Tables,
    /// Drag on the gas per chunk and cell (cell basis) of the layers that hold particles, summed
    /// into the caller's output.
    chunk_force: Vec<Vec<[f64; 3]>>,
    /// Σ K_p·∂u_s/∂u_c per chunk and cell, and the cells' sums over V_cell (`drag_coefficients`).
    chunk_coef: Vec<Vec<f64>>,
    cell_coef: Vec<f64>,
    /// Sub-layers: the pressure correction the gas loses per sub-cell, and scratch (sublayer_pressure.rs).
    sub_lost: Vec<[f64; 3]>,
    sub_scratch: Vec<[f64; 3]>,
    sub_count: Vec<u32>,
    /// The particles' identities in their order at the last call, and the caller's count of
    /// re-sorts then (`follow_reorder`).
    hint_ids: Vec<u32>,
    hint_order: u64,
}

#[derive(Default)]
struct Tables {
    beetstra: Vec<CellTable<<Beetstra as DragLaw>::Cell>>,
    gidaspow: Vec<CellTable<<Gidaspow as DragLaw>::Cell>>,
    di_felice: Vec<CellTable<<DiFelice as DragLaw>::Cell>>,
}

impl Exchange {
    pub fn new(grid: &CylGrid, particles: usize) -> Exchange {
        let mut cell_basis = Vec::with_capacity(grid.cells_per_layer());
        for i in 0..grid.nr {
            for j in 0..grid.cells_in_annulus(i) {
                let th = grid.centre_polar(i, j).1;
                cell_basis.push((th.cos(), th.sin()));
            }
        }
        Exchange {
            cell_basis,
            cell_of: vec![0; particles],
            frozen: Vec::new(),
            tables: Tables::default(),
            chunk_force: vec![Vec::new(); CHUNKS],
            chunk_coef: vec![Vec::new(); CHUNKS],
            cell_coef: Vec::new(),
            sub_lost: Vec::new(),
            sub_scratch: Vec::new(),
            sub_count: Vec::new(),
            hint_ids: Vec::new(),
            hint_order: 0,
        }
    }

    /// Fluid force on every particle (Cartesian, −V_p∇p + drag) into `force_out`, and the
    /// interaction force per unit volume on the gas, I = −Σ drag / V_cell (cylindrical,
    /// cell-centre basis), into `cell_force_out` (overwritten). ε is clamped to [eps_min, 1).
    /// No allocation after the first call.
    #[allow(clippy::too_many_arguments)]
    pub fn particle_gas_forces(
        &mut self,
        grid: &CylGrid,
        drag: DragCells,
        gas: &GasAtCells,
        par: ExchangeParams,
        particles: (&[[f64; 3]], &[[f64; 3]]),
        force_out: &mut [[f64; 3]],
        cell_force_out: &mut [[f64; 3]],
    ) {
        let mut tables = std::mem::take(&mut self.tables);
        match par.law {
            DragModel::Beetstra => {
                self.run(Beetstra, &mut tables.beetstra, grid, drag, gas, par, particles, force_out, cell_force_out)
            }
            DragModel::Gidaspow => {
                self.run(Gidaspow, &mut tables.gidaspow, grid, drag, gas, par, particles, force_out, cell_force_out)
            }
            DragModel::DiFelice => {
                self.run(DiFelice, &mut tables.di_felice, grid, drag, gas, par, particles, force_out, cell_force_out)
            }
        }
        self.tables = tables;
    }

    #[allow(clippy::too_many_arguments)]
    fn run<L: DragLaw>(
        &mut self,
        law: L,
        table: &mut Vec<CellTable<L::Cell>>,
        grid: &CylGrid,
        drag: DragCells,
        gas: &GasAtCells,
        par: ExchangeParams,
        (pos, vel): (&[[f64; 3]], &[[f64; 3]]),
        force_out: &mut [[f64; 3]],
        cell_force_out: &mut [[f64; 3]],
    ) {
        assert_eq!(pos.len(), vel.len());
        assert_eq!(pos.len(), force_out.len());
        let (cells, per, m) = (grid.num_cells(), grid.cells_per_layer(), drag.sublayers.max(1));
        assert_eq!(cell_force_out.len(), cells);
        // The drag's cells: m sub-cells per fluid cell, the same in-layer cells.
        let drag_cells = drag.grid.num_cells();
        assert!(drag.grid.cells_per_layer() == per && drag_cells == m * cells && drag.voidage.len() == drag_cells);
        self.cell_of.resize(pos.len(), 0);
        // The drag cells of the layers that hold particles; the cells above get no table and no
        // force (the sub-layers' pressure share reads their sums as the zeros they are).
        let used = gas.layers.min(grid.nz) * m * per;
        // 1. per drag cell (parallel): everything that does not depend on the particle
        let (mu, d) = (par.mu, par.d);
        resize_reused(table, used, CellTable::default());
        let basis = &self.cell_basis;
        table[..used].par_iter_mut().with_min_len(256).enumerate().for_each(|(s, t)| {
            let c = fluid_cell(s, per, m);
            let eps = clamp_voidage(drag.voidage[s], par.eps_min);
            let u = gas.velocity_cyl[c];
            let f = if m == 1 { 1.0 } else { clamp_voidage(gas.voidage[c], par.eps_min) / eps };
            let u_cyl = if m == 1 { u } else { [f * u[0], f * u[1], f * u[2]] };
            *t = CellTable {
                u_cyl,
                grad_cyl: gas.grad_p_cyl[c],
                k: 3.0 * PI * mu * d * eps,
                re_per_w: gas.density[c] * eps * d / mu,
                u_per_cell_u: f,
                basis: basis[s % per],
                law: law.cell(eps),
            };
        });
        // 2. per particle (parallel over fixed chunks): its cell, the drag and the total force
        //    −V_p∇p + drag, with the gas vectors turned to Cartesian at the particle's own angle
        //    (paper section 2.3); the drag, in its cell's basis, summed per chunk for the gas
        let vp = PI * d * d * d / 6.0;
        let chunk = pos.len().div_ceil(CHUNKS).max(1);
        // A particle above the used layers would index past this slice: a panic, never a stale table.
        let table = &table[..used];
        let dgrid = drag.grid;
        // The chunks' sums over the used cells; rows of chunks without particles add nothing.
        self.chunk_force.resize_with(CHUNKS, Vec::new);
        self.chunk_coef.resize_with(CHUNKS, Vec::new);
        let filled = pos.len().div_ceil(chunk);
        for (row, coef) in self.chunk_force[filled..].iter_mut().zip(&mut self.chunk_coef[filled..]) {
            resize_reused(row, used, [0.0; 3]);
            row.fill([0.0; 3]);
            resize_reused(coef, used, 0.0);
            coef.fill(0.0);
        }
        let sums = self.chunk_force.par_iter_mut().zip(self.chunk_coef.par_iter_mut());
        (sums, force_out.par_chunks_mut(chunk), self.cell_of.par_chunks_mut(chunk))
            .into_par_iter()
            .enumerate()
            .for_each(|(n, ((sum, coef), f, co))| {
                resize_reused(sum, used, [0.0; 3]);
                sum.fill([0.0; 3]);
                resize_reused(coef, used, 0.0);
                coef.fill(0.0);
                let lo = n * chunk;
                particle_block_pass_on::<L>(
                    dgrid,
                    table,
                    vp,
                    &pos[lo..lo + f.len()],
                    &vel[lo..lo + f.len()],
                    f,
                    co,
                    (sum, coef),
                );
            });
        // 3. with sub-layers, each particle's share of its sub-cell's pressure drop
        if m > 1 {
            let d = SubLayerDrag {
                sums: &self.chunk_force,
                used,
                voidage: drag.voidage,
                eps_min: par.eps_min,
                cell_of: &self.cell_of,
                per,
                n: m,
                v_sub: drag.grid.cell_volume(),
                vp,
                basis,
            };
            add_sublayer_pressure(&d, force_out, &mut self.sub_lost, (&mut self.sub_scratch, &mut self.sub_count));
        }
        // 4. the gas loses the drag (and the sub-layers' pressure correction) in its cell, with its
        //    drag coefficient: chunk sums and sub-cells in a fixed order, per unit volume
        let inv_v = 1.0 / grid.cell_volume();
        let (sums, coefs, lost) = (&self.chunk_force, &self.chunk_coef, &self.sub_lost);
        resize_reused(&mut self.cell_coef, cells, 0.0);
        let (below, above) = cell_force_out.split_at_mut(used / m);
        let (coef_below, coef_above) = self.cell_coef.split_at_mut(used / m);
        above.fill([0.0; 3]);
        coef_above.fill(0.0);
        below.par_iter_mut().zip(coef_below).with_min_len(512).enumerate().for_each(|(c, (out, coef))| {
            let (mut s, mut a) = ([0.0; 3], 0.0);
            let first = (c / per) * m * per + c % per;
            for sub in 0..m {
                for (row, row_coef) in sums.iter().zip(coefs) {
                    for q in 0..3 {
                        s[q] += row[first + sub * per][q];
                    }
                    a += row_coef[first + sub * per];
                }
                if m > 1 {
                    for q in 0..3 {
                        s[q] += lost[first + sub * per][q];
                    }
                }
            }
            *out = [-s[0] * inv_v, -s[1] * inv_v, -s[2] * inv_v];
            *coef = a * inv_v;
        });
        for row in &mut self.chunk_force[CHUNKS..] {
            row.clear();
        }
    }

    /// Per fluid cell, the drag coefficient of the gas at the last `particle_gas_forces` (or
    /// `frozen_cell_forces`, whose particles are at rest):
    /// a = Σ_p K_p·∂u_s/∂u_c / V_cell (kg m⁻³ s⁻¹), K_p = 3πμdεF the particle's drag per slip, so
    /// that ∂I/∂u ≈ −a at the call's Re (cfd/implicit_drag.rs).
    pub fn drag_coefficients(&self) -> &[f64] {
        &self.cell_coef
    }

    /// The drag cell of each particle at the last `particle_gas_forces` (the particles' order then).
    pub fn cells(&self) -> &[u32] {
        &self.cell_of
    }

    /// Before a call: `order` counts the re-sorts of the particles so far (the DEM's list builds)
    /// and `ids` holds each place's particle identity now. After a re-sort since the last call,
    /// each particle's cell, the next call's lookup hint, moves with it to its new place; without
    /// this the hints belong to other particles and most lookups fall back to the full
    /// `CylGrid::locate` (≈ 4× the cost).
    pub fn follow_reorder(&mut self, order: u64, ids: &[u32]) {
        if order == self.hint_order && ids.len() == self.hint_ids.len() {
            return;
        }
        let old = std::mem::take(&mut self.hint_ids);
        self.carry_hints(&old, ids);
        self.hint_ids = old;
        self.hint_ids.clear();
        self.hint_ids.extend_from_slice(ids);
        self.hint_order = order;
    }

    /// Carry each particle's cell from its place in `old_ids` to its place in `new_ids` (both a
    /// permutation of the particles' identities); nothing without a known earlier order.
    fn carry_hints(&mut self, old_ids: &[u32], new_ids: &[u32]) {
        let n = old_ids.len();
        if n != self.cell_of.len() || new_ids.len() != n {
            return;
        }
        // The cell per particle identity, held only while the hints move (4 B per particle).
        let mut cell_by_id = vec![0; n];
        for (&id, &c) in old_ids.iter().zip(&self.cell_of) {
            cell_by_id[id as usize] = c;
        }
        for (c, &id) in self.cell_of.iter_mut().zip(new_ids) {
            *c = cell_by_id[id as usize];
        }
    }

    /// Remember a frozen bed (particles at rest for the whole run) for `frozen_cell_forces`.
    pub fn freeze(&mut self, grid: &CylGrid, pos: &[[f64; 3]]) {
        self.frozen = vec![(0.0, 0.0, 0.0); grid.num_cells()];
        let per = grid.cells_per_layer();
        for p in pos {
            let c = grid.locate(p[0], p[1], p[2]);
            let (cp, sp) = angle_of(p[0], p[1]);
            let (cc, sc) = self.cell_basis[c % per];
            let e = &mut self.frozen[c];
            // cos and sin of θ_p − θ_c
            *e = (e.0 + 1.0, e.1 + cp * cc + sp * sc, e.2 + sp * cc - cp * sc);
        }
    }

    /// The gas side of the exchange for a frozen bed, in O(cells): every particle of a cell is at
    /// rest and sees the same gas state, so its drag differs only by the rotation θ_p − θ_c of the
    /// cell's velocity; summed, I_c = −D(|u_c|)·(C u_r − S u_θ, S u_r + C u_θ, N u_z)/V_cell with
    /// N, C = Σcos, S = Σsin over the cell's particles. Equal to `Exchange::particle_gas_forces`' gas side
    /// to round-off; the particles' own forces are not needed (they do not move).
    pub fn frozen_cell_forces(
        &mut self,
        grid: &CylGrid,
        gas: &GasAtCells,
        par: ExchangeParams,
        cell_force_out: &mut [[f64; 3]],
    ) {
        assert_eq!(self.frozen.len(), grid.num_cells(), "freeze() first");
        let inv_v = 1.0 / grid.cell_volume();
        resize_reused(&mut self.cell_coef, grid.num_cells(), 0.0);
        self.cell_coef.fill(0.0);
        let (law, mu, eps_min, d) = (par.law, par.mu, par.eps_min, par.d);
        let (frozen, cell_coef) = (&self.frozen, &mut self.cell_coef);
        for (c, (f, &(n, cs, sn))) in cell_force_out.iter_mut().zip(frozen).enumerate() {
            if n == 0.0 {
                *f = [0.0; 3];
                continue;
            }
            let u = gas.velocity_cyl[c];
            // drag_force is linear in the slip at fixed |slip|: its coefficient from a unit call
            let k = drag_force(law, mu, gas.density[c], d, gas.voidage[c], eps_min, u);
            let w = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let coef = if w > 0.0 {
                (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt() / w
            } else {
                drag_force(law, mu, gas.density[c], d, gas.voidage[c], eps_min, [0.0, 0.0, 1.0])[2]
            };
            *f = [
                -coef * (cs * u[0] - sn * u[1]) * inv_v,
                -coef * (sn * u[0] + cs * u[1]) * inv_v,
                -coef * n * u[2] * inv_v,
            ];
            cell_coef[c] = coef * n * inv_v;
        }
    }
}

per_isa!(
    /// `particle_block_pass` on the best vector path the CPU has (`simd::per_isa`): the same
    /// operations in the same order, so the same bits.
    fn particle_block_pass_on<L: DragLaw>, particle_pass_paths, particle_block_pass,
    (grid: &CylGrid, table: &[CellTable<L::Cell>], vp: f64, pos: &[[f64; 3]], vel: &[[f64; 3]], force: &mut [[f64; 3]], cell_of: &mut [u32], gas_sum: (&mut [[f64; 3]], &mut [f64]))
);

/// One chunk of the particle pass, in blocks of `BLOCK` particles: the cell and the gas state
/// per particle (scalar), the drag law's F over the block (branch-free, vectorisable), then the
/// forces and the chunk's sums for the gas.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn particle_block_pass<L: DragLaw>(
    grid: &CylGrid,
    table: &[CellTable<L::Cell>],
    vp: f64,
    pos: &[[f64; 3]],
    vel: &[[f64; 3]],
    force: &mut [[f64; 3]],
    cell_of: &mut [u32],
    (gas_sum, coef_sum): (&mut [[f64; 3]], &mut [f64]),
) {
    let mut lane_cell = [L::Cell::default(); BLOCK];
    let (mut re, mut f) = ([0.0; BLOCK], [0.0; BLOCK]);
    let mut slip = [[0.0; 3]; BLOCK];
    let mut rot = [(0.0, 0.0); BLOCK];
    // What each lane reads (lanes past a short last block keep harmless earlier values).
    let (mut x, mut y, mut rpw) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
    let (mut u_cyl, mut v) = ([[0.0; 3]; BLOCK], [[0.0; 3]; BLOCK]);
    for start in (0..pos.len()).step_by(BLOCK) {
        let m = BLOCK.min(pos.len() - start);
        // The cells and their tables (scalar: the hint test and the gathers).
        for l in 0..m {
            let p = pos[start + l];
            // The cell of the last call is a hint (particles move little; after a re-sort the
            // hint is another particle's and `locate_near` falls back to `locate`).
            let c = grid.locate_near(p[0], p[1], p[2], cell_of[start + l] as usize);
            cell_of[start + l] = c as u32;
            let t = &table[c];
            (x[l], y[l], rpw[l], u_cyl[l], v[l]) = (p[0], p[1], t.re_per_w, t.u_cyl, vel[start + l]);
            lane_cell[l] = t.law;
        }
        // Angle, slip and Re over the whole block (the square roots and division vectorise).
        for l in 0..BLOCK {
            let (cos, sin) = angle_of(x[l], y[l]);
            let u = cyl_to_cart(u_cyl[l], cos, sin);
            let s = [u[0] - v[l][0], u[1] - v[l][1], u[2] - v[l][2]];
            re[l] = rpw[l] * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            slip[l] = s;
            rot[l] = (cos, sin);
        }
        for l in 0..BLOCK {
            f[l] = L::f_cell(&lane_cell[l], re[l]);
        }
        for l in 0..m {
            let c = cell_of[start + l] as usize;
            let t = &table[c];
            let kf = t.k * f[l];
            let s = slip[l];
            let dr = [kf * s[0], kf * s[1], kf * s[2]];
            let (cos, sin) = rot[l];
            let g = cyl_to_cart(t.grad_cyl, cos, sin);
            force[start + l] = [dr[0] - vp * g[0], dr[1] - vp * g[1], dr[2] - vp * g[2]];
            let dc = cart_to_cyl(dr, t.basis.0, t.basis.1);
            let out = &mut gas_sum[c];
            for q in 0..3 {
                out[q] += dc[q];
            }
            coef_sum[c] += kf * t.u_per_cell_u;
        }
    }
}
#[cfg(test)]
#[path = "exchange_sublayers_tests.rs"]
mod sublayers_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn grid() -> CylGrid {
        CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3)
    }

    #[test]
    fn carried_hints_follow_their_particles_through_a_reorder() {
        let g = grid();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let pos: Vec<[f64; 3]> = (0..500)
            .map(|_| {
                let (r, t) = (0.02 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..std::f64::consts::TAU));
                [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
            })
            .collect();
        let mut ex = Exchange::new(&g, pos.len());
        ex.cell_of = pos.iter().map(|p| g.locate(p[0], p[1], p[2]) as u32).collect();
        // Identities before (a shuffle of 0..n) and after a reorder (another shuffle).
        let mut old_ids: Vec<u32> = (0..pos.len() as u32).collect();
        let mut new_order: Vec<usize> = (0..pos.len()).collect();
        for i in (1..pos.len()).rev() {
            old_ids.swap(i, rng.gen_range(0..=i));
            new_order.swap(i, rng.gen_range(0..=i));
        }
        let new_ids: Vec<u32> = new_order.iter().map(|&s| old_ids[s]).collect();
        let moved: Vec<[f64; 3]> = new_order.iter().map(|&s| pos[s]).collect();
        ex.carry_hints(&old_ids, &new_ids);
        for (p, &c) in moved.iter().zip(&ex.cell_of) {
            assert_eq!(c as usize, g.locate(p[0], p[1], p[2]), "a hint left its particle");
        }
    }

    #[test]
    fn cylindrical_cartesian_round_trip() {
        let th: f64 = 2.1;
        let (c, s) = (th.cos(), th.sin());
        // a purely radial unit vector at θ is (cos θ, sin θ); a purely angular one (−sin θ, cos θ)
        let r = cyl_to_cart([1.0, 0.0, 0.0], c, s);
        let t = cyl_to_cart([0.0, 1.0, 0.0], c, s);
        assert!((r[0] - c).abs() < 1e-15 && (r[1] - s).abs() < 1e-15);
        assert!((t[0] + s).abs() < 1e-15 && (t[1] - c).abs() < 1e-15);
        let v = [0.3, -1.7, 2.0];
        let back = cart_to_cyl(cyl_to_cart(v, c, s), c, s);
        for m in 0..3 {
            assert!((back[m] - v[m]).abs() < 1e-15);
        }
    }

    #[test]
    fn uniform_field_gives_the_analytic_force() {
        let g = grid();
        let n = g.num_cells();
        let (mu, rho, eps, d, u, dpdz) = (1.8e-5, 1.204, 0.55, 1.2e-3, 0.8, -5000.0);
        let vel_c = vec![[0.0, 0.0, u]; n];
        let dens = vec![rho; n];
        let grad = vec![[0.0, 0.0, dpdz]; n];
        let void = vec![eps; n];
        let gas =
            GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void, layers: usize::MAX };
        let pos = vec![[0.003, -0.007, 0.005], [0.0, 0.0, 0.001], [-0.015, 0.01, 0.012]];
        let vel = vec![[0.1, 0.0, 0.2], [0.0, 0.0, 0.0], [0.0, -0.3, -0.1]];
        let mut f = vec![[0.0; 3]; 3];
        let mut cf = vec![[0.0; 3]; n];
        for law in [DragModel::Beetstra, DragModel::Gidaspow, DragModel::DiFelice] {
            let par = ExchangeParams { law, mu, eps_min: 0.1, d };
            Exchange::new(&g, pos.len()).particle_gas_forces(
                &g,
                DragCells::cells(&g, gas.voidage),
                &gas,
                par,
                (&pos, &vel),
                &mut f,
                &mut cf,
            );
            let vp = PI * d * d * d / 6.0;
            for k in 0..3 {
                let w = [-vel[k][0], -vel[k][1], u - vel[k][2]];
                let wm = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
                let re = rho * eps * wm * d / mu;
                let c = 3.0 * PI * mu * d * eps * law.f(eps, re);
                let want = [c * w[0], c * w[1], c * w[2] - vp * dpdz];
                for m in 0..3 {
                    assert!(
                        (f[k][m] - want[m]).abs() < 1e-12 * want[2].abs(),
                        "{law:?} particle {k}: {:?} vs {want:?}",
                        f[k]
                    );
                }
            }
        }
    }

    /// A random gas state at the n cells of the test grid (∇p with a random θ component when
    /// `swirl`) and m random particles in its column, for the conservation tests.
    pub(super) struct RandomScene {
        pub vel_c: Vec<[f64; 3]>,
        pub dens: Vec<f64>,
        pub grad: Vec<[f64; 3]>,
        pub void: Vec<f64>,
        pub pos: Vec<[f64; 3]>,
        pub vel: Vec<[f64; 3]>,
    }

    impl RandomScene {
        pub(super) fn new(rng: &mut rand_chacha::ChaCha8Rng, n: usize, m: usize, swirl: bool) -> RandomScene {
            let vel_c =
                (0..n).map(|_| [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0)]).collect();
            let dens = (0..n).map(|_| rng.gen_range(1.1..1.3)).collect();
            let grad = (0..n)
                .map(|_| [rng.gen_range(-50.0..50.0), if swirl { rng.gen_range(-50.0..50.0) } else { 0.0 }, -6000.0])
                .collect();
            let void = (0..n).map(|_| rng.gen_range(0.35..1.0)).collect();
            let pos = (0..m)
                .map(|_| {
                    let (r, t) = (0.021 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                    [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
                })
                .collect();
            let vel = (0..m)
                .map(|_| [rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5)])
                .collect();
            RandomScene { vel_c, dens, grad, void, pos, vel }
        }

        pub(super) fn gas(&self) -> GasAtCells<'_> {
            GasAtCells {
                velocity_cyl: &self.vel_c,
                density: &self.dens,
                grad_p_cyl: &self.grad,
                voidage: &self.void,
                layers: usize::MAX,
            }
        }
    }

    /// The gas's drag coefficient (cfd/implicit_drag.rs) is Σ 3πμdεF(ε, Re) over each cell's
    /// particles per cell volume, F the law's published form at each particle's own slip.
    #[test]
    fn the_drag_coefficient_sums_the_particles_drag_per_slip() {
        let g = grid();
        let n = g.num_cells();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
        let m = 2000;
        let scene = RandomScene::new(&mut rng, n, m, true);
        let gas = scene.gas();
        let (mu, d) = (1.8e-5, 1.2e-3);
        let par = ExchangeParams { law: DragModel::Beetstra, mu, eps_min: 0.1, d };
        let (mut f, mut cf) = (vec![[0.0; 3]; m], vec![[0.0; 3]; n]);
        let mut ex = Exchange::new(&g, m);
        ex.particle_gas_forces(
            &g,
            DragCells::cells(&g, gas.voidage),
            &gas,
            par,
            (&scene.pos, &scene.vel),
            &mut f,
            &mut cf,
        );
        let mut want = vec![0.0; n];
        for (p, v) in scene.pos.iter().zip(&scene.vel) {
            let c = g.locate(p[0], p[1], p[2]);
            let (cos, sin) = angle_of(p[0], p[1]);
            let u = cyl_to_cart(scene.vel_c[c], cos, sin);
            let slip = [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
            let w = (slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2]).sqrt();
            let eps = clamp_voidage(scene.void[c], 0.1);
            let re = scene.dens[c] * eps * w * d / mu;
            want[c] += 3.0 * PI * mu * d * eps * beetstra_f(eps, re) / g.cell_volume();
        }
        for (c, (got, want)) in ex.drag_coefficients().iter().zip(&want).enumerate() {
            assert!((got - want).abs() <= 1e-12 * want.abs(), "cell {c}: {got} vs {want}");
        }
        assert!(want.iter().filter(|&&a| a > 0.0).count() > n / 2, "most cells hold particles");
    }

    #[test]
    fn momentum_is_conserved_between_the_phases() {
        let g = grid();
        let n = g.num_cells();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let m = 5000;
        let scene = RandomScene::new(&mut rng, n, m, true);
        let (gas, pos, vel, grad) = (scene.gas(), &scene.pos, &scene.vel, &scene.grad);
        let (mut f, mut cf) = (vec![[0.0; 3]; m], vec![[0.0; 3]; n]);
        let d = 1.2e-3;
        let par = ExchangeParams { law: DragModel::Beetstra, mu: 1.8e-5, eps_min: 0.1, d };
        Exchange::new(&g, pos.len()).particle_gas_forces(
            &g,
            DragCells::cells(&g, gas.voidage),
            &gas,
            par,
            (pos, vel),
            &mut f,
            &mut cf,
        );
        // Σ drag on particles (total force minus −V_p∇p) against −Σ I·V_cell in Cartesian
        let vp = PI * d * d * d / 6.0;
        let mut drag = [0.0; 3];
        let mut scale = 0.0f64;
        for (k, p) in pos.iter().enumerate() {
            let c = g.locate(p[0], p[1], p[2]);
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
            let gp = cyl_to_cart(grad[c], p[0] / r, p[1] / r);
            for q in 0..3 {
                let dq = f[k][q] + vp * gp[q];
                drag[q] += dq;
                scale = scale.max(dq.abs());
            }
        }
        let mut gas_side = [0.0; 3];
        for (c, i_cyl) in cf.iter().enumerate() {
            let (i, j, _) = g.ijk(c);
            let th = g.centre_polar(i, j).1;
            let v = cyl_to_cart(*i_cyl, th.cos(), th.sin());
            for q in 0..3 {
                gas_side[q] += v[q] * g.cell_volume();
            }
        }
        for q in 0..3 {
            assert!((drag[q] + gas_side[q]).abs() < 1e-12 * scale * m as f64, "{q}: {} vs {}", drag[q], gas_side[q]);
        }
    }

    #[test]
    fn every_code_path_gives_the_same_bits() {
        // The portable particle pass against the one `particle_gas_forces` runs on this CPU.
        let g = grid();
        let n = g.num_cells();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
        let table: Vec<CellTable<<Beetstra as DragLaw>::Cell>> = (0..n)
            .map(|c| CellTable {
                u_cyl: [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0)],
                grad_cyl: [rng.gen_range(-50.0..50.0), rng.gen_range(-50.0..50.0), -6000.0],
                k: rng.gen_range(1e-10..1e-9),
                re_per_w: rng.gen_range(10.0..100.0),
                u_per_cell_u: rng.gen_range(0.8..1.2),
                basis: (c as f64).sin_cos(),
                law: Beetstra.cell(rng.gen_range(0.35..1.0)),
            })
            .collect();
        let m = 3001;
        let pos: Vec<[f64; 3]> = (0..m)
            .map(|k| {
                let (r, t) = (0.021 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                // a few particles on the axis and with zero slip (the branch-free edges)
                if k % 500 == 0 {
                    [0.0, 0.0, 0.005]
                } else {
                    [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
                }
            })
            .collect();
        let vel: Vec<[f64; 3]> =
            (0..m).map(|_| [rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5)]).collect();
        let run = |best: bool| {
            let (mut f, mut co, mut sum) = (vec![[0.0; 3]; m], vec![0u32; m], vec![[0.0; 3]; n]);
            let mut coef = vec![0.0; n];
            if best {
                particle_block_pass_on::<Beetstra>(
                    &g,
                    &table,
                    1e-9,
                    &pos,
                    &vel,
                    &mut f,
                    &mut co,
                    (&mut sum, &mut coef),
                );
            } else {
                particle_block_pass::<Beetstra>(&g, &table, 1e-9, &pos, &vel, &mut f, &mut co, (&mut sum, &mut coef));
            }
            let bits = |v: &[[f64; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
            let coef_bits: Vec<u64> = coef.iter().map(|x| x.to_bits()).collect();
            (bits(&f), co, bits(&sum), coef_bits)
        };
        let (portable, best) = (run(false), run(true));
        assert!(portable == best, "the paths differ");
    }

    #[test]
    fn frozen_shortcut_equals_the_particle_sum() {
        let g = grid();
        let n = g.num_cells();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let vel_c: Vec<[f64; 3]> =
            (0..n).map(|_| [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0)]).collect();
        let dens: Vec<f64> = (0..n).map(|_| rng.gen_range(1.1..1.3)).collect();
        let grad = vec![[0.0, 0.0, -5000.0]; n];
        let void: Vec<f64> = (0..n).map(|_| rng.gen_range(0.35..1.0)).collect();
        let gas =
            GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void, layers: usize::MAX };
        let pos: Vec<[f64; 3]> = (0..3000)
            .map(|_| {
                let (r, t) = (0.021 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
            })
            .collect();
        let vel = vec![[0.0; 3]; pos.len()];
        let (mut f, mut full, mut fast) = (vec![[0.0; 3]; pos.len()], vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        let mut ex = Exchange::new(&g, pos.len());
        let par = ExchangeParams { law: DragModel::DiFelice, mu: 1.8e-5, eps_min: 0.1, d: 1.2e-3 };
        ex.particle_gas_forces(&g, DragCells::cells(&g, gas.voidage), &gas, par, (&pos, &vel), &mut f, &mut full);
        ex.freeze(&g, &pos);
        ex.frozen_cell_forces(&g, &gas, par, &mut fast);
        let scale = full.iter().flat_map(|v| v.iter()).fold(0.0f64, |m, x| m.max(x.abs()));
        for c in 0..n {
            for m in 0..3 {
                assert!((full[c][m] - fast[c][m]).abs() <= 1e-12 * scale, "cell {c}: {:?} vs {:?}", full[c], fast[c]);
            }
        }
    }

    /// A bed in the lower layers: the exchange over its layers only (`layers_with_particles`)
    /// gives the same bits as over the whole column, and the gas above it gets no force, also
    /// after a call whose particles reached higher (no stale sums).
    #[test]
    fn the_layers_with_particles_give_the_same_bits_as_the_whole_column() {
        let g = grid();
        let n = g.num_cells();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut scene = RandomScene::new(&mut rng, n, 3000, true);
        let par = ExchangeParams { law: DragModel::Beetstra, mu: 1.8e-5, eps_min: 0.1, d: 1.2e-3 };
        let mut ex = Exchange::new(&g, scene.pos.len());
        let (mut f, mut cf) = (vec![[0.0; 3]; scene.pos.len()], vec![[0.0; 3]; n]);
        let high = scene.gas();
        ex.particle_gas_forces(
            &g,
            DragCells::cells(&g, high.voidage),
            &high,
            par,
            (&scene.pos, &scene.vel),
            &mut f,
            &mut cf,
        );
        // the same particles squeezed into the lower half of the column
        for p in &mut scene.pos {
            p[2] *= 0.5;
        }
        let layers = layers_with_particles(&g, &scene.pos);
        assert!(layers < g.nz, "the bed leaves layers free");
        let mut whole = Exchange::new(&g, scene.pos.len());
        let (mut f_all, mut cf_all) = (f.clone(), cf.clone());
        let all = scene.gas();
        let v = all.voidage;
        whole.particle_gas_forces(
            &g,
            DragCells::cells(&g, v),
            &all,
            par,
            (&scene.pos, &scene.vel),
            &mut f_all,
            &mut cf_all,
        );
        let low = GasAtCells { layers, ..scene.gas() };
        ex.particle_gas_forces(&g, DragCells::cells(&g, v), &low, par, (&scene.pos, &scene.vel), &mut f, &mut cf);
        assert!(f == f_all && cf == cf_all, "forces differ");
        let per = g.cells_per_layer();
        assert!(cf[layers * per..].iter().all(|c| *c == [0.0; 3]), "force above the bed");
        assert!(cf[..layers * per].iter().any(|c| *c != [0.0; 3]));
    }
}
