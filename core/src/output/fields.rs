//! Fields derived from a snapshot for output: voidage even when only particles were stored,
//! mean particle height for DEM-only traces, Cartesian gas velocity.

use crate::sim::snapshot::Snapshot;

/// The snapshot's voidage; when only particles were stored, the direct method (paper eq. 2:
/// each particle's whole volume in the cell of its centre, ε = 1 − ΣV_p / V_cell).
pub fn voidage(s: &Snapshot) -> Option<Vec<f64>> {
    if let Some(v) = &s.voidage {
        return Some(v.clone());
    }
    let p = s.particles.as_ref()?;
    let grid = s.grid.grid();
    let vp = 4.0 / 3.0 * std::f64::consts::PI * p.radius_m.powi(3);
    let vc = grid.cell_volume();
    let mut eps = vec![1.0; grid.num_cells()];
    for x in &p.positions_m {
        if x[2] >= 0.0 && x[2] < grid.height {
            eps[grid.locate(x[0], x[1], x[2])] -= vp / vc;
        }
    }
    Some(eps)
}

/// Mean height of the particle centres (a bed-height proxy for runs without gas).
pub fn mean_particle_height_m(s: &Snapshot) -> Option<f64> {
    let p = s.particles.as_ref()?;
    if p.positions_m.is_empty() {
        return None;
    }
    Some(p.positions_m.iter().map(|x| x[2]).sum::<f64>() / p.positions_m.len() as f64)
}

/// Gas velocity of each cell turned from cylindrical (U_r, U_θ, U_z) to Cartesian at the cell's mid angle.
pub fn gas_velocity_cartesian(s: &Snapshot) -> Option<Vec<[f64; 3]>> {
    let u = s.gas_velocity_m_s.as_ref()?;
    let grid = s.grid.grid();
    Some(
        u.iter()
            .enumerate()
            .map(|(idx, v)| {
                let (i, j, _) = grid.ijk(idx);
                let (_, th) = grid.centre_polar(i, j);
                let (c, sn) = (th.cos(), th.sin());
                [v[0] * c - v[1] * sn, v[0] * sn + v[1] * c, v[2]]
            })
            .collect(),
    )
}
