//! Face geometry of the equal-volume grid for the finite-volume scheme (paper section 2.2).
//!
//! Every layer has the same horizontal faces, so they are stored once per layer:
//! - angular faces between (i, j) and (i, j+1): planes θ = const, area dr·dz, normal e_θ;
//! - radial faces between (i, j) and each outer neighbour (i+1, jj): the arc segment of r = r_{i+1}
//!   shared by the two cells (the grid's shared-face fractions), whose *vector* area is the exact
//!   integral r·dz·∫e_r dθ over the segment (a chord), so Σ S_f = 0 closes every cell exactly.
//!
//! Axial faces have area A_z = π dr²/n0 and normal ±e_z. The tube wall and the axis (zero area)
//! carry no convective or viscous flux (full slip); see solver.rs for the pressure closure.

use crate::grid::CylGrid;

/// One horizontal face between in-layer cells `a` and `b`; the vector area points from a to b.
#[derive(Clone, Copy, Debug)]
pub struct HFace {
    pub a: u32,
    pub b: u32,
    /// Vector area (x, y) of the face over one layer height, m².
    pub sx: f64,
    pub sy: f64,
    /// Area over distance between the two cell centres, |S|/δ (for the compact viscous term), m.
    pub area_over_delta: f64,
    /// |S| and the centre-to-centre vector d = x_b − x_a (for the pressure dissipation of rhs.rs).
    pub s_abs: f64,
    pub dx: f64,
    pub dy: f64,
    /// |d|, the distance between the two centres.
    pub delta: f64,
}

/// Horizontal neighbour of an in-layer cell with the outward vector area of the shared face.
#[derive(Clone, Copy, Debug)]
pub struct Neighbour {
    pub c: u32,
    pub sx: f64,
    pub sy: f64,
    /// Centre-to-centre vector to the neighbour, x_nb − x_c.
    pub dx: f64,
    pub dy: f64,
}

/// Geometry shared by all layers.
#[derive(Clone, Debug)]
pub struct FaceGeometry {
    pub faces: Vec<HFace>,
    /// cos θ_c and sin θ_c of each in-layer cell centre (the cell's cylindrical basis).
    pub cos_c: Vec<f64>,
    pub sin_c: Vec<f64>,
    /// Axial face area A_z and cell volume V (equal for all cells).
    pub area_z: f64,
    pub volume: f64,
    /// Per in-layer cell: its horizontal neighbours (CSR) with outward vector areas.
    pub nb_start: Vec<usize>,
    pub nb: Vec<Neighbour>,
    /// max over cells of Σ_f (|S_f|/δ_f)/V over all faces (horizontal and axial), 1/m²: the
    /// spectral radius of the compact Laplacian is at most 2× this times the diffusivity.
    pub max_laplacian_factor: f64,
}

impl FaceGeometry {
    pub fn new(g: &CylGrid) -> FaceGeometry {
        let per = g.cells_per_layer();
        let (dr, dz) = (g.dr, g.dz);
        let mut cos_c = vec![0.0; per];
        let mut sin_c = vec![0.0; per];
        let mut centre = vec![(0.0, 0.0); per];
        for i in 0..g.nr {
            for j in 0..g.cells_in_annulus(i) {
                let c = g.layer_index(i, j);
                let (r, th) = g.centre_polar(i, j);
                cos_c[c] = th.cos();
                sin_c[c] = th.sin();
                centre[c] = (r * th.cos(), r * th.sin());
            }
        }
        let dist =
            |a: usize, b: usize| ((centre[a].0 - centre[b].0).powi(2) + (centre[a].1 - centre[b].1).powi(2)).sqrt();
        let mut faces = Vec::new();
        for i in 0..g.nr {
            let n = g.cells_in_annulus(i);
            let w = g.dtheta(i);
            for j in 0..n {
                let a = g.layer_index(i, j);
                // Angular face at θ = (j+1)Δθ, normal e_θ from j to j+1.
                let th = (j + 1) as f64 * w;
                let b = g.layer_index(i, (j + 1) % n);
                let area = dr * dz;
                let (dx, dy) = (centre[b].0 - centre[a].0, centre[b].1 - centre[a].1);
                faces.push(HFace {
                    a: a as u32,
                    b: b as u32,
                    sx: -th.sin() * area,
                    sy: th.cos() * area,
                    area_over_delta: area / dist(a, b),
                    s_abs: area,
                    dx,
                    dy,
                    delta: dx.hypot(dy),
                });
                // Radial segments shared with the outer annulus.
                if i + 1 < g.nr {
                    let r = (i + 1) as f64 * dr;
                    let w2 = g.dtheta(i + 1);
                    for l in g.outer_neighbours(i, j) {
                        let b = g.layer_index(i + 1, l.j);
                        let t0 = (j as f64 * w).max(l.j as f64 * w2);
                        let t1 = ((j + 1) as f64 * w).min((l.j + 1) as f64 * w2);
                        // Exact vector area r·dz·∫ e_r dθ over [t0, t1].
                        let (sx, sy) = (r * dz * (t1.sin() - t0.sin()), r * dz * (t0.cos() - t1.cos()));
                        let arc = r * dz * (t1 - t0);
                        let (dx, dy) = (centre[b].0 - centre[a].0, centre[b].1 - centre[a].1);
                        faces.push(HFace {
                            a: a as u32,
                            b: b as u32,
                            sx,
                            sy,
                            area_over_delta: arc / dist(a, b),
                            s_abs: sx.hypot(sy),
                            dx,
                            dy,
                            delta: dx.hypot(dy),
                        });
                    }
                }
            }
        }
        let mut lists: Vec<Vec<Neighbour>> = vec![Vec::new(); per];
        let mut lap = vec![0.0; per];
        for f in &faces {
            lists[f.a as usize].push(Neighbour { c: f.b, sx: f.sx, sy: f.sy, dx: f.dx, dy: f.dy });
            lists[f.b as usize].push(Neighbour { c: f.a, sx: -f.sx, sy: -f.sy, dx: -f.dx, dy: -f.dy });
            lap[f.a as usize] += f.area_over_delta;
            lap[f.b as usize] += f.area_over_delta;
        }
        let area_z = g.cell_area();
        let volume = g.cell_volume();
        let max_lap = lap.iter().fold(0.0f64, |m, &x| m.max(x)) + 2.0 * area_z / dz;
        let mut nb_start = vec![0];
        let mut nb = Vec::new();
        for l in lists {
            nb.extend(l);
            nb_start.push(nb.len());
        }
        FaceGeometry { faces, cos_c, sin_c, area_z, volume, nb_start, nb, max_laplacian_factor: max_lap / volume }
    }

    /// Horizontal neighbours of in-layer cell c with outward vector areas.
    #[inline]
    pub fn neighbours(&self, c: usize) -> &[Neighbour] {
        &self.nb[self.nb_start[c]..self.nb_start[c + 1]]
    }

    /// Cartesian (x, y) of cylindrical (r, θ) components in the basis of in-layer cell c.
    #[inline]
    pub fn to_cartesian(&self, c: usize, vr: f64, vt: f64) -> (f64, f64) {
        let (co, si) = (self.cos_c[c], self.sin_c[c]);
        (vr * co - vt * si, vr * si + vt * co)
    }

    /// Cylindrical (r, θ) of Cartesian (x, y) components in the basis of in-layer cell c.
    #[inline]
    pub fn to_cylindrical(&self, c: usize, vx: f64, vy: f64) -> (f64, f64) {
        let (co, si) = (self.cos_c[c], self.sin_c[c]);
        (vx * co + vy * si, -vx * si + vy * co)
    }
}

/// ½ Σ_f |S_f| / V over the horizontal faces of any cell of the equal-volume grid, including the
/// wall: [(2i+1) dr Δθ_i + 2 dr]·dz / (π dr² dz / n0) / 2 = (1 + n0/π)/dr, the same in every annulus.
/// With 1/dz for the axial faces it bounds the spectral radius of the central acoustic operator.
pub fn horizontal_inverse_spacing(dr: f64, n0: usize) -> f64 {
    (1.0 + n0 as f64 / std::f64::consts::PI) / dr
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vector_areas_close_every_cell_so_a_uniform_field_has_zero_divergence() {
        // Σ_f S_f = 0 over each cell's faces (tube-wall face added analytically): the discrete
        // divergence of any uniform vector field vanishes in every cell.
        let g = CylGrid::new(0.022, 0.0088, 0.0044, 0.0044, 3);
        let geo = FaceGeometry::new(&g);
        let u = (0.37, -1.3);
        for i in 0..g.nr {
            for j in 0..g.cells_in_annulus(i) {
                let c = g.layer_index(i, j);
                let (mut sx, mut sy) = (0.0, 0.0);
                for n in geo.neighbours(c) {
                    sx += n.sx;
                    sy += n.sy;
                }
                if i + 1 == g.nr {
                    let (t0, t1) = g.theta_bounds(i, j);
                    sx += g.radius * g.dz * (t1.sin() - t0.sin());
                    sy += g.radius * g.dz * (t0.cos() - t1.cos());
                }
                let div = (u.0 * sx + u.1 * sy) / geo.volume;
                assert!(div.abs() < 1e-12, "cell ({i},{j}): divergence {div}");
            }
        }
    }

    #[test]
    fn face_segments_have_the_shared_fraction_of_the_arc() {
        // The arc areas of a cell's outer segments add up to its whole outer face r_{i+1}Δθ_i dz.
        let g = CylGrid::new(0.022, 0.0044, 0.0044, 0.0044, 3);
        let geo = FaceGeometry::new(&g);
        for i in 0..g.nr - 1 {
            for j in 0..g.cells_in_annulus(i) {
                let c = g.layer_index(i, j) as u32;
                let chord: f64 = geo
                    .faces
                    .iter()
                    .filter(|f| f.a == c && g.ijk(f.b as usize).0 == i + 1)
                    .map(|f| f.sx.hypot(f.sy))
                    .sum();
                let r = (i + 1) as f64 * g.dr;
                let whole = 2.0 * r * g.dz * (g.dtheta(i) / 2.0).sin();
                // Chords of the parts are at least the chord of the whole, at most the arc.
                assert!(chord >= whole * (1.0 - 1e-14) && chord <= r * g.dz * g.dtheta(i) * (1.0 + 1e-14));
            }
        }
    }

    #[test]
    fn inverse_spacing_formula_matches_the_cell_faces() {
        let g = CylGrid::new(0.022, 0.0044, 0.0044, 0.0044, 3);
        let geo = FaceGeometry::new(&g);
        for c in 0..g.cells_per_layer() {
            let (i, _, _) = g.ijk(c);
            let mut s: f64 = 0.0;
            // Arc areas: inner + outer arcs and two angular faces.
            let (r0, r1) = (i as f64 * g.dr, (i + 1) as f64 * g.dr);
            s += (r0 + r1) * g.dtheta(i) * g.dz + 2.0 * g.dr * g.dz;
            let want = horizontal_inverse_spacing(g.dr, g.n0);
            assert!((0.5 * s / geo.volume - want).abs() < 1e-9 * want);
        }
    }
}
