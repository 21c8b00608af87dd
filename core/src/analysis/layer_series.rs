//! Cross-section means per layer over time (voidage or pressure): one row of `nz` layer means per
//! sample, the input of `count_bubbles` and `rise_velocity` at chosen heights.

use super::layers::surface_height;
use crate::grid::CylGrid;
use serde::{Deserialize, Serialize};

/// Layer means of a cell field at each sample, in sample order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LayerSeries {
    nz: usize,
    cells_per_layer: usize,
    dz: f64,
    times_s: Vec<f64>,
    /// Sample-major: row s holds layers 0 … nz − 1.
    rows: Vec<f64>,
}

impl LayerSeries {
    pub fn new(grid: &CylGrid) -> LayerSeries {
        LayerSeries { nz: grid.nz, cells_per_layer: grid.cells_per_layer(), dz: grid.dz, times_s: vec![], rows: vec![] }
    }

    /// The layer means of one cell field taken at time `t_s` (equal cell volumes: plain means).
    pub fn add_sample(&mut self, t_s: f64, field: &[f64]) {
        assert_eq!(field.len(), self.nz * self.cells_per_layer, "LayerSeries: field size");
        self.times_s.push(t_s);
        self.rows.extend(field.chunks(self.cells_per_layer).map(|l| l.iter().sum::<f64>() / l.len() as f64));
    }

    pub fn len(&self) -> usize {
        self.times_s.len()
    }
    pub fn is_empty(&self) -> bool {
        self.times_s.is_empty()
    }
    pub fn times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// Mean sampling step (t_last − t_first)/(n − 1); `None` below two samples.
    pub fn dt(&self) -> Option<f64> {
        let n = self.times_s.len();
        (n >= 2).then(|| (self.times_s[n - 1] - self.times_s[0]) / (n - 1) as f64)
    }

    /// The time series of the layer holding height `z_m` (clamped to the column).
    pub fn at_height(&self, z_m: f64) -> Vec<f64> {
        let k = if z_m <= 0.0 { 0 } else { ((z_m / self.dz) as usize).min(self.nz - 1) };
        self.layer(k)
    }

    /// The time series of layer k.
    pub fn layer(&self, k: usize) -> Vec<f64> {
        assert!(k < self.nz, "LayerSeries: layer {k} of {}", self.nz);
        self.rows.chunks(self.nz).map(|r| r[k]).collect()
    }

    /// The bed surface at each sample: the top (k + 1)·dz of the highest layer whose mean is below
    /// `below` (0 when none is), the instantaneous form of the run analysis's bed height.
    pub fn surface_heights(&self, below: f64) -> Vec<f64> {
        self.rows.chunks(self.nz).map(|r| surface_height(r, below, self.dz).unwrap_or(0.0)).collect()
    }

    /// Centre height (k + ½) dz of layer k.
    pub fn layer_height(&self, k: usize) -> f64 {
        (k as f64 + 0.5) * self.dz
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_layer_keeps_its_own_cross_section_mean_over_time() {
        // Field value k + 10 s + (cell index within the layer): layer mean k + 10 s + (per − 1)/2.
        let g = CylGrid::new(0.01, 0.03, 0.005, 0.01, 2);
        let per = g.cells_per_layer();
        let mut ls = LayerSeries::new(&g);
        for s in 0..5 {
            let f: Vec<f64> =
                (0..g.num_cells()).map(|c| (c / per) as f64 + 10.0 * s as f64 + (c % per) as f64).collect();
            ls.add_sample(0.1 * s as f64, &f);
        }
        assert_eq!(ls.len(), 5);
        assert!((ls.dt().unwrap() - 0.1).abs() < 1e-12);
        let half = (per as f64 - 1.0) / 2.0;
        let want: Vec<f64> = (0..5).map(|s| 1.0 + 10.0 * s as f64 + half).collect();
        assert_eq!(ls.layer(1), want);
        assert_eq!(ls.at_height(0.015), want);
        assert_eq!(ls.at_height(9.0), ls.layer(2));
        assert!((ls.layer_height(2) - 0.025).abs() < 1e-12);
    }

    #[test]
    fn the_surface_is_the_top_of_the_highest_layer_below_the_threshold() {
        // Three layers of 10 mm: dense below, the top one dense at sample 1 only, all gas at 2;
        // a dense layer above a gap (a plug over a slug) sets the surface.
        let g = CylGrid::new(0.01, 0.03, 0.005, 0.01, 2);
        let per = g.cells_per_layer();
        let mut ls = LayerSeries::new(&g);
        for layers in [[0.4, 0.4, 0.95], [0.4, 0.5, 0.6], [1.0, 1.0, 1.0], [0.4, 0.9, 0.5]] {
            let f: Vec<f64> = (0..g.num_cells()).map(|c| layers[c / per]).collect();
            ls.add_sample(0.0, &f);
        }
        let h = ls.surface_heights(0.8);
        let want = [0.02, 0.03, 0.0, 0.03];
        assert!(h.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12), "{h:?}");
    }
}
