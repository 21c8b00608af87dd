//! The set-up of the paper's Table 3 / Fig. 5 (section 3.2): 26 particles of d = 1.2 mm wholly
//! inside one cell of the 44-mm grid with dr = dz = 4.4 mm, n0 = 3.
//!
//! Cell "1" is (i = 2, j = 1, k = 1): annulus 2 has 15 cells of 24°, so cell 1 spans 24°–48°. Its
//! radial neighbours reproduce the paper's grouping column exactly: inner annulus (9 cells of 40°)
//! cells j = 0 and j = 1 hold 16° and 8° of their 40° outer faces against cell 1 (weights 0.4 and
//! 0.2 → paper cells 4 and 5: 1 − 0.4·V_s/7V and 1 − 0.2·V_s/7V, the paper's 0.982 and 0.991);
//! outer annulus (21 cells of 17.14°) cells j = 1 and 2 share 0.6 and 0.8 of their inner faces
//! (paper cells 6 and 7: 0.974 and 0.965). Cells 2 and 3 are the angular neighbours j = 0 and 2,
//! cells 8 and 9 the cells below (k = 0) and above (k = 2).

use crate::grid::CylGrid;
use rand::{Rng, SeedableRng};

pub const DIAMETER: f64 = 1.2e-3;
pub const COUNT: usize = 26;
/// The paper's Table 3 values, rows = cells 1..9, columns = direct, grouping, square grid with
/// cuboid config. 1, 2, 3, square grid exact config. 1, 2, 3.
pub const PAPER: [[f64; 8]; 9] = [
    [0.692, 0.956, 0.907, 0.796, 0.755, 0.907, 0.795, 0.752],
    [1.0, 0.956, 0.949, 0.966, 0.971, 0.949, 0.966, 0.972],
    [1.0, 0.956, 0.940, 0.962, 0.978, 0.938, 0.961, 0.977],
    [1.0, 0.982, 0.995, 0.997, 0.999, 0.998, 0.998, 0.999],
    [1.0, 0.991, 0.981, 0.991, 0.996, 0.981, 0.991, 0.997],
    [1.0, 0.974, 0.982, 0.990, 0.998, 0.982, 0.991, 0.998],
    [1.0, 0.965, 0.947, 0.992, 0.995, 0.948, 0.993, 0.997],
    [1.0, 0.956, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
    [1.0, 0.956, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
];
/// Square-grid box sides of configurations 1, 2, 3 (dr, dr/2, 1.375 mm).
pub const BOX_SIDES: [f64; 3] = [4.4e-3, 2.2e-3, 1.375e-3];

/// The grid: R = 22 mm, dr = dz = 4.4 mm, n0 = 3, three layers.
pub fn grid() -> CylGrid {
    CylGrid::new(0.022, 3.0 * 4.4e-3, 4.4e-3, 4.4e-3, 3)
}

/// Indices of the paper's cells 1..9 (see the module comment).
pub fn cells(g: &CylGrid) -> [usize; 9] {
    let (i, j, k) = (2, 1, 1);
    [
        g.index(i, j, k),
        g.index(i, 0, k),
        g.index(i, 2, k),
        g.index(i - 1, 0, k),
        g.index(i - 1, 1, k),
        g.index(i + 1, 1, k),
        g.index(i + 1, 2, k),
        g.index(i, j, k - 1),
        g.index(i, j, k + 1),
    ]
}

/// `COUNT` random non-overlapping spheres of `DIAMETER` wholly inside cell 1 (seeded): random
/// centres in the cell, then overlaps pushed apart and centres projected back inside until no
/// pair overlaps (random sequential addition jams before 26 spheres fit in this cell).
pub fn particles(g: &CylGrid, seed: u64) -> Vec<[f64; 3]> {
    let (i, j, k) = (2usize, 1usize, 1usize);
    // a hair more than the radius, so round-off never lets a sphere touch a face
    let a = DIAMETER / 2.0 * (1.0 + 1e-6);
    let (r0, r1) = (i as f64 * g.dr + a, (i + 1) as f64 * g.dr - a);
    let (t0, t1) = g.theta_bounds(i, j);
    let (z0, z1) = (k as f64 * g.dz + a, (k + 1) as f64 * g.dz - a);
    // the two ray planes as unit normals pointing into the cell
    let n0 = [-t0.sin(), t0.cos()];
    let n1 = [t1.sin(), -t1.cos()];
    let project = |p: &mut [f64; 3]| {
        for _ in 0..8 {
            for n in [n0, n1] {
                let dist = n[0] * p[0] + n[1] * p[1];
                if dist < a {
                    p[0] += (a - dist) * n[0];
                    p[1] += (a - dist) * n[1];
                }
            }
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
            let rc = r.clamp(r0, r1);
            p[0] *= rc / r;
            p[1] *= rc / r;
        }
        p[2] = p[2].clamp(z0, z1);
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut out: Vec<[f64; 3]> = (0..COUNT)
        .map(|_| {
            let r = rng.gen_range(r0 * r0..r1 * r1).sqrt();
            let t = rng.gen_range(t0..t1);
            let mut p = [r * t.cos(), r * t.sin(), rng.gen_range(z0..z1)];
            project(&mut p);
            p
        })
        .collect();
    let gap = DIAMETER * (1.0 + 1e-9);
    for _sweep in 0..100_000 {
        let mut overlap = false;
        for m in 0..COUNT {
            for n in m + 1..COUNT {
                let d: Vec<f64> = (0..3).map(|q| out[n][q] - out[m][q]).collect();
                let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if dist < DIAMETER {
                    overlap = true;
                    let push = 0.5 * (gap * 1.01 - dist) / dist.max(1e-12);
                    for q in 0..3 {
                        out[m][q] -= push * d[q];
                        out[n][q] += push * d[q];
                    }
                    project(&mut out[m]);
                    project(&mut out[n]);
                }
            }
        }
        if !overlap {
            return out;
        }
    }
    panic!("could not separate {COUNT} particles");
}
