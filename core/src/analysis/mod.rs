//! Pressure drop, time averages, particle-based averages.

use crate::grid::CylGrid;

/// Mean of a cell field over each layer (all cells have one volume, so a plain mean).
pub fn layer_means(grid: &CylGrid, field: &[f64]) -> Vec<f64> {
    let per = grid.cells_per_layer();
    field.chunks(per).map(|l| l.iter().sum::<f64>() / per as f64).collect()
}

/// Total pressure drop from the distributor (z = 0, the bottom layer mean extrapolated linearly
/// from the two lowest layer centres) to the top layer, from layer-mean pressures.
pub fn bed_pressure_drop(layers: &[f64]) -> f64 {
    let bottom = if layers.len() >= 2 { 1.5 * layers[0] - 0.5 * layers[1] } else { layers[0] };
    bottom - layers[layers.len() - 1]
}
