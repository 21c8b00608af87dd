//! Bubble volume fraction by height: the fraction of a layer's cells whose voidage is above a
//! threshold (0.8 by default, a common bubble boundary for ε_mf ≈ 0.4), averaged over samples.
//! All cells of the grid have one volume, so a fraction of cells is a fraction of volume.

use crate::grid::CylGrid;
use serde::{Deserialize, Serialize};

/// The usual bubble threshold on the cell voidage.
pub const DEFAULT_BUBBLE_VOIDAGE: f64 = 0.8;

/// A value per layer, with the layer-centre heights (k + ½) dz.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ByHeight {
    pub z_m: Vec<f64>,
    pub value: Vec<f64>,
    pub samples: u64,
}

/// Accumulates, per layer, how many cells were above the threshold over all samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BubbleFraction {
    pub threshold: f64,
    cells_per_layer: usize,
    dz: f64,
    above: Vec<u64>,
    samples: u64,
}

impl BubbleFraction {
    pub fn new(grid: &CylGrid, threshold: f64) -> BubbleFraction {
        BubbleFraction {
            threshold,
            cells_per_layer: grid.cells_per_layer(),
            dz: grid.dz,
            above: vec![0; grid.nz],
            samples: 0,
        }
    }

    /// One voidage field (one value per cell, the grid's order). Panics on a field of another grid.
    pub fn add_sample(&mut self, voidage: &[f64]) {
        assert_eq!(voidage.len(), self.cells_per_layer * self.above.len(), "BubbleFraction: field size");
        for (a, layer) in self.above.iter_mut().zip(voidage.chunks(self.cells_per_layer)) {
            *a += layer.iter().filter(|&&e| e > self.threshold).count() as u64;
        }
        self.samples += 1;
    }

    /// Time-averaged bubble fraction per layer (zeros before any sample).
    pub fn finish(&self) -> ByHeight {
        let denom = (self.samples * self.cells_per_layer as u64).max(1) as f64;
        ByHeight {
            z_m: (0..self.above.len()).map(|k| (k as f64 + 0.5) * self.dz).collect(),
            value: self.above.iter().map(|&a| a as f64 / denom).collect(),
            samples: self.samples,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::test_signals::Noise;

    #[test]
    fn random_bubble_cells_average_to_their_probability_in_each_layer() {
        // Layer k is bubble with probability b_k = 0.1 + 0.05 k in every cell and sample; the
        // mean of 4000 samples × 192 cells is within 4 standard errors of b_k.
        let g = CylGrid::new(0.02, 0.04, 0.0025, 0.005, 3);
        let per = g.cells_per_layer();
        let mut bf = BubbleFraction::new(&g, DEFAULT_BUBBLE_VOIDAGE);
        let mut noise = Noise::new(4);
        let b = |k: usize| 0.1 + 0.05 * k as f64;
        for _ in 0..4000 {
            let field: Vec<f64> =
                (0..g.num_cells()).map(|c| if noise.uniform() < b(c / per) { 0.95 } else { 0.42 }).collect();
            bf.add_sample(&field);
        }
        let out = bf.finish();
        assert_eq!(out.samples, 4000);
        for (k, (&z, &f)) in out.z_m.iter().zip(&out.value).enumerate() {
            assert!((z - (k as f64 + 0.5) * 0.005).abs() < 1e-12);
            let se = (b(k) * (1.0 - b(k)) / (4000.0 * per as f64)).sqrt();
            assert!((f - b(k)).abs() < 4.0 * se, "layer {k}: {f} vs {}", b(k));
        }
    }

    #[test]
    fn the_threshold_is_strict_and_round_trips_through_serde() {
        let g = CylGrid::new(0.01, 0.02, 0.005, 0.01, 1);
        let mut bf = BubbleFraction::new(&g, 0.8);
        // Per layer 4 cells: layer 0 has one above 0.8 and one exactly at it (not counted).
        bf.add_sample(&[0.81, 0.8, 0.4, 0.4, 0.9, 0.9, 0.9, 0.1]);
        let back: BubbleFraction = serde_json::from_str(&serde_json::to_string(&bf).unwrap()).unwrap();
        assert_eq!(back, bf);
        assert_eq!(back.finish().value, vec![0.25, 0.75]);
    }
}
