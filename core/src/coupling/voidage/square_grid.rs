//! Square-grid method (paper section 2.3, eq. 8–9): particle volume is split over boxes of side
//! dl_xy × dl_xy × dz (aligned with the fluid layers) by the cuboid approximation (PHYSICS.md 4)
//! or exactly (PHYSICS.md 3), then mapped to the cells with the box→cell fractions of `BoxGrid`.

use super::box_grid::BoxGrid;
use super::cuboid::{interval_split, Axis, FixedSplit, SplitThree, SplitTwo, MAX_SPAN};
use super::sphere_box::sphere_box_volume;
use super::{Scatter, VoidageMethod};
use crate::case::BoxSplit;
use crate::grid::CylGrid;
use crate::simd::per_isa;
use std::f64::consts::PI;

pub struct SquareGrid {
    grid: CylGrid,
    boxes: BoxGrid,
    split: BoxSplit,
    cube_side_factor: f64,
    scatter: Scatter<()>,
    /// Solid volume per box of the layers each fixed chunk reaches, one buffer per chunk.
    box_volume: Vec<BoxSums>,
}

/// Fixed number of particle chunks for the box accumulation (results do not depend on threads).
const BOX_CHUNKS: usize = 2;

impl SquareGrid {
    pub fn new(grid: &CylGrid, box_side: f64, split: BoxSplit, cube_side_factor: f64) -> Self {
        SquareGrid {
            grid: grid.clone(),
            boxes: BoxGrid::new(grid, box_side),
            split,
            cube_side_factor,
            scatter: Scatter::new(grid.num_cells(), || ()),
            box_volume: Vec::new(),
        }
    }
    pub fn box_grid(&self) -> &BoxGrid {
        &self.boxes
    }
}

impl VoidageMethod for SquareGrid {
    fn name(&self) -> &'static str {
        match self.split {
            BoxSplit::Cuboid => "square_grid_cuboid",
            BoxSplit::Exact => "square_grid_exact",
        }
    }
    fn solid_volume(&mut self, positions: &[[f64; 3]], radius: f64, out: &mut [f64]) {
        let (g, bg) = (&self.grid, &self.boxes);
        match self.split {
            BoxSplit::Cuboid => {
                let h = self.cube_side_factor * 2.0 * radius;
                two_stage_cuboid(g, bg, &mut self.box_volume, positions, radius, h, out)
            }
            BoxSplit::Exact => self.scatter.run(positions, out, |p, buf, _| exact_particle(g, bg, p, radius, buf)),
        }
    }
}

/// One chunk's solid volume per box of the layers it reaches this call, `layers`: box (k, by, bx)
/// at ((k − layers.start)·nb + by)·nb + bx. Sized to those layers, not the column's (the
/// freeboard holds no solid); the buffer keeps its largest size, so calls do not allocate once the
/// bed has reached its height.
#[derive(Clone, Default)]
struct BoxSums {
    volume: Vec<f64>,
    layers: std::ops::Range<usize>,
}

/// The paper's two stages (eq. 8): every particle's cube onto the boxes (≤ 8 boxes per particle,
/// PHYSICS.md 4), then each box's solid volume onto the cells with the precomputed fractions,
/// once per call — so the per-particle work does not grow with the cells a box touches.
fn two_stage_cuboid(
    g: &CylGrid,
    bg: &BoxGrid,
    bufs: &mut Vec<BoxSums>,
    positions: &[[f64; 3]],
    radius: f64,
    h: f64,
    out: &mut [f64],
) {
    use rayon::prelude::*;
    let nb = bg.nb;
    if bufs.len() != BOX_CHUNKS {
        *bufs = vec![BoxSums::default(); BOX_CHUNKS];
    }
    let vp = 4.0 / 3.0 * PI * radius.powi(3);
    let chunk = positions.len().div_ceil(BOX_CHUNKS).max(1);
    // Each chunk clears, fills and hands on only the layers its cubes reach (the particles are
    // in the DEM's z-major cell order, so the chunks are mostly the lower and the upper bed, and
    // the freeboard holds no solid): cubes span [z − h/2, z + h/2], so layers
    // cell(z_min − h/2) ..= cell(z_max + h/2) of the chunk, and one more at each end (below).
    let up = Axis::new(0.0, g.dz, g.nz);
    bufs.par_iter_mut().enumerate().for_each(|(n, sums)| {
        let lo = (n * chunk).min(positions.len());
        let hi = ((n + 1) * chunk).min(positions.len());
        let (z_min, z_max) =
            positions[lo..hi].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p[2]), b.max(p[2])));
        // One layer more at each end: the split's cell of an end can round to the neighbour of
        // `Axis::cell`'s, and its second pair names the next layer even at a zero share.
        let (k0, k1) = if lo == hi {
            (0, 0)
        } else {
            (up.cell(z_min - h / 2.0).saturating_sub(1), (up.cell(z_max + h / 2.0) + 2).min(g.nz))
        };
        sums.layers = k0..k1;
        let buf = &mut sums.volume;
        buf.clear();
        buf.resize((k1 - k0) * nb * nb, 0.0);
        // Box indices below are the column's, less the first layer's.
        let base = k0 * nb * nb;
        let (mut fx, mut fy, mut fz) = ([(0, 0.0); MAX_SPAN], [(0, 0.0); MAX_SPAN], [(0, 0.0); MAX_SPAN]);
        let across = Axis::new(bg.origin, bg.dl, nb);
        if h <= bg.dl && h <= 2.0 * g.dz {
            // Every cube in at most 2 × 2 × 2 boxes (× 3 layers thinner than the cube: drag-voidage
            // sub-layers): eight (twelve) adds, no data-dependent branch.
            let (cubes, across) = (&positions[lo..hi], SplitTwo::new(&across, h));
            if h <= g.dz {
                deposit_small_cubes_on(cubes, across, SplitTwo::new(&up, h), nb, base, vp, buf);
            } else {
                deposit_cubes_on_thin_layers(cubes, across, SplitThree::new(&up, h), nb, base, vp, buf);
            }
            return;
        }
        for p in &positions[lo..hi] {
            let nx = interval_split(p[0], h, &across, &mut fx);
            let ny = interval_split(p[1], h, &across, &mut fy);
            let nz = interval_split(p[2], h, &up, &mut fz);
            for &(k, sz) in &fz[..nz] {
                for &(by, sy) in &fy[..ny] {
                    let row = (k * nb + by) * nb - base;
                    for &(bx, sx) in &fx[..nx] {
                        buf[row + bx] += vp * sx * sy * sz;
                    }
                }
            }
        }
    });
    // boxes → cells, layer by layer (parallel over layers; each layer writes its own cells), from
    // the chunks whose layers include it, in chunk order
    let per = g.cells_per_layer();
    out.par_chunks_mut(per).enumerate().for_each(|(k, layer)| {
        layer.fill(0.0);
        // Layer k's boxes of each chunk that reaches it.
        let (mut from, mut m): ([&[f64]; BOX_CHUNKS], usize) = ([&[]; BOX_CHUNKS], 0);
        for sums in bufs.iter().filter(|s| s.layers.contains(&k)) {
            let at = (k - sums.layers.start) * nb * nb;
            (from[m], m) = (&sums.volume[at..at + nb * nb], m + 1);
        }
        if m == 0 {
            return;
        }
        let (first, rest) = (from[0], &from[1..m]);
        let v = |b: u32| first[b as usize] + rest.iter().map(|r| r[b as usize]).sum::<f64>();
        // Each cell sums its whole boxes in registers (four running sums), so consecutive boxes of
        // one cell do not wait on each other through memory; then the shared boxes add their shares.
        for (c, out) in layer.iter_mut().enumerate() {
            let boxes = bg.whole_boxes_of(c);
            let mut acc = [0.0; 4];
            let mut quads = boxes.chunks_exact(4);
            for q in &mut quads {
                for (a, &b) in acc.iter_mut().zip(q) {
                    *a += v(b);
                }
            }
            let tail: f64 = quads.remainder().iter().map(|&b| v(b)).sum();
            *out = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + tail;
        }
        for &b in bg.shared_boxes() {
            let vb = v(b);
            if vb != 0.0 {
                for &(c, f) in bg.cells_of_box(b as usize) {
                    layer[c as usize] += vb * f;
                }
            }
        }
    });
}

per_isa!(
    /// `deposit_small_cubes` on the best vector path the CPU has (`simd::per_isa`): the same
    /// operations in the same order (no fused multiply-add), so the same bits.
    fn deposit_small_cubes_on, deposit_paths, deposit_small_cubes,
    (positions: &[[f64; 3]], across: SplitTwo, up: SplitTwo, nb: usize, base: usize, vp: f64, buf: &mut [f64])
);

per_isa!(
    /// `deposit_small_cubes` for layers thinner than the cube (h ≤ 2 dz), on the best vector path.
    fn deposit_cubes_on_thin_layers, thin_layer_paths, deposit_small_cubes,
    (positions: &[[f64; 3]], across: SplitTwo, up: SplitThree, nb: usize, base: usize, vp: f64, buf: &mut [f64])
);

/// Each particle's cube (side h ≤ the box side) onto its 2 × 2 × (2 or 3) boxes of `buf`
/// (layer-major, rows of `nb` boxes, the column's box index less `base`), the layers split by
/// `up`: per layer and row the two boxes are neighbours.
#[inline(always)]
fn deposit_small_cubes<Z: FixedSplit>(
    positions: &[[f64; 3]],
    across: SplitTwo,
    up: Z,
    nb: usize,
    base: usize,
    vp: f64,
    buf: &mut [f64],
) {
    for p in positions {
        let ([(x0, wx0), (x1, wx1)], [(y0, wy0), (y1, wy1)]) = (across.split(p[0]), across.split(p[1]));
        for &(k, wz) in up.split(p[2]).as_ref() {
            let wz = vp * wz;
            for (by, w) in [(y0, wz * wy0), (y1, wz * wy1)] {
                let row = (k * nb + by) * nb - base;
                buf[row + x0] += w * wx0;
                buf[row + x1] += w * wx1;
            }
        }
    }
}

/// Cube of side h: separable shares per axis (PHYSICS.md 4), then box → cells, particle by
/// particle (the reference for the two-stage path).
#[cfg(test)]
pub(super) fn cuboid_particle(g: &CylGrid, bg: &BoxGrid, p: &[f64; 3], radius: f64, h: f64, out: &mut [f64]) {
    let vp = 4.0 / 3.0 * PI * radius.powi(3);
    let mut fx = [(0, 0.0); MAX_SPAN];
    let mut fy = [(0, 0.0); MAX_SPAN];
    let mut fz = [(0, 0.0); MAX_SPAN];
    let across = Axis::new(bg.origin, bg.dl, bg.nb);
    let nx = interval_split(p[0], h, &across, &mut fx);
    let ny = interval_split(p[1], h, &across, &mut fy);
    let nz = interval_split(p[2], h, &Axis::new(0.0, g.dz, g.nz), &mut fz);
    let per = g.cells_per_layer();
    for &(by, sy) in &fy[..ny] {
        for &(bx, sx) in &fx[..nx] {
            let cells = bg.cells_of(bx, by);
            for &(k, sz) in &fz[..nz] {
                let v = vp * sx * sy * sz;
                let base = k * per;
                for &(c, f) in cells {
                    out[base + c as usize] += v * f;
                }
            }
        }
    }
}

/// Exact sphere ∩ box volumes (PHYSICS.md 3); the end boxes and layers reach to infinity so
/// nothing is lost, and the shares are normalised to V_p against round-off.
fn exact_particle(g: &CylGrid, bg: &BoxGrid, p: &[f64; 3], radius: f64, out: &mut [f64]) {
    let vp = 4.0 / 3.0 * PI * radius.powi(3);
    let bounds = |idx: usize, origin: f64, dl: f64, n: usize| {
        let lo = if idx == 0 { f64::NEG_INFINITY } else { origin + idx as f64 * dl };
        let hi = if idx + 1 == n { f64::INFINITY } else { origin + (idx + 1) as f64 * dl };
        (lo, hi)
    };
    let span = |x: f64, origin: f64, dl: f64, n: usize| {
        let axis = Axis::new(origin, dl, n);
        (axis.cell(x - radius), axis.cell(x + radius))
    };
    let (x0, x1) = span(p[0], bg.origin, bg.dl, bg.nb);
    let (y0, y1) = span(p[1], bg.origin, bg.dl, bg.nb);
    let (z0, z1) = span(p[2], 0.0, g.dz, g.nz);
    let mut parts = [(0usize, 0usize, 0usize, 0.0f64); MAX_SPAN * MAX_SPAN * 2];
    let mut m = 0;
    let mut total = 0.0;
    for k in z0..=z1 {
        let (zl, zh) = bounds(k, 0.0, g.dz, g.nz);
        for by in y0..=y1 {
            let (yl, yh) = bounds(by, bg.origin, bg.dl, bg.nb);
            for bx in x0..=x1 {
                let (xl, xh) = bounds(bx, bg.origin, bg.dl, bg.nb);
                let v = sphere_box_volume(*p, radius, [xl, yl, zl], [xh, yh, zh]);
                if v > 0.0 && m < parts.len() {
                    parts[m] = (bx, by, k, v);
                    m += 1;
                    total += v;
                }
            }
        }
    }
    let per = g.cells_per_layer();
    for &(bx, by, k, v) in &parts[..m] {
        let v = v * vp / total;
        for &(c, f) in bg.cells_of(bx, by) {
            out[k * per + c as usize] += v * f;
        }
    }
}

#[cfg(test)]
mod two_stage_tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn two_stage_equals_the_per_particle_split() {
        // (layer height, box side, cube side factor): the general path (cube 1.2 mm over 1.375-mm
        // boxes), the 2 × 2 × 2 path, and the 2 × 2 × 3 path of layers thinner than the cube
        // (8 drag-voidage sub-layers of 4.4 mm).
        for (dz, side, f) in [(0.0044, 0.001375, 1.0), (0.0022, 0.0008, 0.66), (0.00055, 0.0008, 0.66)] {
            let g = CylGrid::new(0.022, 0.0264, 0.0044, dz, 3);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
            let pos: Vec<[f64; 3]> = (0..6000)
                .map(|_| {
                    let (r, t) = (0.0214 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                    [r * t.cos(), r * t.sin(), rng.gen_range(0.0006..0.0258)]
                })
                .collect();
            let radius = 0.0006;
            let h = f * 2.0 * radius;
            let mut sg = SquareGrid::new(&g, side, BoxSplit::Cuboid, f);
            let mut fast = vec![0.0; g.num_cells()];
            sg.solid_volume(&pos, radius, &mut fast);
            let mut slow = vec![0.0; g.num_cells()];
            for p in &pos {
                cuboid_particle(&g, &sg.boxes, p, radius, h, &mut slow);
            }
            let vp = 4.0 / 3.0 * PI * radius.powi(3);
            for c in 0..g.num_cells() {
                let tol = 1e-12 * vp * pos.len() as f64;
                assert!((fast[c] - slow[c]).abs() < tol, "dz {dz}, cell {c}: {} vs {}", fast[c], slow[c]);
            }
            let total: f64 = fast.iter().sum();
            assert!((total / (vp * pos.len() as f64) - 1.0).abs() < 1e-12, "dz {dz}");
        }
    }

    #[test]
    fn every_code_path_deposits_the_same_bits() {
        // The portable deposit against the one this CPU runs, on a bed packed in the cell order.
        let g = CylGrid::new(0.022, 0.0264, 0.0044, 0.0022, 3);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut pos: Vec<[f64; 3]> = (0..4000)
            .map(|_| {
                let (r, t) = (0.0216 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0264)]
            })
            .collect();
        pos.sort_by(|a, b| a[2].total_cmp(&b[2]));
        let bg = BoxGrid::new(&g, 0.0008);
        let (across, up) = (Axis::new(bg.origin, bg.dl, bg.nb), Axis::new(0.0, g.dz, g.nz));
        let h = 0.66 * 0.0012;
        let (across, up) = (SplitTwo::new(&across, h), SplitTwo::new(&up, h));
        let mut best = vec![0.0; bg.nb * bg.nb * g.nz];
        let mut portable = best.clone();
        deposit_small_cubes_on(&pos, across, up, bg.nb, 0, 1.0, &mut best);
        deposit_small_cubes(&pos, across, up, bg.nb, 0, 1.0, &mut portable);
        assert!(best.iter().zip(&portable).all(|(a, b)| a.to_bits() == b.to_bits()));
        let total: f64 = best.iter().sum();
        assert!((total - pos.len() as f64).abs() < 1e-9, "volume {total}");
        // Layers thinner than the cube (2 × 2 × 3).
        let thin = CylGrid::new(0.022, 0.0264, 0.0044, 0.00055, 3);
        let up = SplitThree::new(&Axis::new(0.0, thin.dz, thin.nz), h);
        let mut best = vec![0.0; bg.nb * bg.nb * thin.nz];
        let mut portable = best.clone();
        deposit_cubes_on_thin_layers(&pos, across, up, bg.nb, 0, 1.0, &mut best);
        deposit_small_cubes(&pos, across, up, bg.nb, 0, 1.0, &mut portable);
        assert!(best.iter().zip(&portable).all(|(a, b)| a.to_bits() == b.to_bits()));
        let total: f64 = best.iter().sum();
        assert!((total - pos.len() as f64).abs() < 1e-9, "thin layers: volume {total}");
    }

    #[test]
    fn layers_without_solid_are_skipped_and_keep_nothing_from_an_earlier_call() {
        // A bed in the top layers, then the same bed dropped to the bottom: the second call must
        // equal a fresh method's (no stale box sums in the layers the first call filled), and the
        // layers no cube reaches hold exactly nothing. Both box sizes: the 8-add path (cube ≤ box)
        // and the general one.
        let g = CylGrid::new(0.022, 0.0264, 0.0044, 0.0022, 3);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let (radius, per) = (0.0006, g.cells_per_layer());
        let high: Vec<[f64; 3]> = (0..3000)
            .map(|_| {
                let (r, t) = (0.0214 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                [r * t.cos(), r * t.sin(), rng.gen_range(0.018..0.0258)]
            })
            .collect();
        let low: Vec<[f64; 3]> = high.iter().map(|p| [p[0], p[1], p[2] - 0.0175]).collect();
        for (side, f) in [(0.0008, 0.66), (0.001375, 1.0)] {
            let mut reused = SquareGrid::new(&g, side, BoxSplit::Cuboid, f);
            let mut out = vec![0.0; g.num_cells()];
            reused.solid_volume(&high, radius, &mut out);
            reused.solid_volume(&low, radius, &mut out);
            let mut fresh = vec![0.0; g.num_cells()];
            SquareGrid::new(&g, side, BoxSplit::Cuboid, f).solid_volume(&low, radius, &mut fresh);
            assert!(out == fresh, "box {side}: a reused method differs from a fresh one");
            let top = low.iter().map(|p| p[2]).fold(0.0, f64::max) + f * radius;
            let first_empty = (top / g.dz).floor() as usize + 1;
            assert!(out[first_empty * per..].iter().all(|&v| v == 0.0), "box {side}: solid above the bed");
            let vp = 4.0 / 3.0 * PI * radius.powi(3);
            let total: f64 = out.iter().sum();
            assert!((total / (vp * low.len() as f64) - 1.0).abs() < 1e-12, "box {side}: volume {total}");
        }
    }
}
