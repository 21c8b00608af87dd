//! Cell-to-cell roughness of a cell field (paper Fig. 3, the direct method's jumps): the mean
//! |Δf| between vertically and angularly adjacent cells of layers 1..k_max (k_max's upper
//! neighbour included), over the mean of f in those layers.

use crate::grid::CylGrid;

pub fn roughness(grid: &CylGrid, f: &[f64], k_max: usize) -> f64 {
    let (mut sum, mut n, mut mean) = (0.0, 0.0, 0.0);
    for k in 1..k_max.min(grid.nz - 1) {
        for i in 0..grid.nr {
            for j in 0..grid.cells_in_annulus(i) {
                let c = grid.index(i, j, k);
                let (_, jn) = grid.angular_neighbours(i, j);
                sum += (f[grid.index(i, j, k + 1)] - f[c]).abs() + (f[grid.index(i, jn, k)] - f[c]).abs();
                n += 2.0;
                mean += f[c];
            }
        }
    }
    (sum / n) / (mean / (n / 2.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_alternating_by_layer_has_half_its_jump_over_its_mean() {
        // f = c ± a alternating from layer to layer, uniform within a layer: every vertical pair
        // differs by 2a, no angular pair differs, so over layers 1..4 (two of each sign, mean c)
        // the roughness is (2a + 0)/2 / c = a/c.
        let g = CylGrid::new(0.022, 0.044, 0.0044, 0.0044, 3);
        let (c, a) = (0.5, 0.05);
        let f: Vec<f64> = (0..g.num_cells())
            .map(|idx| c + if (idx / g.cells_per_layer()).is_multiple_of(2) { a } else { -a })
            .collect();
        let r = roughness(&g, &f, 5);
        assert!((r - a / c).abs() < 1e-12, "{r}");
        let flat = vec![c; g.num_cells()];
        assert_eq!(roughness(&g, &flat, 5), 0.0);
    }
}
