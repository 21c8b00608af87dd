//! Grouping method of Lim, Wang & Yu (2006), paper eq. 3 / PHYSICS.md 5.
//!
//! The group of cell c is c itself, its 2 angular and 2 axial neighbours (weight 1 each) and its
//! radial neighbours, each weighted by the fraction of c's radial face it shares (so the inner
//! ones weigh 1 in total and the outer ones 1): 7 cells' worth in the interior, which reproduces
//! the paper's Table 3 (cells 1, 2, 3, 8, 9 all 1 − V_s/(7 V_cell)).
//!
//! Written as a scatter so that particle volume is conserved: the direct-method solid of cell n
//! goes to every cell c whose group holds n, in proportion w_cn / Σ_c' w_c'n. In the interior
//! Σ_c' w_c'n = 7 (the radial weights seen from n's side sum to n_{i+1}/n_i + n_{i-1}/n_i = 2),
//! so this is exactly eq. 3 there; at the axis, the wall, the bottom and the top the share of the
//! missing neighbours stays with the cells that exist.

use super::{Direct, VoidageMethod};
use crate::grid::CylGrid;

pub struct Grouping {
    direct: Direct,
    centroid: Vec<f64>,
    /// CSR over source cells n: (target cell c, w_cn / Σ_c' w_c'n).
    start: Vec<usize>,
    targets: Vec<(u32, f64)>,
}

impl Grouping {
    pub fn new(grid: &CylGrid) -> Self {
        let mut start = vec![0];
        let mut targets = Vec::new();
        for n in 0..grid.num_cells() {
            let row = group_weights_from(grid, n);
            let sum: f64 = row.iter().map(|e| e.1).sum();
            targets.extend(row.iter().map(|&(c, w)| (c as u32, w / sum)));
            start.push(targets.len());
        }
        Grouping { direct: Direct::new(grid), centroid: vec![0.0; grid.num_cells()], start, targets }
    }
}

/// Cells c whose group holds cell n, with the weight w_cn that n has in c's group.
pub fn group_weights_from(grid: &CylGrid, n: usize) -> Vec<(usize, f64)> {
    let (i, j, k) = grid.ijk(n);
    let mut row = vec![(n, 1.0)];
    let (a, b) = grid.angular_neighbours(i, j);
    row.push((grid.index(i, a, k), 1.0));
    if b != a {
        row.push((grid.index(i, b, k), 1.0));
    }
    if k > 0 {
        row.push((grid.index(i, j, k - 1), 1.0));
    }
    if k + 1 < grid.nz {
        row.push((grid.index(i, j, k + 1), 1.0));
    }
    // c in annulus i+1 holds n with the fraction of c's inner face that n shares
    for l in grid.outer_neighbours(i, j) {
        let w = grid.inner_neighbours(i + 1, l.j).iter().find(|m| m.j == j).map_or(0.0, |m| m.fraction);
        row.push((grid.index(i + 1, l.j, k), w));
    }
    for l in grid.inner_neighbours(i, j) {
        let w = grid.outer_neighbours(i - 1, l.j).iter().find(|m| m.j == j).map_or(0.0, |m| m.fraction);
        row.push((grid.index(i - 1, l.j, k), w));
    }
    row
}

impl VoidageMethod for Grouping {
    fn name(&self) -> &'static str {
        "grouping"
    }
    fn solid_volume(&mut self, positions: &[[f64; 3]], radius: f64, out: &mut [f64]) {
        self.direct.solid_volume(positions, radius, &mut self.centroid);
        out.fill(0.0);
        for (n, &v) in self.centroid.iter().enumerate() {
            if v != 0.0 {
                for &(c, w) in &self.targets[self.start[n]..self.start[n + 1]] {
                    out[c as usize] += w * v;
                }
            }
        }
    }
}
