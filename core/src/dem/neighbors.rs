//! O(N) neighbour search: linked cells give the cell order (particles are re-sorted by cell
//! at every rebuild for memory locality) and a half Verlet list (each pair once, j > i) in CSR
//! form, each row nearest first (touching pairs lead). The list holds no contact histories: at a
//! build they are carried by particle-id pair (`id_histories`) into the near list (`near_list`),
//! which holds them between builds. Everything here is deterministic and independent of the thread count.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Particles per work block of the list build (fixed, so results do not depend on threads).
pub(super) const BLOCK: usize = 256;

/// A contact history ξ as stored: single precision, what the pair law (`pair_batch::lanes`)
/// computes it in, so storing it so loses nothing and halves the bytes the pair pass streams.
pub type Hist = [f32; 3];

/// Half neighbour list in CSR form.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct NeighborList {
    /// Row i is nbr[offsets[i]..offsets[i+1]], all j > i.
    pub offsets: Vec<u32>,
    pub nbr: Vec<u32>,
    /// Tangential displacement ξ of each listed pair (oriented i → j); live only where `touch`.
    pub shear: Vec<Hist>,
    /// 1 when the pair touched in the last force evaluation (its history is live), else 0.
    pub touch: Vec<u8>,
}

/// Cell order of the particles: the permutation that sorts them by linked cell (stable).
pub fn cell_order(x: &[[f64; 3]], tube_radius: f64, cell: f64) -> Vec<u32> {
    let grid = CellGrid::new(x, tube_radius, cell);
    let cells: Vec<u32> = x.par_iter().map(|p| grid.cell_of(p) as u32).collect();
    let mut count = vec![0u32; grid.len() + 1];
    for &c in &cells {
        count[c as usize + 1] += 1;
    }
    for c in 0..grid.len() {
        count[c + 1] += count[c];
    }
    let mut order = vec![0u32; x.len()];
    for (i, &c) in cells.iter().enumerate() {
        order[count[c as usize] as usize] = i as u32;
        count[c as usize] += 1;
    }
    order
}

/// Uniform cells of side ≥ `cell` covering the tube cross-section and the particles' z range.
struct CellGrid {
    lo: [f64; 3],
    inv: [f64; 3],
    n: [usize; 3],
}

impl CellGrid {
    fn new(x: &[[f64; 3]], tube_radius: f64, cell: f64) -> Self {
        let (mut zlo, mut zhi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in x {
            zlo = zlo.min(p[2]);
            zhi = zhi.max(p[2]);
        }
        if !(zlo.is_finite() && zhi.is_finite()) {
            (zlo, zhi) = (0.0, 0.0);
        }
        let side = 2.0 * tube_radius;
        let nxy = ((side / cell).floor() as usize).max(1);
        let nz = (((zhi - zlo) / cell).floor() as usize).clamp(1, 1 << 20);
        let dxy = side / nxy as f64;
        let dz = ((zhi - zlo) / nz as f64).max(cell);
        CellGrid { lo: [-tube_radius, -tube_radius, zlo], inv: [1.0 / dxy, 1.0 / dxy, 1.0 / dz], n: [nxy, nxy, nz] }
    }
    fn len(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }
    #[inline]
    fn coord(&self, p: &[f64; 3], a: usize) -> usize {
        let c = ((p[a] - self.lo[a]) * self.inv[a]).floor();
        (c.max(0.0) as usize).min(self.n[a] - 1)
    }
    #[inline]
    fn cell_of(&self, p: &[f64; 3]) -> usize {
        (self.coord(p, 2) * self.n[1] + self.coord(p, 1)) * self.n[0] + self.coord(p, 0)
    }
}

/// Build the half list for particles already sorted by cell (`x` in cell order), pairs closer
/// than `cutoff`, each row sorted by the gap to contact (centre distance − `diameter`).
#[cfg(test)]
pub fn build_list(x: &[[f64; 3]], tube_radius: f64, cutoff: f64, diameter: f64) -> NeighborList {
    let rows = build_rows(x, tube_radius, cutoff, diameter);
    let mut offsets = Vec::with_capacity(x.len() + 1);
    offsets.push(0u32);
    let total: usize = rows.iter().map(|r| r.1.len()).sum();
    let mut nbr = Vec::with_capacity(total);
    for (counts, list) in rows {
        for c in counts {
            offsets.push(offsets.last().unwrap() + c);
        }
        nbr.extend_from_slice(&list);
    }
    NeighborList { offsets, nbr, shear: Vec::new(), touch: Vec::new() }
}

/// The rows of `build_list` per block of BLOCK particles, in block order: each row's length and
/// the block's partners.
pub fn build_rows(x: &[[f64; 3]], tube_radius: f64, cutoff: f64, diameter: f64) -> Vec<(Vec<u32>, Vec<u32>)> {
    let grid = CellGrid::new(x, tube_radius, cutoff);
    let ncell = grid.len();
    let cells: Vec<usize> = x.par_iter().map(|p| grid.cell_of(p)).collect();
    let mut start = vec![0u32; ncell + 1];
    for &c in &cells {
        start[c + 1] += 1;
    }
    for c in 0..ncell {
        start[c + 1] += start[c];
    }
    let c2 = cutoff * cutoff;
    let [nx, ny, nz] = grid.n;
    // Rows built per block in parallel, concatenated in block order.
    (0..x.len().div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            let (a, e) = (b * BLOCK, ((b + 1) * BLOCK).min(x.len()));
            let mut counts = Vec::with_capacity(e - a);
            let mut list = Vec::with_capacity((e - a) * 8);
            let mut row: Vec<(f32, u32)> = Vec::new();
            for i in a..e {
                let before = list.len();
                let c = cells[i];
                let (ix, iy, iz) = (c % nx, (c / nx) % ny, c / (nx * ny));
                let xi = x[i];
                // Neighbour cells in increasing linear index: j ascending, and j > i.
                for dz in 0..3usize {
                    let z = iz + dz;
                    if z == 0 || z > nz {
                        continue;
                    }
                    for dy in 0..3usize {
                        let y = iy + dy;
                        if y == 0 || y > ny {
                            continue;
                        }
                        for dxx in 0..3usize {
                            let xx = ix + dxx;
                            if xx == 0 || xx > nx {
                                continue;
                            }
                            let cc = ((z - 1) * ny + (y - 1)) * nx + (xx - 1);
                            if cc < c {
                                continue;
                            }
                            let lo = (start[cc] as usize).max(i + 1);
                            for (j, xj) in x.iter().enumerate().take(start[cc + 1] as usize).skip(lo) {
                                let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                                if r2 < c2 {
                                    row.push(((r2.sqrt() - diameter) as f32, j as u32));
                                }
                            }
                        }
                    }
                }
                // nearest first (touching pairs lead; entry order is force summation order)
                row.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
                list.extend(row.drain(..).map(|e| e.1));
                counts.push((list.len() - before) as u32);
            }
            (counts, list)
        })
        .collect()
}
