//! Exact-cylindrical method (ours): each sphere is split straight onto the polar cells.
//!
//! In z the split is exact: the sphere's volume in each fluid layer is the analytic slab volume
//! π∫(R² − t²)dt. Inside a layer the volume is shared among the (i, j) cells in proportion to
//! ∫A_c(t)dt, where A_c(t) is the *exact* area of the horizontal slice disk (radius √(R² − t²))
//! inside cell c (Green's theorem on circle arcs, `polar_area::disk_cell_area`), integrated by
//! Gauss–Legendre in t over the part of the sphere in that layer. The shares are normalised, so
//! volume is conserved to round-off whatever the node count; the only error is the quadrature of
//! the smooth ∫A_c dt (tested against lattice sampling). A sphere wholly inside one cell (the most
//! common case) costs one point location, and a slice wholly inside one cell needs no area work.

use super::cuboid::Axis;
use super::polar_area::disk_cell_area;
use super::sphere_box::sphere_slab_volume;
use super::{Scatter, VoidageMethod};
use crate::grid::CylGrid;
use std::f64::consts::PI;

/// Gauss–Legendre nodes per layer crossed by a sphere (chosen by the voidage benchmark).
pub const DEFAULT_NODES: usize = 4;

pub struct ExactCylindrical {
    grid: CylGrid,
    nodes: Vec<(f64, f64)>,
    scatter: Scatter<Vec<(usize, f64)>>,
}

impl ExactCylindrical {
    pub fn new(grid: &CylGrid) -> Self {
        Self::with_nodes(grid, DEFAULT_NODES)
    }
    /// With `n` Gauss–Legendre nodes per layer (n ≥ 2 keeps the slab volumes exact).
    pub fn with_nodes(grid: &CylGrid, n: usize) -> Self {
        ExactCylindrical {
            grid: grid.clone(),
            nodes: gauss_legendre(n.max(1)),
            scatter: Scatter::new(grid.num_cells(), || Vec::with_capacity(64)),
        }
    }
}

impl VoidageMethod for ExactCylindrical {
    fn name(&self) -> &'static str {
        "exact_cylindrical"
    }
    fn solid_volume(&mut self, positions: &[[f64; 3]], radius: f64, out: &mut [f64]) {
        let (g, nodes) = (&self.grid, &self.nodes);
        self.scatter.run(positions, out, |p, buf, scratch| split_sphere(g, nodes, p, radius, buf, scratch));
    }
}

/// Does the disk (x, y, ρ) lie inside horizontal cell (i, j)? (Walls of the column do not count:
/// what crosses the wall is given to the cells inside anyway.)
#[inline]
fn disk_inside_cell(g: &CylGrid, x: f64, y: f64, rho: f64, i: usize, j: usize) -> bool {
    let r = (x * x + y * y).sqrt();
    let (r0, r1) = (i as f64 * g.dr, (i + 1) as f64 * g.dr);
    if (i > 0 && r - r0 < rho) || (i + 1 < g.nr && r1 - r < rho) {
        return false;
    }
    let (t0, t1) = g.theta_bounds(i, j);
    // distances to the two lines of the cell's rays
    (t0.cos() * y - t0.sin() * x) >= rho && (t1.sin() * x - t1.cos() * y) >= rho
}

fn split_sphere(
    g: &CylGrid,
    nodes: &[(f64, f64)],
    p: &[f64; 3],
    a: f64,
    out: &mut [f64],
    cells: &mut Vec<(usize, f64)>,
) {
    let vp = 4.0 / 3.0 * PI * a * a * a;
    let (i, j) = g.locate_ij(p[0], p[1]);
    let layers = Axis::new(0.0, g.dz, g.nz);
    let (k0, k1) = (layers.cell(p[2] - a), layers.cell(p[2] + a));
    let per = g.cells_per_layer();
    if disk_inside_cell(g, p[0], p[1], a, i, j) {
        // horizontally whole: only the exact split over layers
        if k0 == k1 {
            out[k0 * per + g.layer_index(i, j)] += vp;
        } else {
            for k in k0..=k1 {
                out[k * per + g.layer_index(i, j)] += layer_volume(g, p[2], a, k);
            }
        }
        return;
    }
    for k in k0..=k1 {
        let vk = layer_volume(g, p[2], a, k);
        if vk <= 0.0 {
            continue;
        }
        let (zl, zh) = layer_bounds(g, k);
        let (ta, tb) = ((zl - p[2]).max(-a), (zh - p[2]).min(a));
        let (mid, half) = (0.5 * (ta + tb), 0.5 * (tb - ta));
        cells.clear();
        for &(xi, w) in nodes {
            let t = mid + half * xi;
            let rho = (a * a - t * t).max(0.0).sqrt();
            slice_areas(g, p[0], p[1], rho, w, cells);
        }
        let total: f64 = cells.iter().map(|e| e.1).sum();
        if total > 0.0 {
            for &(c, s) in cells.iter() {
                out[k * per + c] += vk * s / total;
            }
        } else {
            out[k * per + g.layer_index(i, j)] += vk;
        }
    }
}

/// Add w·area(disk ∩ cell) for every in-layer cell the disk (x, y, ρ) meets.
fn slice_areas(g: &CylGrid, x: f64, y: f64, rho: f64, w: f64, cells: &mut Vec<(usize, f64)>) {
    let mut add = |c: usize, v: f64| match cells.iter_mut().find(|e| e.0 == c) {
        Some(e) => e.1 += v,
        None => cells.push((c, v)),
    };
    let (ic, jc) = g.locate_ij(x, y);
    if disk_inside_cell(g, x, y, rho, ic, jc) {
        add(g.layer_index(ic, jc), w * PI * rho * rho);
        return;
    }
    let rc = (x * x + y * y).sqrt();
    let i0 = (((rc - rho).max(0.0) / g.dr) as usize).min(g.nr - 1);
    let i1 = (((rc + rho) / g.dr) as usize).min(g.nr - 1);
    let tc = y.atan2(x);
    for i in i0..=i1 {
        let n = g.cells_in_annulus(i);
        let dth = g.dtheta(i);
        let (r0, r1) = (i as f64 * g.dr, (i + 1) as f64 * g.dr);
        let (first, count) = if rc <= rho * 1.000001 {
            (0i64, n)
        } else {
            let half = (rho / rc).min(1.0).asin();
            let f = ((tc - half) / dth).floor() as i64;
            let l = ((tc + half) / dth).floor() as i64;
            (f, ((l - f + 1) as usize).min(n))
        };
        for q in 0..count {
            let jj = (first + q as i64).rem_euclid(n as i64) as usize;
            let (t0, t1) = g.theta_bounds(i, jj);
            let area = disk_cell_area([x, y], rho, r0, r1, t0, t1);
            if area > 0.0 {
                add(g.layer_index(i, jj), w * area);
            }
        }
    }
}

fn layer_bounds(g: &CylGrid, k: usize) -> (f64, f64) {
    let lo = if k == 0 { f64::NEG_INFINITY } else { k as f64 * g.dz };
    let hi = if k + 1 == g.nz { f64::INFINITY } else { (k + 1) as f64 * g.dz };
    (lo, hi)
}

fn layer_volume(g: &CylGrid, z: f64, a: f64, k: usize) -> f64 {
    let (lo, hi) = layer_bounds(g, k);
    sphere_slab_volume(z, a, lo, hi)
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|k| {
            let mut x = (PI * (k as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for m in 2..=n {
                    let p2 = ((2 * m - 1) as f64 * x * p1 - (m - 1) as f64 * p0) / m as f64;
                    p0 = p1;
                    p1 = p2;
                }
                if n == 1 {
                    p1 = x;
                    p0 = 1.0;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}
