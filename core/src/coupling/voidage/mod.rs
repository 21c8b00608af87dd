//! Voidage methods (paper section 1 and 2.3): each turns particle positions into the solid volume
//! in every fluid cell; ε = 1 − V_s/V_cell (paper eq. 1). All methods conserve the total particle
//! volume to round-off (a particle's parts outside the column are given to the cells inside).

pub mod box_grid;
pub mod cuboid;
pub mod direct;
pub mod exact_cylindrical;
pub mod grouping;
pub mod polar_area;
pub mod sampling;
pub mod sphere_box;
pub mod square_grid;
pub mod table3;

pub use direct::Direct;
pub use exact_cylindrical::ExactCylindrical;
pub use grouping::Grouping;
pub use square_grid::SquareGrid;

use crate::case::{Case, Voidage};
use crate::grid::CylGrid;
use rayon::prelude::*;

/// One way of turning particles into solid volume per fluid cell. Called every coupling step:
/// implementations allocate nothing per call.
pub trait VoidageMethod: Send + Sync {
    fn name(&self) -> &'static str;
    /// Solid volume per fluid cell (len = grid.num_cells()), overwritten.
    fn solid_volume(&mut self, positions: &[[f64; 3]], radius: f64, out: &mut [f64]);
}

/// The method the case asks for.
pub fn build_voidage(case: &Case, grid: &CylGrid) -> Box<dyn VoidageMethod> {
    build_from(&case.voidage, case.particles.diameter_m, case.column.diameter_m, grid)
}

/// The method for a `Voidage` setting, particle diameter `d` and column diameter.
pub fn build_from(v: &Voidage, d: f64, column_diameter: f64, grid: &CylGrid) -> Box<dyn VoidageMethod> {
    match v {
        Voidage::Direct => Box::new(Direct::new(grid)),
        Voidage::Grouping => Box::new(Grouping::new(grid)),
        Voidage::SquareGrid { box_side_m, split, cube_side_factor } => {
            let dl = box_side_m.unwrap_or_else(|| default_box_side(column_diameter, d));
            Box::new(SquareGrid::new(grid, dl, *split, *cube_side_factor))
        }
        Voidage::ExactCylindrical => Box::new(ExactCylindrical::new(grid)),
    }
}

/// Configuration 3 of the paper's section 3.2, "just above d": the column diameter divided into
/// the largest power-of-two number of boxes that are still wider than d (44 mm, d = 1.2 mm →
/// 32 boxes of 1.375 mm, the paper's value).
pub fn default_box_side(column_diameter: f64, d: f64) -> f64 {
    let mut n = 1usize;
    while column_diameter / (2 * n) as f64 > d {
        n *= 2;
    }
    column_diameter / n as f64
}

/// ε = 1 − V_s / V_cell (paper eq. 1, 9).
pub fn voidage_from_solid(grid: &CylGrid, solid: &[f64], out: &mut [f64]) {
    let inv = 1.0 / grid.cell_volume();
    for (e, s) in out.iter_mut().zip(solid) {
        *e = 1.0 - s * inv;
    }
}

/// Below this many particles the scatter runs on one thread.
const PARALLEL_MIN_PARTICLES: usize = 4096;
/// Fixed number of partial sums, so results do not depend on the thread count.
const CHUNKS: usize = 8;

/// Per-particle scatter into per-cell sums, in parallel over fixed chunks of particles with a
/// preallocated buffer (and scratch `S`) per chunk, summed in a fixed order.
pub(crate) struct Scatter<S> {
    parts: Vec<(Vec<f64>, S)>,
}

impl<S: Send + Sync> Scatter<S> {
    pub fn new(cells: usize, make: impl Fn() -> S) -> Self {
        Scatter { parts: (0..CHUNKS).map(|_| (vec![0.0; cells], make())).collect() }
    }

    pub fn run<F>(&mut self, positions: &[[f64; 3]], out: &mut [f64], f: F)
    where
        F: Fn(&[f64; 3], &mut [f64], &mut S) + Sync,
    {
        if positions.len() < PARALLEL_MIN_PARTICLES {
            out.fill(0.0);
            let s = &mut self.parts[0].1;
            for p in positions {
                f(p, out, s);
            }
            return;
        }
        let chunk = positions.len().div_ceil(CHUNKS);
        let used = positions.len().div_ceil(chunk);
        self.parts.par_iter_mut().zip(positions.par_chunks(chunk)).for_each(|((buf, s), ps)| {
            buf.fill(0.0);
            for p in ps {
                f(p, buf, s);
            }
        });
        let parts = &self.parts[..used];
        out.par_iter_mut().enumerate().for_each(|(c, o)| *o = parts.iter().map(|p| p.0[c]).sum());
    }
}

#[cfg(test)]
mod tests;
