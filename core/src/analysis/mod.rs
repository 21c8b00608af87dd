//! Pressure drop, time averages, particle-based averages.

use crate::grid::CylGrid;

/// Mean of a cell field over each layer (all cells have one volume, so a plain mean).
pub fn layer_means(grid: &CylGrid, field: &[f64]) -> Vec<f64> {
    let per = grid.cells_per_layer();
    field.chunks(per).map(|l| l.iter().sum::<f64>() / per as f64).collect()
}
