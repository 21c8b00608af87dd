//! Radial profiles at chosen heights and azimuthal-mean maps on the axial (r, z) plane, from a
//! per-cell field (a time average). With weights (the particle counts of `ParticleMeans`) an
//! annulus mean Σ w_c q_c / Σ w_c of particle-based cell averages is itself particle-based:
//! Σ_c Σ_s Σ_p q_p / Σ_c Σ_s N_c(s). Without weights every cell counts once (equal volumes).

use crate::grid::CylGrid;
use serde::{Deserialize, Serialize};

/// Annulus means over layers `k0 ..= k1`: value and total weight per annulus. Cells with zero
/// weight or a NaN value are left out; an annulus with none left is NaN.
fn annulus_means(
    grid: &CylGrid,
    values: &[f64],
    weights: Option<&[f64]>,
    k0: usize,
    k1: usize,
) -> (Vec<f64>, Vec<f64>) {
    assert_eq!(values.len(), grid.num_cells(), "profile: values size");
    if let Some(w) = weights {
        assert_eq!(w.len(), grid.num_cells(), "profile: weights size");
    }
    let (mut sum, mut wsum) = (vec![0.0; grid.nr], vec![0.0; grid.nr]);
    for k in k0..=k1 {
        for i in 0..grid.nr {
            for j in 0..grid.cells_in_annulus(i) {
                let c = grid.index(i, j, k);
                let w = weights.map_or(1.0, |w| w[c]);
                if w > 0.0 && !values[c].is_nan() {
                    sum[i] += w * values[c];
                    wsum[i] += w;
                }
            }
        }
    }
    let mean = sum.iter().zip(&wsum).map(|(s, w)| if *w > 0.0 { s / w } else { f64::NAN }).collect();
    (mean, wsum)
}

/// A radial profile: annulus centres (i + ½) dr and the annulus means over the layers
/// [z_lo_m, z_hi_m] cover.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RadialProfile {
    pub z_lo_m: f64,
    pub z_hi_m: f64,
    pub r_m: Vec<f64>,
    pub value: Vec<f64>,
    pub weight: Vec<f64>,
}

/// The radial profile of `values` over the layers holding heights `z_lo` … `z_hi` (a single
/// height: z_lo = z_hi, its layer).
pub fn radial_profile(grid: &CylGrid, values: &[f64], weights: Option<&[f64]>, z_lo: f64, z_hi: f64) -> RadialProfile {
    let (k0, k1) = (grid.locate_k(z_lo.min(z_hi)), grid.locate_k(z_lo.max(z_hi)));
    let (value, weight) = annulus_means(grid, values, weights, k0, k1);
    RadialProfile {
        z_lo_m: k0 as f64 * grid.dz,
        z_hi_m: (k1 + 1) as f64 * grid.dz,
        r_m: (0..grid.nr).map(|i| (i as f64 + 0.5) * grid.dr).collect(),
        value,
        weight,
    }
}

/// Azimuthal means on the (r, z) plane, `value[k · nr + i]` at (r_m[i], z_m[k]): for an
/// axisymmetric time average, the axial plane of the paper's Figs 6–7 from every angle at once.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxialMap {
    pub nr: usize,
    pub nz: usize,
    pub r_m: Vec<f64>,
    pub z_m: Vec<f64>,
    pub value: Vec<f64>,
}

impl AxialMap {
    /// The map as a cell field of `grid` (each cell its annulus's value), for the axial-slice picture.
    pub fn cell_field(&self, grid: &CylGrid) -> Vec<f64> {
        (0..grid.num_cells())
            .map(|c| {
                let (i, _, k) = grid.ijk(c);
                self.value[k * self.nr + i]
            })
            .collect()
    }
}

pub fn axial_map(grid: &CylGrid, values: &[f64], weights: Option<&[f64]>) -> AxialMap {
    let value = (0..grid.nz).flat_map(|k| annulus_means(grid, values, weights, k, k).0).collect();
    AxialMap {
        nr: grid.nr,
        nz: grid.nz,
        r_m: (0..grid.nr).map(|i| (i as f64 + 0.5) * grid.dr).collect(),
        z_m: (0..grid.nz).map(|k| (k as f64 + 0.5) * grid.dz).collect(),
        value,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_of_r_and_z_maps_to_itself_and_weights_pick_the_particle_mean() {
        // q = 1 + 2 r_c² + 3 z_c at cell centres, plus an angular ripple sin(θ_c) that averages to
        // zero over each annulus (its cells are equally spaced in angle).
        let g = CylGrid::new(0.02, 0.03, 0.005, 0.005, 3);
        let q: Vec<f64> = (0..g.num_cells())
            .map(|c| {
                let (i, j, k) = g.ijk(c);
                let (r, th) = g.centre_polar(i, j);
                1.0 + 2.0 * r * r + 3.0 * (k as f64 + 0.5) * g.dz + th.sin()
            })
            .collect();
        let m = axial_map(&g, &q, None);
        for k in 0..g.nz {
            for i in 0..g.nr {
                let want = 1.0 + 2.0 * m.r_m[i].powi(2) + 3.0 * m.z_m[k];
                assert!((m.value[k * g.nr + i] - want).abs() < 1e-12, "({i}, {k})");
            }
        }
        // Layers 1–2 (z in [5, 15) mm): the mean of their two z_c, 10 mm.
        let p = radial_profile(&g, &q, None, 0.006, 0.012);
        assert!((p.z_lo_m - 0.005).abs() < 1e-12 && (p.z_hi_m - 0.015).abs() < 1e-12);
        assert!((p.value[1] - (1.0 + 2.0 * 0.0075f64.powi(2) + 0.03)).abs() < 1e-12);
        assert_eq!(p.weight[2], 2.0 * g.cells_in_annulus(2) as f64);
        // Weights: annulus 0 of layer 0 holds cells valued 10, 20, 30 with 1, 0, 3 particles seen:
        // (10 + 90)/4 = 25; an annulus with no weight is NaN.
        let mut v = vec![0.0; g.num_cells()];
        let mut w = vec![0.0; g.num_cells()];
        for (j, (val, wt)) in [(10.0, 1.0), (20.0, 0.0), (30.0, 3.0)].into_iter().enumerate() {
            v[g.index(0, j, 0)] = val;
            w[g.index(0, j, 0)] = wt;
        }
        let p = radial_profile(&g, &v, Some(&w), 0.0, 0.0);
        assert!((p.value[0] - 25.0).abs() < 1e-12);
        assert!(p.value[1].is_nan());
    }
}
