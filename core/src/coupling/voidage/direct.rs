//! Direct (particle-centroid) method, paper eq. 2 / PHYSICS.md 5: a particle's whole volume goes
//! to the cell holding its centre.

use super::{Scatter, VoidageMethod};
use crate::grid::CylGrid;
use std::f64::consts::PI;

pub struct Direct {
    grid: CylGrid,
    scatter: Scatter<()>,
}

impl Direct {
    pub fn new(grid: &CylGrid) -> Self {
        Direct { grid: grid.clone(), scatter: Scatter::new(grid.num_cells(), || ()) }
    }
}

impl VoidageMethod for Direct {
    fn name(&self) -> &'static str {
        "direct"
    }
    fn solid_volume(&mut self, positions: &[[f64; 3]], radius: f64, out: &mut [f64]) {
        let vp = 4.0 / 3.0 * PI * radius.powi(3);
        let g = &self.grid;
        self.scatter.run(positions, out, |p, buf, _| buf[g.locate(p[0], p[1], p[2])] += vp);
    }
}
