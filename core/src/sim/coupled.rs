//! The coupled step (paper section 2.3): voidage from the particles, drag and −V∇p on the
//! particles, the opposite drag on the gas in the cell of each particle's centre, recomputed every
//! `coupling.interval_steps` DEM steps and held in between; the gas steps at its own stable step
//! (a whole fraction of the coupling interval when that is longer, plan.rs `aligned_gas_dt`) and
//! the particles at the DEM step, both by AB3. With drag-voidage sub-layers
//! (`coupling.drag_voidage_sublayers` = n > 1) the voidage method runs on the grid of n sub-layers
//! per fluid layer; the cells' solid volume is the sum of their sub-cells' (exact: solid volume
//! adds), and the drag reads the sub-cells' voidage averaged over a window of three sub-layers
//! (coupling/exchange.rs, `windowed_voidage`).

use super::{watchdog, SimError, Simulation};
use crate::case::{GasDrag, GasVoidage, PressureForce};
use crate::coupling::{
    layers_with_particles, voidage_from_solid, DragCells, Exchange, ExchangeParams, GasAtCells, VoidageMethod,
};
use crate::dem::DemSystem;
use crate::grid::CylGrid;

/// Work arrays, allocated once.
pub(super) struct Buffers {
    pub solid: Vec<f64>,
    pub voidage: Vec<f64>,
    pub cell_velocity: Vec<[f64; 3]>,
    pub cell_density: Vec<f64>,
    pub cell_grad_p: Vec<[f64; 3]>,
    pub cell_force: Vec<[f64; 3]>,
    pub exchange: Exchange,
    /// The voidage of a frozen bed is computed once.
    pub voidage_fresh: bool,
    /// Drag-voidage sub-layers: their grid (n layers per fluid layer), solid volume and voidage.
    pub sub: Option<SubLayers>,
}

pub(super) struct SubLayers {
    pub n: usize,
    pub grid: CylGrid,
    pub solid: Vec<f64>,
    pub voidage: Vec<f64>,
}

impl SubLayers {
    pub fn new(grid: &CylGrid, n: usize) -> SubLayers {
        let fine = sublayer_grid(grid, n);
        let cells = fine.num_cells();
        SubLayers { n, grid: fine, solid: vec![0.0; cells], voidage: vec![1.0; cells] }
    }
}

/// The grid of `n` sub-layers per layer of `grid` (the same cells in each layer).
pub(super) fn sublayer_grid(grid: &CylGrid, n: usize) -> CylGrid {
    let fine = CylGrid::new(grid.radius, grid.height, grid.dr, grid.dz / n as f64, grid.n0);
    assert_eq!(fine.nz, n * grid.nz, "sub-layers of the fluid layers");
    fine
}

/// The drag voidage of each sub-cell: the solid volume of it and of the sub-cells above and below
/// it in its column (a window of three sub-layers; two at the plate and the top) over their volume.
/// The window smooths the layering of particles in sub-layers thinner than a particle, which the
/// drag law (convex in ε) would turn into extra drag (docs/VALIDATION.md).
fn windowed_voidage(fine: &CylGrid, solid: &[f64], out: &mut [f64]) {
    use rayon::prelude::*;
    let (per, nz, v) = (fine.cells_per_layer(), fine.nz, fine.cell_volume());
    out.par_iter_mut().with_min_len(2048).enumerate().for_each(|(s, e)| {
        let k = s / per;
        let (lo, hi) = (k.saturating_sub(1), (k + 1).min(nz - 1));
        let sum: f64 = (lo..=hi).map(|k2| solid[s - k * per + k2 * per]).sum();
        *e = 1.0 - sum / ((hi - lo + 1) as f64 * v);
    });
}

impl Buffers {
    pub fn new(grid: &CylGrid, particles: usize, sublayers: usize) -> Buffers {
        let cells = grid.num_cells();
        Buffers {
            solid: vec![0.0; cells],
            voidage: vec![1.0; cells],
            cell_velocity: vec![[0.0; 3]; cells],
            cell_density: vec![0.0; cells],
            cell_grad_p: vec![[0.0; 3]; cells],
            cell_force: vec![[0.0; 3]; cells],
            exchange: Exchange::new(grid, particles),
            voidage_fresh: false,
            sub: (sublayers > 1).then(|| SubLayers::new(grid, sublayers)),
        }
    }
}

/// The cells' voidage (and the sub-cells', with sub-layers) from the particles. With sub-layers
/// `method` runs on their grid.
pub(super) fn compute_voidage(grid: &CylGrid, method: &mut dyn VoidageMethod, dem: &DemSystem, buf: &mut Buffers) {
    match buf.sub.as_mut() {
        None => method.solid_volume(dem.positions(), dem.radius(), &mut buf.solid),
        Some(sub) => {
            method.solid_volume(dem.positions(), dem.radius(), &mut sub.solid);
            windowed_voidage(&sub.grid, &sub.solid, &mut sub.voidage);
            let (per, n) = (grid.cells_per_layer(), sub.n);
            for (c, s) in buf.solid.iter_mut().enumerate() {
                let first = (c / per) * n * per + c % per;
                *s = (0..n).map(|k| sub.solid[first + k * per]).sum();
            }
        }
    }
    voidage_from_solid(grid, &buf.solid, &mut buf.voidage);
}

impl Simulation {
    /// The gas starts at rest around the settled bed: set ε keeping ρ (no pressure jump).
    pub(super) fn initial_voidage(&mut self) {
        if let Some(gas) = self.st.gas.as_mut() {
            compute_voidage(&self.grid, self.voidage.as_mut(), &self.st.dem, &mut self.buf);
            gas.set_initial_voidage(&self.buf.voidage);
        }
    }

    /// Exchange between the phases at the current state: voidage, particle forces, gas sink.
    /// A frozen bed takes the exact O(cells) shortcut (`Exchange::frozen_cell_forces`).
    pub(super) fn couple(&mut self) {
        if !self.st.plan.coupling {
            return;
        }
        let t0 = std::time::Instant::now();
        let gas = self.st.gas.as_mut().expect("coupling needs gas");
        // The frozen shortcut reads the cells' voidage: with sub-layers the particle pass runs.
        let moving = self.st.plan.particles_move;
        let per_particle = moving || self.buf.sub.is_some();
        if moving || !self.buf.voidage_fresh {
            compute_voidage(&self.grid, self.voidage.as_mut(), &self.st.dem, &mut self.buf);
            let interval = self.st.plan.coupling_interval as f64 * self.st.case.dem.time_step_s;
            let how = self.st.case.coupling.gas_voidage;
            if moving && how != GasVoidage::Held {
                let t = self.st.steps as f64 * self.st.case.dem.time_step_s;
                gas.ramp_voidage(&self.buf.voidage, t, interval, how == GasVoidage::Extrapolated);
            } else {
                gas.set_voidage(&self.buf.voidage);
            }
            if !moving {
                self.buf.exchange.freeze(&self.grid, self.st.dem.positions());
            }
            self.buf.voidage_fresh = true;
        }
        let t1 = std::time::Instant::now();
        let b = &mut self.buf;
        // The layers that hold particles (with sub-layers, the drag reads its fluid cells' fields).
        let layers = layers_with_particles(&self.grid, self.st.dem.positions());
        gas.exchange_fields(layers, &mut b.cell_velocity, &mut b.cell_density, &mut b.cell_grad_p);
        if self.st.case.coupling.pressure_force == PressureForce::IntervalMean {
            let next = (layers + 2).min(self.grid.nz) * self.grid.cells_per_layer();
            self.st.mean.take_mean(gas, &mut b.cell_grad_p, next);
        }
        let g = self.st.case.gas.as_ref().expect("gas section");
        let at = GasAtCells {
            velocity_cyl: &b.cell_velocity,
            density: &b.cell_density,
            grad_p_cyl: &b.cell_grad_p,
            voidage: &b.voidage,
            layers,
        };
        let dem = &mut self.st.dem;
        let par = ExchangeParams {
            law: self.st.case.coupling.drag_law,
            mu: g.viscosity_pa_s,
            eps_min: g.drag_voidage_min,
            d: 2.0 * dem.radius(),
        };
        if per_particle {
            let drag = match &b.sub {
                None => DragCells::cells(&self.grid, &b.voidage),
                Some(s) => DragCells { grid: &s.grid, sublayers: s.n, voidage: &s.voidage },
            };
            b.exchange.follow_reorder(dem.list_builds().0, dem.ids());
            let (pos, vel, ext) = dem.coupling_views();
            b.exchange.particle_gas_forces(&self.grid, drag, &at, par, (pos, vel), ext, &mut b.cell_force);
        } else {
            b.exchange.frozen_cell_forces(&self.grid, &at, par, &mut b.cell_force);
        }
        gas.interaction_force_mut().copy_from_slice(&b.cell_force);
        let implicit = self.st.case.coupling.gas_drag == GasDrag::Implicit;
        gas.set_implicit_drag(implicit.then(|| b.exchange.drag_coefficients()));
        if per_particle && self.st.case.coupling.pressure_force == PressureForce::GasStep {
            let stamp = (self.st.dem.list_builds().0, gas.steps());
            let m = b.sub.as_ref().map_or(1, |s| s.n);
            self.st.follow.record(&self.grid, b.exchange.cells(), m, layers, &b.cell_grad_p, stamp);
        }
        self.timers.voidage += (t1 - t0).as_secs_f64();
        self.timers.exchange += t1.elapsed().as_secs_f64();
    }

    /// Bring the gas to the particles' time: the gas steps (at its own step `gas_dt`) that the
    /// paper's loop takes while the particles take theirs, so that afterwards the gas leads the
    /// particles by less than one gas step. Between couplings the gas reads only the held
    /// voidage and interaction force and nothing reads the gas, so these steps are taken together
    /// at the next coupling or output (`step`, `advance`): the same bits as one DEM step at a time
    /// (test `the_gas_caught_up_at_couplings_gives_the_same_bits_as_step_by_step`), with the gas's
    /// state brought into cache once per interval instead of at every gas step.
    pub(super) fn sync_gas(&mut self) -> Result<(), SimError> {
        let plan = &self.st.plan;
        let (true, Some(dt_g)) = (plan.gas, plan.gas_dt_s) else { return Ok(()) };
        let dt = self.st.case.dem.time_step_s;
        // Gas steps that reach the end of the DEM steps taken (to within rounding).
        let target = super::plan::gas_steps_due(self.st.steps, dt, dt_g);
        let gas = self.st.gas.as_mut().expect("gas");
        let mean = plan.particles_move && self.st.case.coupling.pressure_force == PressureForce::IntervalMean;
        let t0 = std::time::Instant::now();
        while gas.steps() < target {
            gas.step(dt_g);
            if mean {
                self.st.mean.add_step(gas);
            }
            if gas.steps().is_multiple_of(watchdog::GAS_CHECK_EVERY) {
                watchdog::check_gas(gas, &self.limits, dt_g, gas.time(), self.st.steps)?;
            }
        }
        self.timers.gas += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Between couplings with `coupling.pressure_force` = "gas_step": the particles' −V_p∇p moved
    /// to the gas's current state (pressure_follow.rs).
    fn follow_gas_pressure(&mut self) {
        let t0 = std::time::Instant::now();
        let (Some(gas), b) = (self.st.gas.as_mut(), &mut self.buf) else { return };
        let scratch = (&mut b.cell_velocity[..], &mut b.cell_density[..], &mut b.cell_grad_p[..]);
        self.st.follow.update(&self.grid, gas, &mut self.st.dem, scratch);
        self.timers.exchange += t0.elapsed().as_secs_f64();
    }

    /// One DEM step. Every `coupling_interval` DEM steps the gas is brought to the particles'
    /// time (`sync_gas`) and the voidage and the drag are recomputed (held in between); with
    /// gas_dt = DEM dt and an interval of 1: couple, one gas step, one DEM step — the paper's loop.
    pub(super) fn step(&mut self) -> Result<(), SimError> {
        let plan = &self.st.plan;
        let (gas_on, interval, particles_move) = (plan.gas, plan.coupling_interval, plan.particles_move);
        if gas_on && self.st.steps.is_multiple_of(interval) {
            self.sync_gas()?;
            self.couple();
        } else if gas_on && particles_move && self.st.case.coupling.pressure_force == PressureForce::GasStep {
            self.sync_gas()?;
            self.follow_gas_pressure();
        }
        let t0 = std::time::Instant::now();
        let before = self.st.dem.neighbour_seconds();
        self.st.dem.step();
        let neighbours = self.st.dem.neighbour_seconds() - before;
        self.timers.neighbours += neighbours;
        self.timers.contacts_integration += t0.elapsed().as_secs_f64() - neighbours;
        self.st.steps += 1;
        if particles_move {
            watchdog::check_dem(&self.st.dem, &self.limits, self.st.steps, self.time())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_drag_voidage_window_averages_three_sublayers_of_a_column() {
        let fine = sublayer_grid(&CylGrid::new(0.01, 0.008, 0.005, 0.004, 3), 4);
        let (per, v) = (fine.cells_per_layer(), fine.cell_volume());
        // Solid 0.6 V in sub-cell (layer 3, cell 2) only: it and its two neighbours read 0.2 V.
        let mut solid = vec![0.0; fine.num_cells()];
        solid[3 * per + 2] = 0.6 * v;
        let mut eps = vec![0.0; fine.num_cells()];
        windowed_voidage(&fine, &solid, &mut eps);
        for (s, e) in eps.iter().enumerate() {
            let want = if s % per == 2 && (2..=4).contains(&(s / per)) { 0.8 } else { 1.0 };
            assert!((e - want).abs() < 1e-15, "sub-cell {s}: {e} vs {want}");
        }
        // At the plate the window is the bottom two sub-layers.
        solid.fill(0.0);
        solid[per] = 0.5 * v;
        windowed_voidage(&fine, &solid, &mut eps);
        assert!((eps[0] - 0.75).abs() < 1e-15 && (eps[per] - 1.0 + 0.5 / 3.0).abs() < 1e-15, "{} {}", eps[0], eps[per]);
    }
}
