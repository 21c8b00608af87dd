//! Layer means of a cell field, and the bed pressure drop from them.

use crate::grid::CylGrid;

/// Mean of a cell field over each layer (all cells have one volume, so a plain mean).
pub fn layer_means(grid: &CylGrid, field: &[f64]) -> Vec<f64> {
    let per = grid.cells_per_layer();
    field.chunks(per).map(|l| l.iter().sum::<f64>() / per as f64).collect()
}

/// The bed surface from layer means of the voidage: the top (k + 1)·dz of the highest layer whose
/// mean is below `below`; `None` when none is.
pub fn surface_height(layers: &[f64], below: f64, dz: f64) -> Option<f64> {
    layers.iter().rposition(|&e| e < below).map(|k| (k + 1) as f64 * dz)
}

/// Total pressure drop from the distributor (z = 0) to the top of the column, from layer-mean
/// pressures L_k (centres at (k + ½)dz). The plate pressure is extrapolated as
/// p(0) = (L0 + L1)/2 + (L0 − L2)/2, exact for a linear profile and blind to an odd–even ripple
/// (±A on alternate layers cancels in both terms); the top is the mean of the last two layers.
pub fn bed_pressure_drop(layers: &[f64]) -> f64 {
    let n = layers.len();
    let bottom = match n {
        0 => return 0.0,
        1 | 2 => layers[0],
        _ => 0.5 * (layers[0] + layers[1]) + 0.5 * (layers[0] - layers[2]),
    };
    let top = if n >= 2 { 0.5 * (layers[n - 1] + layers[n - 2]) } else { layers[0] };
    bottom - top
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pressure_drop_is_exact_for_a_linear_profile_and_ignores_an_odd_even_ripple() {
        // p(z) = 1000 − 50 z/dz: the plate is at 1000, the top layers' mean at z = (n − 1) dz
        let n = 12;
        let lin: Vec<f64> = (0..n).map(|k| 1000.0 - 50.0 * (k as f64 + 0.5)).collect();
        let want = 1000.0 - (1000.0 - 50.0 * (n as f64 - 1.0));
        assert!((bed_pressure_drop(&lin) - want).abs() < 1e-9);
        let rippled: Vec<f64> = lin.iter().enumerate().map(|(k, p)| p + if k % 2 == 0 { 7.0 } else { -7.0 }).collect();
        assert!((bed_pressure_drop(&rippled) - want).abs() < 1e-9);
    }
}
