//! The coupled step (paper section 2.3): voidage from the particles, drag and −V∇p on the
//! particles, the opposite drag on the gas in the cell of each particle's centre; the gas is
//! sub-cycled at its own stable step and the particles at the DEM step, both by AB3, with the
//! exchange terms held for one gas step.

use super::{watchdog, SimError, Simulation};
use crate::coupling::{voidage_from_solid, Exchange, GasAtCells, VoidageMethod};
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
    pub particle_force: Vec<[f64; 3]>,
    pub exchange: Exchange,
    /// The voidage of a frozen bed is computed once.
    pub voidage_fresh: bool,
}

impl Buffers {
    pub fn new(grid: &CylGrid, particles: usize) -> Buffers {
        let cells = grid.num_cells();
        Buffers {
            solid: vec![0.0; cells],
            voidage: vec![1.0; cells],
            cell_velocity: vec![[0.0; 3]; cells],
            cell_density: vec![0.0; cells],
            cell_grad_p: vec![[0.0; 3]; cells],
            cell_force: vec![[0.0; 3]; cells],
            particle_force: vec![[0.0; 3]; particles],
            exchange: Exchange::new(grid, particles),
            voidage_fresh: false,
        }
    }
}

pub(super) fn compute_voidage(grid: &CylGrid, method: &mut dyn VoidageMethod, dem: &DemSystem, buf: &mut Buffers) {
    method.solid_volume(dem.positions(), dem.radius(), &mut buf.solid);
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
        let moving = self.st.plan.particles_move;
        if moving || !self.buf.voidage_fresh {
            compute_voidage(&self.grid, self.voidage.as_mut(), &self.st.dem, &mut self.buf);
            gas.set_voidage(&self.buf.voidage);
            if !moving {
                self.buf.exchange.freeze(&self.grid, self.st.dem.positions());
            }
            self.buf.voidage_fresh = true;
        }
        let t1 = std::time::Instant::now();
        let b = &mut self.buf;
        for c in 0..self.grid.num_cells() {
            b.cell_velocity[c] = gas.velocity_cyl(c);
            b.cell_density[c] = gas.density(c);
            b.cell_grad_p[c] = gas.pressure_gradient_cyl(c);
        }
        let g = self.st.case.gas.as_ref().expect("gas section");
        let at = GasAtCells {
            velocity_cyl: &b.cell_velocity,
            density: &b.cell_density,
            grad_p_cyl: &b.cell_grad_p,
            voidage: &b.voidage,
        };
        let dem = &self.st.dem;
        let d = 2.0 * dem.radius();
        if moving {
            b.exchange.particle_gas_forces(
                &self.grid,
                &at,
                g.viscosity_pa_s,
                g.drag_voidage_min,
                d,
                dem.positions(),
                dem.velocities(),
                &mut b.particle_force,
                &mut b.cell_force,
            );
            self.st.dem.external_forces_mut().copy_from_slice(&b.particle_force);
        } else {
            b.exchange.frozen_cell_forces(&self.grid, &at, g.viscosity_pa_s, g.drag_voidage_min, d, &mut b.cell_force);
        }
        gas.interaction_force_mut().copy_from_slice(&b.cell_force);
        self.timers.voidage += (t1 - t0).as_secs_f64();
        self.timers.exchange += t1.elapsed().as_secs_f64();
    }

    /// One DEM step, with a gas step (or several gas sub-steps) when one is due.
    pub(super) fn step(&mut self) -> Result<(), SimError> {
        let plan = self.st.plan.clone();
        if plan.gas && self.st.steps % plan.dem_steps_per_gas_step == 0 {
            self.couple();
            let dt = plan.gas_dt_s.expect("gas step chosen");
            let t = self.time();
            let gas = self.st.gas.as_mut().expect("gas");
            let t0 = std::time::Instant::now();
            for _ in 0..plan.gas_steps_per_dem_step {
                gas.step(dt);
            }
            watchdog::check_gas(gas, dt, t)?;
            self.timers.gas += t0.elapsed().as_secs_f64();
        }
        let t0 = std::time::Instant::now();
        self.st.dem.step();
        self.timers.dem += t0.elapsed().as_secs_f64();
        self.st.steps += 1;
        if plan.particles_move {
            watchdog::check_dem(&self.st.dem, self.st.steps, self.time())?;
        }
        Ok(())
    }
}
