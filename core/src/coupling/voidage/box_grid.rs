//! The square (box) grid of the square-grid voidage method (paper section 2.3, eq. 8): square
//! boxes of side dl in x and y, centred on the axis with one padding ring, and the fluid layers in
//! z. At start-up each box's fraction in each polar cell is computed from exact areas; a box partly
//! outside the column shares its volume in proportion to box∩cell / box∩column area, so no volume
//! is lost at the wall. A box wholly outside goes to the cell nearest to it.

use super::polar_area::rect_cell_area;
use crate::grid::CylGrid;

#[derive(Clone, Debug)]
pub struct BoxGrid {
    /// Box side dl_xy.
    pub dl: f64,
    /// Boxes per side (including the padding ring).
    pub nb: usize,
    /// x = y of the lower-left corner of box (0, 0).
    pub origin: f64,
    /// CSR: for box b = by·nb + bx, entries start[b]..start[b+1] of (in-layer cell, fraction).
    start: Vec<usize>,
    entries: Vec<(u32, f64)>,
    /// CSR by in-layer cell c: whole[whole_start[c]..whole_start[c+1]] are the boxes that lie in c
    /// alone (fraction 1); `shared` the boxes that share their volume between cells.
    whole_start: Vec<u32>,
    whole: Vec<u32>,
    shared: Vec<u32>,
}

impl BoxGrid {
    pub fn new(grid: &CylGrid, dl: f64) -> BoxGrid {
        assert!(dl > 0.0);
        let inner = (2.0 * grid.radius / dl - 1e-9).ceil() as usize;
        let nb = inner + 2;
        let origin = -(nb as f64) * dl / 2.0;
        let mut start = vec![0];
        let mut entries = Vec::new();
        let mut row = Vec::new();
        for by in 0..nb {
            for bx in 0..nb {
                let (x0, y0) = (origin + bx as f64 * dl, origin + by as f64 * dl);
                let (x1, y1) = (x0 + dl, y0 + dl);
                row.clear();
                let mut in_column = 0.0;
                for (i, j) in candidate_cells(grid, x0, x1, y0, y1) {
                    let (t0, t1) = grid.theta_bounds(i, j);
                    let (r0, r1) = (i as f64 * grid.dr, (i + 1) as f64 * grid.dr);
                    let a = rect_cell_area(x0, x1, y0, y1, r0, r1, t0, t1);
                    if a > 0.0 {
                        row.push((grid.layer_index(i, j) as u32, a));
                        in_column += a;
                    }
                }
                if in_column <= 1e-12 * dl * dl {
                    // wholly outside: the cell at the box point nearest the axis, pulled inside
                    row.clear();
                    let (nx, ny) = (0f64.clamp(x0, x1), 0f64.clamp(y0, y1));
                    let r = (nx * nx + ny * ny).sqrt();
                    let f = if r > 0.0 { (grid.radius * (1.0 - 1e-12) / r).min(1.0) } else { 1.0 };
                    let (i, j) = grid.locate_ij(nx * f, ny * f);
                    row.push((grid.layer_index(i, j) as u32, 1.0));
                } else {
                    for e in row.iter_mut() {
                        e.1 /= in_column;
                    }
                }
                entries.extend_from_slice(&row);
                start.push(entries.len());
            }
        }
        let per = grid.cells_per_layer();
        let (mut by_cell, mut shared) = (vec![Vec::new(); per], Vec::new());
        for b in 0..nb * nb {
            match &entries[start[b]..start[b + 1]] {
                [(c, f)] if *f == 1.0 => by_cell[*c as usize].push(b as u32),
                _ => shared.push(b as u32),
            }
        }
        let mut whole_start = vec![0u32];
        for boxes in &by_cell {
            whole_start.push(whole_start.last().expect("start") + boxes.len() as u32);
        }
        let whole = by_cell.concat();
        BoxGrid { dl, nb, origin, start, entries, whole_start, whole, shared }
    }

    /// The boxes (b = by·nb + bx) that lie in in-layer cell c alone.
    #[inline]
    pub fn whole_boxes_of(&self, c: usize) -> &[u32] {
        &self.whole[self.whole_start[c] as usize..self.whole_start[c + 1] as usize]
    }

    /// The boxes that share their volume between cells (`cells_of_box` gives the shares).
    pub fn shared_boxes(&self) -> &[u32] {
        &self.shared
    }

    /// (in-layer cell, fraction) pairs of box b = by·nb + bx.
    #[inline]
    pub fn cells_of_box(&self, b: usize) -> &[(u32, f64)] {
        &self.entries[self.start[b]..self.start[b + 1]]
    }

    /// (in-layer cell, fraction) pairs of box (bx, by); fractions sum to 1.
    #[inline]
    pub fn cells_of(&self, bx: usize, by: usize) -> &[(u32, f64)] {
        self.cells_of_box(by * self.nb + bx)
    }

    /// Area of box (bx, by) inside the column (for the tiling test).
    pub fn area_in_column(&self, grid: &CylGrid, bx: usize, by: usize) -> f64 {
        let (x0, y0) = (self.origin + bx as f64 * self.dl, self.origin + by as f64 * self.dl);
        let mut a = 0.0;
        for (i, j) in candidate_cells(grid, x0, x0 + self.dl, y0, y0 + self.dl) {
            let (t0, t1) = grid.theta_bounds(i, j);
            a += rect_cell_area(
                x0,
                x0 + self.dl,
                y0,
                y0 + self.dl,
                i as f64 * grid.dr,
                (i + 1) as f64 * grid.dr,
                t0,
                t1,
            );
        }
        a
    }
}

/// Polar cells (i, j) that may meet the rectangle: annuli between its nearest and farthest
/// distance from the axis, and in each annulus the cells within its angular span.
fn candidate_cells(grid: &CylGrid, x0: f64, x1: f64, y0: f64, y1: f64) -> Vec<(usize, usize)> {
    let near = {
        let (nx, ny) = (0f64.clamp(x0, x1), 0f64.clamp(y0, y1));
        (nx * nx + ny * ny).sqrt()
    };
    let far = [x0.abs().max(x1.abs()), y0.abs().max(y1.abs())];
    let far = (far[0] * far[0] + far[1] * far[1]).sqrt();
    let mut out = Vec::new();
    if near >= grid.radius {
        return out;
    }
    let i0 = ((near / grid.dr) as usize).min(grid.nr - 1);
    let i1 = ((far / grid.dr) as usize).min(grid.nr - 1);
    let contains_axis = x0 <= 0.0 && x1 >= 0.0 && y0 <= 0.0 && y1 >= 0.0;
    let (tc, span) = if contains_axis {
        (0.0, f64::INFINITY)
    } else {
        let tc = (0.5 * (y0 + y1)).atan2(0.5 * (x0 + x1));
        let mut lo: f64 = 0.0;
        let mut hi: f64 = 0.0;
        for (x, y) in [(x0, y0), (x1, y0), (x1, y1), (x0, y1)] {
            let d =
                (y.atan2(x) - tc + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI;
            lo = lo.min(d);
            hi = hi.max(d);
        }
        (tc, hi - lo + 1e-9)
    };
    for i in i0..=i1 {
        let n = grid.cells_in_annulus(i);
        let w = grid.dtheta(i);
        if span >= std::f64::consts::PI {
            out.extend((0..n).map(|j| (i, j)));
        } else {
            // a generous angular window around the box centre
            let first = ((tc - span) / w).floor() as i64 - 1;
            let last = ((tc + span) / w).floor() as i64 + 1;
            let count = ((last - first + 1) as usize).min(n);
            out.extend((0..count).map(|k| (i, (first + k as i64).rem_euclid(n as i64) as usize)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_fractions_sum_to_one_and_tile_each_cell() {
        let grid = CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3);
        for dl in [0.0044, 0.0022, 0.001375, 0.0017] {
            let bg = BoxGrid::new(&grid, dl);
            let mut cell_area = vec![0.0; grid.cells_per_layer()];
            for by in 0..bg.nb {
                for bx in 0..bg.nb {
                    let s: f64 = bg.cells_of(bx, by).iter().map(|e| e.1).sum();
                    assert!((s - 1.0).abs() < 1e-13, "box sum {s}");
                    let a = bg.area_in_column(&grid, bx, by);
                    for &(c, f) in bg.cells_of(bx, by) {
                        cell_area[c as usize] += f * a;
                    }
                }
            }
            for a in cell_area {
                assert!((a / grid.cell_area() - 1.0).abs() < 1e-12, "dl {dl}: {}", a / grid.cell_area());
            }
        }
    }
}
