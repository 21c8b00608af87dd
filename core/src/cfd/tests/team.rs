//! The gas step as one team of threads (team_step.rs) against the serial step: the same bits.

use super::support::solver;
use crate::case::Gas;
use crate::cfd::{GasSolver, Outlet};
use crate::team::solver_pool;
use std::sync::atomic::Ordering;

/// A 8-layer column with a bed-like voidage, a drag-like force and a swirling, rising flow.
pub(super) fn stirred_bed(outlet: Outlet) -> GasSolver {
    let gas = Gas { superficial_velocity_m_s: 0.4, bulk_viscosity_pa_s: 1e-4, ..Default::default() };
    let mut s = solver(gas, 9.81, 3, 0.004, 8, 0.004);
    s.set_outlet(outlet);
    let n = s.grid().num_cells();
    let eps: Vec<f64> = (0..n).map(|c| 0.45 + 0.4 * ((c as f64) * 0.37).sin().abs()).collect();
    s.set_initial_voidage(&eps);
    for (c, &e) in eps.iter().enumerate() {
        let [x, y, z] = s.grid().centre_xyz(c);
        let rho = s.density(c) * (1.0 + 1e-3 * (200.0 * z).cos());
        s.set_cell(
            c,
            rho,
            [0.3 * (x * 300.0).sin(), 2.0 * (x * x + y * y).sqrt() * 50.0, 0.4 + 0.4 * (y * 200.0).cos()],
        );
        s.interaction_force_mut()[c] = [10.0 * (c as f64).cos(), 5.0 * (c as f64).sin(), 800.0 * (1.0 - e)];
    }
    s
}

pub(super) fn state_bits(s: &GasSolver) -> Vec<u64> {
    let n = s.grid().num_cells();
    (0..n).flat_map(|c| [s.density(c)].into_iter().chain(s.velocity_xyz(c))).map(f64::to_bits).collect()
}

#[test]
fn a_team_of_threads_steps_the_same_bits_as_one_thread() {
    for outlet in [Outlet::Characteristic, Outlet::Wall] {
        let mut serial = stirred_bed(outlet);
        serial.set_parallel(false);
        let dt = 0.8 * serial.stable_dt();
        for _ in 0..120 {
            serial.step(dt);
        }
        for threads in [2, 3] {
            let pool = solver_pool().num_threads(threads).build().unwrap();
            let mut team = stirred_bed(outlet);
            team.set_parallel(true);
            let before = super::super::team_step::TEAM_STEPS.load(Ordering::Relaxed);
            pool.install(|| (0..120).for_each(|_| team.step(dt)));
            let ran = super::super::team_step::TEAM_STEPS.load(Ordering::Relaxed) - before;
            assert!(ran >= 119, "{outlet:?}, {threads} threads: {ran} team steps of 119 multistep steps");
            assert!(state_bits(&team) == state_bits(&serial), "{outlet:?}, {threads} threads: the bits differ");
        }
    }
}
