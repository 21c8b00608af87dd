//! The particles' pressure-gradient force between couplings (case `coupling.pressure_force` =
//! "gas_step"). A coupling gives each particle drag − V_p∇p of the gas's state then
//! (coupling/exchange.rs), and by default both are held until the next coupling. Here the −V_p∇p
//! part follows the gas: after each gas step between couplings every particle's force moves by
//! −V_p R(θ_p)(∇p_now − ∇p_before) of its cell, so it is −V_p∇p of the gas's current state while
//! the drag stays held. The cell is the one the coupling found the particle in (after a
//! re-sort of the particles, the one it is in then); R(θ_p) turns the cell's (r, θ, z) vector to
//! Cartesian at the particle's angle, as the exchange does.
//!
//! Why: the gas's own force −ε∇p follows its pressure at every gas step. A voidage set anew at a
//! coupling moves each cell's pressure at once (the gas holds its mass), and the gas relaxes that
//! step within a few of its steps; a particle force held from the coupling instant keeps it for the
//! whole interval. The two phases then feel the pressure of different states, their pressure
//! impulses no longer cancel, and the bed's ΔP moves away from the weight the gas carries
//! (docs/VALIDATION.md, "The pressure force between couplings").

use crate::cfd::GasSolver;
use crate::coupling::exchange::{angle_of, cyl_to_cart, fluid_cell};
use crate::dem::DemSystem;
use crate::grid::CylGrid;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Particles per parallel task of the update.
const CHUNK: usize = 2048;

/// What the update needs between couplings; travels in the checkpoint (`pressure_follow`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct PressureFollow {
    /// Fluid cell of each particle, in the particles' order of list build `build`.
    cells: Vec<u32>,
    build: u64,
    /// ∇p per cell of the layers holding particles at the coupling, (r, θ, z) in the cell's
    /// basis, that the particles' forces carry now.
    grad: Vec<[f64; 3]>,
    /// The gas's step count when `grad` was read.
    gas_steps: u64,
}

impl PressureFollow {
    /// At a coupling: the cells of the exchange (`drag_cells` on a grid of `sublayers` drag
    /// sub-layers per fluid layer) and the gradients `grad` it read for `layers` layers.
    pub(super) fn record(
        &mut self,
        grid: &CylGrid,
        drag_cells: &[u32],
        sublayers: usize,
        layers: usize,
        grad: &[[f64; 3]],
        (build, gas_steps): (u64, u64),
    ) {
        let (per, m) = (grid.cells_per_layer(), sublayers.max(1));
        self.cells.clear();
        self.cells.extend(drag_cells.iter().map(|&s| fluid_cell(s as usize, per, m) as u32));
        self.grad.clear();
        self.grad.extend_from_slice(&grad[..layers.min(grid.nz) * per]);
        (self.build, self.gas_steps) = (build, gas_steps);
    }

    /// After the gas's steps since the last update: move each particle's force by −V_p times the
    /// change of its cell's ∇p. `scratch` takes the new gradients (and the fields the gas computes
    /// with them). Nothing to do before the first coupling or when the gas has not stepped.
    pub(super) fn update(
        &mut self,
        grid: &CylGrid,
        gas: &mut GasSolver,
        dem: &mut DemSystem,
        scratch: (&mut [[f64; 3]], &mut [f64], &mut [[f64; 3]]),
    ) {
        if self.cells.is_empty() || gas.steps() == self.gas_steps {
            return;
        }
        let (vel, rho, grad_new) = scratch;
        let used = self.grad.len();
        gas.exchange_fields(used / grid.cells_per_layer(), vel, rho, grad_new);
        let build = dem.list_builds().0;
        if build != self.build || self.cells.len() != dem.len() {
            // The particles were re-sorted: their cells now.
            self.cells.clear();
            self.cells.extend(dem.positions().iter().map(|p| grid.locate(p[0], p[1], p[2]) as u32));
            self.build = build;
        }
        let d = 2.0 * dem.radius();
        let vp = std::f64::consts::PI * d * d * d / 6.0;
        let (old, new) = (&self.grad[..], &grad_new[..used]);
        let cells = &self.cells[..];
        let (pos, _, ext) = dem.coupling_views();
        (ext.par_chunks_mut(CHUNK), pos.par_chunks(CHUNK), cells.par_chunks(CHUNK)).into_par_iter().for_each(
            |(f, x, c)| {
                for ((f, x), &c) in f.iter_mut().zip(x).zip(c) {
                    let c = c as usize;
                    // A particle above the coupling's layers (re-sorted out of them) keeps its force.
                    if c >= used {
                        continue;
                    }
                    let dg = [new[c][0] - old[c][0], new[c][1] - old[c][1], new[c][2] - old[c][2]];
                    let (cos, sin) = angle_of(x[0], x[1]);
                    let g = cyl_to_cart(dg, cos, sin);
                    for q in 0..3 {
                        f[q] -= vp * g[q];
                    }
                }
            },
        );
        self.grad.copy_from_slice(new);
        self.gas_steps = gas.steps();
    }
}

#[cfg(test)]
mod tests {
    use crate::case::PressureForce;
    use crate::coupling::exchange::{angle_of, cyl_to_cart};

    #[test]
    fn between_couplings_the_pressure_force_moves_by_minus_vp_times_the_change_of_the_gas_gradient() {
        // The resume tests' bed coupled every 6 DEM steps, from one state at step 600: one run with
        // the force following the gas (a), one with it held (b).
        let (mut a, mut b) = super::super::resume_tests::held_and(PressureForce::GasStep, 600);
        a.step().unwrap(); // the coupling at step 600, then one DEM step
        b.step().unwrap();
        let grad_at_coupling = a.st.follow.grad.clone();
        for _ in 0..4 {
            a.step().unwrap();
            b.step().unwrap();
        }
        assert_eq!(a.st.dem.list_builds().0, a.st.follow.build, "no re-sort inside the interval");
        let gas = a.st.gas.as_ref().unwrap();
        assert_eq!(gas.steps(), a.st.follow.gas_steps, "the forces follow the gas's last step");
        let d = 2.0 * a.st.dem.radius();
        let vp = std::f64::consts::PI * d * d * d / 6.0;
        let pos = a.st.dem.positions().to_vec();
        let fa = a.st.dem.external_forces_mut().to_vec();
        let fb = b.st.dem.external_forces_mut().to_vec();
        let (mut moved, mut scale, mut worst) = (0.0f64, 0.0f64, 0.0f64);
        for (i, p) in pos.iter().enumerate() {
            let c = a.st.follow.cells[i] as usize;
            let (now, then) = (gas.pressure_gradient_cyl(c), grad_at_coupling[c]);
            let (cos, sin) = angle_of(p[0], p[1]);
            let dg = cyl_to_cart([now[0] - then[0], now[1] - then[1], now[2] - then[2]], cos, sin);
            for q in 0..3 {
                let want = -vp * dg[q];
                worst = worst.max((fa[i][q] - fb[i][q] - want).abs());
                moved = moved.max(want.abs());
                scale = scale.max((vp * now[q]).abs());
            }
        }
        // The gas's gradient moved within the interval, by a part of the force that matters...
        assert!(moved > 1e-3 * scale, "the gradient hardly moved: {moved:e} of {scale:e}");
        // ...and the two runs' forces differ by exactly that, up to the particles' turn about the
        // axis since the coupling (< 1e-3 rad in 16 µs), at which the earlier changes were applied.
        assert!(worst < 1e-3 * moved, "{worst:e} against {moved:e}");
    }
}
