//! The pressure force of drag-voidage sub-layers (case `coupling.drag_voidage_sublayers` = n > 1).
//!
//! In model A (PHYSICS.md 11) a particle feels −V_p∇p besides its drag, and in steady flow the gas
//! sets ε∇p = −I, I the drag per volume. Resolved on sub-layers, sub-cell s of a cell would have
//! −∇p_s = I_s/ε_s, and the cell's pressure drop the mean of its sub-cells':
//! G_c = (1/n) Σ_s I_s/ε_s. The fluid cell holds one gradient, so each particle of sub-cell s
//! gets the difference V_p·(G_s − G_c) on top of −V_p∇p_c, and the gas loses the sum of these
//! differences in its cell. With a voidage that counts particle centres the gas then loses ε_c·G_c
//! per volume and its gradient is G_c. Without this, a packed sub-layer in a half-empty cell carries
//! its drag times 1/ε_c instead of 1/ε_s (the U_mf of docs/VALIDATION.md). Both phases gain and lose
//! the same vectors (cell basis): momentum is conserved to round-off.

use super::drag::clamp_voidage;
use super::exchange::cyl_to_cart;
use rayon::prelude::*;

/// What the correction reads: per sub-cell the drag sums of the particle pass (cell basis, one row
/// per chunk) and the drag voidage; the sub-cell of each particle; the geometry.
pub(super) struct SubLayerDrag<'a> {
    pub sums: &'a [Vec<[f64; 3]>],
    /// Sub-cells 0..used: the fluid layers that hold particles; the sums above are zero and not
    /// read.
    pub used: usize,
    pub voidage: &'a [f64],
    pub eps_min: f64,
    pub cell_of: &'a [u32],
    /// Cells per layer, sub-layers per layer, sub-cell volume, particle volume.
    pub per: usize,
    pub n: usize,
    pub v_sub: f64,
    pub vp: f64,
    /// (cos θ_c, sin θ_c) per in-layer cell.
    pub basis: &'a [(f64, f64)],
}

/// Adds V_p(G_s − G_c) to each particle's force (Cartesian) and writes Σ of it per sub-cell (cell
/// basis) into `lost` (the gas loses it; sub-cells 0..used); `g` and `count` are scratch of one
/// entry per sub-cell. The sub-cells above `used` hold no particle: their G_s never reaches one,
/// and the windows of the ones below take their sums as zero.
pub(super) fn add_sublayer_pressure(
    d: &SubLayerDrag,
    force: &mut [[f64; 3]],
    lost: &mut Vec<[f64; 3]>,
    (g, count): (&mut Vec<[f64; 3]>, &mut Vec<u32>),
) {
    let (per, used) = (d.per, d.used);
    let layers = d.voidage.len() / per;
    // I_s over the window of the drag voidage (the sub-cell and the ones above and below it).
    g.resize(used, [0.0; 3]);
    g.par_iter_mut().with_min_len(1024).enumerate().for_each(|(s, gs)| {
        let k = s / per;
        let (lo, hi) = (k.saturating_sub(1), (k + 1).min(layers - 1));
        let mut sum = [0.0; 3];
        for at in (lo..=hi).map(|k2| s - k * per + k2 * per).filter(|&at| at < used) {
            for row in d.sums {
                (0..3).for_each(|q| sum[q] += row[at][q]);
            }
        }
        let w = 1.0 / ((hi - lo + 1) as f64 * d.v_sub * clamp_voidage(d.voidage[s], d.eps_min));
        *gs = [w * sum[0], w * sum[1], w * sum[2]];
    });
    // G_s − G_c: the sub-cells of cell (layer k, in-layer j) are n·k·per + j + i·per, i < n.
    let n = d.n;
    for layer in 0..used / (n * per) {
        for j in 0..per {
            let first = layer * n * per + j;
            let mut mean = [0.0; 3];
            for i in 0..n {
                for q in 0..3 {
                    mean[q] += g[first + i * per][q];
                }
            }
            for i in 0..n {
                let gs = &mut g[first + i * per];
                for q in 0..3 {
                    gs[q] -= mean[q] / n as f64;
                }
            }
        }
    }
    // Every particle of sub-cell s gains the same V_p(G_s − G_c): the gas loses it once per
    // particle there.
    let g = &g[..];
    force.par_iter_mut().zip(d.cell_of.par_iter()).with_min_len(4096).for_each(|(f, &s)| {
        let s = s as usize;
        let (cos, sin) = d.basis[s % per];
        let cart = cyl_to_cart([d.vp * g[s][0], d.vp * g[s][1], d.vp * g[s][2]], cos, sin);
        for q in 0..3 {
            f[q] += cart[q];
        }
    });
    count.clear();
    count.resize(used, 0);
    for &s in d.cell_of {
        count[s as usize] += 1;
    }
    lost.clear();
    lost.extend(g.iter().zip(count.iter()).map(|(gs, &k)| {
        let c = k as f64 * d.vp;
        [c * gs[0], c * gs[1], c * gs[2]]
    }));
}
