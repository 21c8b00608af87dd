//! Independent reference for tests and benchmarks: each sphere sampled on a body-centred lattice
//! of points (n per diameter), each point located on the grid in O(1).

use crate::grid::CylGrid;
use std::f64::consts::PI;

/// Solid volume per cell from lattice sampling of each sphere (weights normalised to V_p).
pub fn sampled_solid(g: &CylGrid, positions: &[[f64; 3]], radius: f64, n: usize, out: &mut [f64]) {
    out.fill(0.0);
    let vp = 4.0 / 3.0 * PI * radius.powi(3);
    let h = 2.0 * radius / n as f64;
    let mut offsets = Vec::new();
    for a in 0..n {
        for b in 0..n {
            for c in 0..n {
                let o = [(a as f64 + 0.5) * h - radius, (b as f64 + 0.5) * h - radius, (c as f64 + 0.5) * h - radius];
                if o[0] * o[0] + o[1] * o[1] + o[2] * o[2] < radius * radius {
                    offsets.push(o);
                }
            }
        }
    }
    let w = vp / offsets.len() as f64;
    for p in positions {
        for o in &offsets {
            out[g.locate(p[0] + o[0], p[1] + o[1], p[2] + o[2])] += w;
        }
    }
}
