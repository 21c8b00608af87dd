//! Gas solver benchmark: cost of one gas step per cell on the 44-mm column grid
//! (R = 22 mm, dr = 4.4 mm, dz ≈ dr, H = 0.12 m, n0 = 3), with a bed-like voidage and drag field.
//! Prints the single-thread and rayon figures; the last line is the one quoted.

use fluidbed_core::case::{Case, Gas};
use fluidbed_core::cfd::{GasSolver, PARALLEL_MIN_CELLS};
use fluidbed_core::grid::CylGrid;
use std::time::Instant;

fn solver(parallel: bool) -> GasSolver {
    let json = r#"{"column":{"diameter_m":0.044,"height_m":0.12},"particles":{},"bed":{"generated":{"settled_height_m":0.03}}}"#;
    let mut case: Case = serde_json::from_str(json).expect("case");
    case.gas = Some(Gas { superficial_velocity_m_s: 0.6, ramp_time_s: 0.0, ..Default::default() });
    let grid = CylGrid::new(0.022, 0.12, 0.0044, case.grid_dz_m(), 3);
    let mut s = GasSolver::new(&case, grid);
    let n = s.grid().num_cells();
    // A bed in the lower quarter (ε = 0.45) with a drag-like force, ε = 1 above.
    let eps: Vec<f64> = (0..n).map(|c| if s.grid().centre_xyz(c)[2] < 0.03 { 0.45 } else { 1.0 }).collect();
    s.set_initial_voidage(&eps);
    for (c, f) in s.interaction_force_mut().iter_mut().enumerate() {
        if eps[c] < 1.0 {
            *f = [0.0, 0.0, -500.0];
        }
    }
    s.set_parallel(parallel);
    s
}

/// Median ns per cell-step over `batches` timed batches of `steps` steps (after a warm-up).
fn time(parallel: bool, batches: usize, steps: usize) -> (usize, f64) {
    let mut s = solver(parallel);
    let dt = s.stable_dt();
    for _ in 0..steps {
        s.step(dt);
    }
    let n = s.grid().num_cells();
    let mut per_cell: Vec<f64> = (0..batches)
        .map(|_| {
            let t0 = Instant::now();
            for _ in 0..steps {
                s.step(dt);
            }
            t0.elapsed().as_nanos() as f64 / (steps * n) as f64
        })
        .collect();
    s.check_finite().expect("benchmark run stayed finite");
    per_cell.sort_by(|a, b| a.partial_cmp(b).unwrap());
    (n, per_cell[batches / 2])
}

pub fn run() {
    let (batches, steps) = (9, 400);
    let (n, serial) = time(false, batches, steps);
    println!("{{\"bench\":\"cfd_single_thread\",\"cells\":{n},\"ns_per_cell_step\":{serial:.1}}}");
    let (_, par) = time(true, batches, steps);
    let threads = rayon::current_num_threads();
    println!("{{\"bench\":\"cfd_rayon\",\"cells\":{n},\"threads\":{threads},\"ns_per_cell_step\":{par:.1}}}");
    // The solver's default (parallel from PARALLEL_MIN_CELLS cells) is the figure quoted.
    let best = if n >= PARALLEL_MIN_CELLS { par } else { serial };
    println!("{{\"bench\":\"cfd\",\"cells\":{n},\"ns_per_cell_step\":{best:.1}}}");
}
