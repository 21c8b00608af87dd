//! The equal-volume cylindrical fluid grid (paper section 2.2, Fig. 1).
//!
//! Constant radial spacing dr over N_r annuli and constant dz over N_z layers. Annulus i holds
//! n_i = n0·(2i+1) cells, so every cell has the horizontal area π dr²/n0 and the same volume.
//! Cells are numbered layer by layer: index = k·cells_per_layer + n0·i² + j.

#[cfg(test)]
mod tests;

use std::f64::consts::PI;

/// One radial neighbour across an annulus boundary: its angular index in the adjacent annulus
/// and the fraction of *this* cell's radial face that it shares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialLink {
    pub j: usize,
    pub fraction: f64,
}

#[derive(Clone, Debug)]
pub struct CylGrid {
    pub radius: f64,
    pub height: f64,
    pub dr: f64,
    pub dz: f64,
    pub n0: usize,
    pub nr: usize,
    pub nz: usize,
    /// First in-layer index of annulus i: n0·i².
    offset: Vec<usize>,
    /// For in-layer cell c: its neighbours in annulus i+1 (outer) and i-1 (inner), CSR.
    outer_start: Vec<usize>,
    outer: Vec<RadialLink>,
    inner_start: Vec<usize>,
    inner: Vec<RadialLink>,
    /// Per in-layer cell, the bounds `locate_near` tests a hint against.
    sectors: Vec<Sector>,
}

/// Bounds of one in-layer cell, shrunk by a margin (`Sector::MARGIN`) far above the rounding
/// of `locate`: r² strictly between `r2_lo` and `r2_hi`, and the point on the inner side of
/// both edge directions `lo` and `hi` (unit vectors at θ_j and θ_{j+1}).
#[derive(Clone, Copy, Debug)]
struct Sector {
    r2_lo: f64,
    r2_hi: f64,
    lo: (f64, f64),
    hi: (f64, f64),
    /// Sectors of half a turn or more are never tested (the edge test needs less).
    usable: bool,
}

impl Sector {
    /// Relative margin in r and angle (radians): 1e-9, against ~1e-15 of rounding in `locate`.
    const MARGIN: f64 = 1e-9;
}

impl CylGrid {
    /// Build the grid for a column of `radius` and `height`; `dr` and `dz` are rounded to whole
    /// annuli and layers (case validation refuses spacings that are not).
    pub fn new(radius: f64, height: f64, dr: f64, dz: f64, n0: usize) -> CylGrid {
        assert!(n0 >= 1 && dr > 0.0 && dz > 0.0);
        let nr = ((radius / dr).round() as usize).max(1);
        let nz = ((height / dz).round() as usize).max(1);
        let (dr, dz) = (radius / nr as f64, height / nz as f64);
        let offset: Vec<usize> = (0..=nr).map(|i| n0 * i * i).collect();
        let mut g = CylGrid {
            radius,
            height,
            dr,
            dz,
            n0,
            nr,
            nz,
            offset,
            outer_start: vec![0],
            outer: vec![],
            inner_start: vec![0],
            inner: vec![],
            sectors: vec![],
        };
        for i in 0..nr {
            for j in 0..g.cells_in_annulus(i) {
                if i + 1 < nr {
                    g.outer.extend(Self::overlaps(g.cells_in_annulus(i), j, g.cells_in_annulus(i + 1)));
                }
                g.outer_start.push(g.outer.len());
                if i > 0 {
                    g.inner.extend(Self::overlaps(g.cells_in_annulus(i), j, g.cells_in_annulus(i - 1)));
                }
                g.inner_start.push(g.inner.len());
                g.sectors.push(g.sector(i, j));
            }
        }
        g
    }

    fn sector(&self, i: usize, j: usize) -> Sector {
        let m = Sector::MARGIN;
        let (r0, r1) = (i as f64 * self.dr * (1.0 + m), (i + 1) as f64 * self.dr * (1.0 - m));
        // The outer annulus also holds points beyond the wall (`locate_ij`).
        let r2_hi = if i + 1 == self.nr { f64::INFINITY } else { r1 * r1 };
        let (t0, t1) = self.theta_bounds(i, j);
        let usable = self.cells_in_annulus(i) >= 3;
        Sector { r2_lo: r0 * r0, r2_hi, lo: (t0.cos(), t0.sin()), hi: (t1.cos(), t1.sin()), usable }
    }

    /// Cells of an annulus with `m` cells that overlap cell j of an annulus with `n` cells, with the
    /// overlap as a fraction of cell j's angular width. Integer arithmetic on the common
    /// subdivision n·m, so the fractions sum to exactly 1.
    fn overlaps(n: usize, j: usize, m: usize) -> Vec<RadialLink> {
        let (a0, a1) = (j * m, (j + 1) * m);
        let mut out = Vec::new();
        for jj in (a0 / n)..=((a1 - 1) / n).min(m - 1) {
            let (b0, b1) = (jj * n, (jj + 1) * n);
            let ov = a1.min(b1).saturating_sub(a0.max(b0));
            if ov > 0 {
                out.push(RadialLink { j: jj, fraction: ov as f64 / m as f64 });
            }
        }
        out
    }

    pub fn cells_in_annulus(&self, i: usize) -> usize {
        self.n0 * (2 * i + 1)
    }
    pub fn cells_per_layer(&self) -> usize {
        self.offset[self.nr]
    }
    pub fn num_cells(&self) -> usize {
        self.cells_per_layer() * self.nz
    }
    /// Horizontal area of every cell: π dr² / n0.
    pub fn cell_area(&self) -> f64 {
        PI * self.dr * self.dr / self.n0 as f64
    }
    /// Volume of every cell.
    pub fn cell_volume(&self) -> f64 {
        self.cell_area() * self.dz
    }
    /// Exact volume of cell (i, j, k) from its bounds: ½Δθ(r₁² − r₀²)·dz (for the equal-volume test).
    pub fn cell_volume_from_bounds(&self, i: usize) -> f64 {
        let (r0, r1) = (i as f64 * self.dr, (i + 1) as f64 * self.dr);
        0.5 * self.dtheta(i) * (r1 * r1 - r0 * r0) * self.dz
    }
    /// Angular width of a cell in annulus i.
    pub fn dtheta(&self, i: usize) -> f64 {
        2.0 * PI / self.cells_in_annulus(i) as f64
    }
    /// Index of cell (i, j, k).
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        k * self.cells_per_layer() + self.offset[i] + j
    }
    /// In-layer index of (i, j).
    #[inline]
    pub fn layer_index(&self, i: usize, j: usize) -> usize {
        self.offset[i] + j
    }
    /// (i, j, k) of a cell index.
    pub fn ijk(&self, idx: usize) -> (usize, usize, usize) {
        let per = self.cells_per_layer();
        let (k, c) = (idx / per, idx % per);
        let i = ((c / self.n0) as f64).sqrt() as usize;
        // Guard the float square root at annulus boundaries.
        let i = if self.offset[i + 1] <= c {
            i + 1
        } else if self.offset[i] > c {
            i - 1
        } else {
            i
        };
        (i, c - self.offset[i], k)
    }
    /// (i, j) of the column through a horizontal point; O(1). Points beyond the wall map to the
    /// outer annulus.
    #[inline]
    pub fn locate_ij(&self, x: f64, y: f64) -> (usize, usize) {
        let r = (x * x + y * y).sqrt();
        let i = ((r / self.dr) as usize).min(self.nr - 1);
        let mut th = y.atan2(x);
        if th < 0.0 {
            th += 2.0 * PI;
        }
        let n = self.cells_in_annulus(i);
        let j = ((th / (2.0 * PI) * n as f64) as usize).min(n - 1);
        (i, j)
    }
    /// Layer of height z, clamped to the column.
    #[inline]
    pub fn locate_k(&self, z: f64) -> usize {
        if z <= 0.0 {
            0
        } else {
            ((z / self.dz) as usize).min(self.nz - 1)
        }
    }
    /// Index of the cell holding point (x, y, z); O(1).
    #[inline]
    pub fn locate(&self, x: f64, y: f64, z: f64) -> usize {
        let (i, j) = self.locate_ij(x, y);
        self.index(i, j, self.locate_k(z))
    }
    /// The cell holding (x, y, z), exactly as `locate`, trying the cell `hint` first (say, the
    /// one the point was in before): when the point is inside the hint's bounds by the margin
    /// (`Sector::MARGIN`, far above `locate`'s rounding), the hint is the answer and the square
    /// root and atan2 are skipped; otherwise `locate` decides.
    #[inline]
    pub fn locate_near(&self, x: f64, y: f64, z: f64, hint: usize) -> usize {
        if self.hint_holds(x, y, z, hint) {
            hint
        } else {
            self.locate(x, y, z)
        }
    }
    /// (x, y, z) is inside cell `hint` by the margin of `locate_near` (its layer as `locate`).
    #[inline]
    pub(crate) fn hint_holds(&self, x: f64, y: f64, z: f64, hint: usize) -> bool {
        let per = self.cells_per_layer();
        let c = hint.wrapping_sub(self.locate_k(z) * per);
        if c >= per {
            return false;
        }
        let s = &self.sectors[c];
        let r2 = x * x + y * y;
        // r × sin of the angle from each edge, positive inside.
        let (a, b) = (s.lo.0 * y - s.lo.1 * x, x * s.hi.1 - y * s.hi.0);
        let tol2 = Sector::MARGIN * Sector::MARGIN * r2;
        s.usable && r2 > s.r2_lo && r2 < s.r2_hi && a > 0.0 && b > 0.0 && a * a > tol2 && b * b > tol2
    }
    /// Angular neighbours (j-1, j+1) of (i, j), periodic.
    pub fn angular_neighbours(&self, i: usize, j: usize) -> (usize, usize) {
        let n = self.cells_in_annulus(i);
        ((j + n - 1) % n, (j + 1) % n)
    }
    /// Neighbours of (i, j) in annulus i+1 with the fraction of (i, j)'s outer face each shares.
    pub fn outer_neighbours(&self, i: usize, j: usize) -> &[RadialLink] {
        let c = self.layer_index(i, j);
        &self.outer[self.outer_start[c]..self.outer_start[c + 1]]
    }
    /// Neighbours of (i, j) in annulus i-1 with the fraction of (i, j)'s inner face each shares.
    pub fn inner_neighbours(&self, i: usize, j: usize) -> &[RadialLink] {
        let c = self.layer_index(i, j);
        &self.inner[self.inner_start[c]..self.inner_start[c + 1]]
    }
    /// Angular bounds [θ0, θ1) of cell (i, j).
    pub fn theta_bounds(&self, i: usize, j: usize) -> (f64, f64) {
        let w = self.dtheta(i);
        (j as f64 * w, (j + 1) as f64 * w)
    }
    /// Radius of the cell centre (i + ½)·dr and its mid angle.
    pub fn centre_polar(&self, i: usize, j: usize) -> (f64, f64) {
        ((i as f64 + 0.5) * self.dr, (j as f64 + 0.5) * self.dtheta(i))
    }
    /// Cartesian centre of cell idx (at mid radius, mid angle, mid layer).
    pub fn centre_xyz(&self, idx: usize) -> [f64; 3] {
        let (i, j, k) = self.ijk(idx);
        let (r, th) = self.centre_polar(i, j);
        [r * th.cos(), r * th.sin(), (k as f64 + 0.5) * self.dz]
    }
}
