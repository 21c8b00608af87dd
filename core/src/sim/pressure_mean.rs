//! The particles' pressure-gradient force as the mean of the gas's over the last interval (case
//! `coupling.pressure_force` = "interval_mean"). Held (the paper's), each particle keeps −V_p∇p of
//! the gas state right after a coupling has set the new voidage: the gas holds each cell's mass,
//! so that state carries the pressure step −pΔε/ε, which the gas relaxes within a few of its
//! steps while the particles keep it for the whole interval (docs/VALIDATION.md, "The pressure
//! force between couplings"). Here the coupling gives the particles, in place of that gradient,
//! the mean of the ∇p the gas's momentum equation used at each of its steps since the last
//! coupling (`GasSolver::last_step_pressure_gradient`): over a run the particles then receive the
//! pressure impulse the gas felt, one interval (25 µs at the default 20) late. Unlike "gas_step"
//! (pressure_follow.rs) nothing runs per particle between couplings: the cost is a sum over the
//! bed's cells per gas step.

use crate::cfd::GasSolver;
use serde::{Deserialize, Serialize};

/// Σ ∇p (Cartesian) per cell of the bed's layers (and two above) over the gas steps since the last
/// coupling; travels in the checkpoint (`pressure_mean`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct PressureMean {
    sum: Vec<[f64; 3]>,
    steps: u64,
}

impl PressureMean {
    /// After a gas step: add the ∇p its right-hand side used, for the cells the last coupling
    /// chose (`take_mean`).
    pub(super) fn add_step(&mut self, gas: &GasSolver) {
        let (gx, gy, gz) = gas.last_step_pressure_gradient();
        for (c, s) in self.sum.iter_mut().enumerate() {
            s[0] += gx[c];
            s[1] += gy[c];
            s[2] += gz[c];
        }
        self.steps += 1;
    }

    /// At a coupling: the mean over the gas steps since the last one, as (∂p/∂r, (1/r)∂p/∂θ,
    /// ∂p/∂z) in each cell's basis (as `GasSolver::pressure_gradient_cyl`), into the cells of
    /// `grad_cyl` that the sum holds (the others keep theirs: the gas's current gradient, as at
    /// the first coupling, when there is no step yet). Then the sum restarts over the first
    /// `next_cells` cells.
    pub(super) fn take_mean(&mut self, gas: &GasSolver, grad_cyl: &mut [[f64; 3]], next_cells: usize) {
        if self.steps > 0 {
            let inv = 1.0 / self.steps as f64;
            let n = self.sum.len().min(grad_cyl.len());
            for (c, (g, s)) in grad_cyl[..n].iter_mut().zip(&self.sum).enumerate() {
                let (r, t) = gas.horizontal_to_cylindrical(c, s[0] * inv, s[1] * inv);
                *g = [r, t, s[2] * inv];
            }
        }
        self.sum.clear();
        self.sum.resize(next_cells, [0.0; 3]);
        self.steps = 0;
    }
}

#[cfg(test)]
mod tests {
    use crate::case::PressureForce;
    use crate::coupling::exchange::{angle_of, cyl_to_cart, fluid_cell};

    #[test]
    fn a_coupling_gives_the_particles_minus_vp_times_the_mean_gas_gradient_of_the_interval() {
        // The resume tests' bed coupled every 6 DEM steps, at step 606 (a coupling next): one run
        // whose coupling gives the mean (a), one the gradient of the moment (b).
        let (mut a, mut b) = super::super::resume_tests::held_and(PressureForce::IntervalMean, 606);
        // The gas steps this coupling's catch-up takes, replayed on a copy of the gas: the
        // gradient of the state each starts from, as the gas solver reports it.
        let mut gas = a.gas().unwrap().clone();
        let (dt, dt_g) = (a.st.case.dem.time_step_s, a.plan().gas_dt_s.unwrap());
        let target = crate::sim::plan::gas_steps_due(606, dt, dt_g);
        let cells = a.grid.num_cells();
        let mut sum = vec![[0.0f64; 3]; cells];
        let mut steps = 0;
        while gas.steps() < target {
            for (c, s) in sum.iter_mut().enumerate() {
                let g = gas.pressure_gradient_cyl(c);
                (0..3).for_each(|q| s[q] += g[q]);
            }
            gas.step(dt_g);
            steps += 1;
        }
        assert!(steps >= 2, "the interval holds several gas steps ({steps})");
        let pos = a.dem().positions().to_vec();
        a.step().unwrap();
        b.step().unwrap();
        // The coupling read the mean for the bed's cells...
        let held = a.st.mean.sum.len();
        let per = a.grid.cells_per_layer();
        assert!(held > per && held < cells, "the bed's layers and two above: {held} of {cells}");
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for (got, s) in a.buf.cell_grad_p[..held - 2 * per].iter().zip(&sum) {
            for (g, x) in got.iter().zip(s) {
                let want = x / steps as f64;
                worst = worst.max((g - want).abs());
                scale = scale.max(want.abs());
            }
        }
        assert!(worst <= 1e-9 * scale, "mean gradient off by {worst:e} of {scale:e}");
        // ...and it differs from the gradient of the moment, by a part that matters.
        let moved = (0..held - 2 * per)
            .flat_map(|c| (0..3).map(move |q| (c, q)))
            .map(|(c, q)| (a.buf.cell_grad_p[c][q] - b.buf.cell_grad_p[c][q]).abs())
            .fold(0.0, f64::max);
        assert!(moved > 1e-3 * scale, "the mean is the gradient of the moment: {moved:e} of {scale:e}");
        // The particles' forces differ by −V_p R(θ_p)(mean − moment) of their cells: the drag is
        // the same in both runs.
        let d = 2.0 * a.dem().radius();
        let vp = std::f64::consts::PI * d * d * d / 6.0;
        let (fa, fb) = (a.st.dem.external_forces_mut().to_vec(), b.st.dem.external_forces_mut().to_vec());
        let m = a.buf.sub.as_ref().map_or(1, |s| s.n);
        let mut off = 0.0f64;
        for (i, p) in pos.iter().enumerate() {
            let c = fluid_cell(a.buf.exchange.cells()[i] as usize, per, m);
            let (ga, gb) = (a.buf.cell_grad_p[c], b.buf.cell_grad_p[c]);
            let (cos, sin) = angle_of(p[0], p[1]);
            let dg = cyl_to_cart([ga[0] - gb[0], ga[1] - gb[1], ga[2] - gb[2]], cos, sin);
            for q in 0..3 {
                off = off.max((fa[i][q] - fb[i][q] + vp * dg[q]).abs());
            }
        }
        assert!(off <= 1e-9 * vp * scale, "force difference off by {off:e}");
    }
}
