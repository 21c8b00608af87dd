//! Wall contacts (distributor plate z = 0, tube of radius R_t, optional lid z = H) with the
//! particle-wall contact law (PHYSICS.md 2; paper section 2.1). Only particles that can reach a
//! wall before the next list rebuild are checked: the wall list holds every particle within one
//! skin of a wall at the last rebuild (a rebuild comes before anything moves half a skin), with
//! the tangential histories of its three walls.

use super::contact::{contact_force, ContactLaw, V3};
use super::DemParams;
use serde::{Deserialize, Serialize};

/// Particles near a wall (ascending index) and their wall histories (plate, tube, lid).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct WallList {
    pub idx: Vec<u32>,
    pub hist: Vec<[V3; 3]>,
}

impl WallList {
    /// Particles of `x` within one skin of a wall, histories carried from `old` (whose particle
    /// `order[i]` is particle i now), zero for particles new to the list.
    pub fn build(p: &DemParams, x: &[V3], old: &WallList, order: Option<&[u32]>) -> WallList {
        let (r, s) = (p.radius, p.skin);
        let reach = p.tube_radius - r - s;
        let near = |q: &V3| {
            let rho2 = q[0] * q[0] + q[1] * q[1];
            q[2] < r + s || reach <= 0.0 || rho2 > reach * reach || (p.lid && q[2] > p.height - r - s)
        };
        // Old histories by old particle index.
        let mut old_at = std::collections::HashMap::new();
        for (&i, h) in old.idx.iter().zip(&old.hist) {
            if *h != [[0.0; 3]; 3] {
                old_at.insert(i, *h);
            }
        }
        let mut out = WallList::default();
        for (i, q) in x.iter().enumerate() {
            let before = order.map_or(i as u32, |o| o[i]);
            let h = old_at.get(&before).copied().unwrap_or([[0.0; 3]; 3]);
            if near(q) || h != [[0.0; 3]; 3] {
                out.idx.push(i as u32);
                out.hist.push(h);
            }
        }
        out
    }

    /// Entries [k0, k1) of the list with particle index in [lo, hi).
    pub fn range(&self, lo: usize, hi: usize) -> (usize, usize) {
        (self.idx.partition_point(|&i| (i as usize) < lo), self.idx.partition_point(|&i| (i as usize) < hi))
    }
}

/// One wall contact: overlap `delta` along the outward normal `nrm`; adds force and n × F_t.
/// Returns (overlap, Coulomb excess) for the diagnostics.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn wall_contact<const FR: bool>(
    law: &ContactLaw, r: f64, h: f64, delta: f64, nrm: V3, vi: V3, wi: V3, hist: &mut V3, acc: &mut [f64; 6],
) -> (f64, f64) {
    if delta <= 0.0 {
        *hist = [0.0; 3];
        return (0.0, f64::NEG_INFINITY);
    }
    let ws = [r * wi[0], r * wi[1], r * wi[2]];
    let cf = contact_force::<FR>(law, delta, nrm, vi, ws, hist, h);
    for k in 0..3 {
        acc[k] += cf.f[k];
        acc[3 + k] += cf.c[k];
    }
    (delta, if FR { cf.excess } else { f64::NEG_INFINITY })
}

/// All wall forces on a particle at `xi` (force and n × F_t summed into `acc`); returns the
/// largest overlap and Coulomb excess.
#[inline]
pub fn wall_forces<const FR: bool>(p: &DemParams, xi: V3, vi: V3, wi: V3, hist: &mut [V3; 3], acc: &mut [f64; 6]) -> (f64, f64) {
    let (law, r, h) = (&p.wall, p.radius, p.dt);
    let [h0, h1, h2] = hist;
    // Distributor plate z = 0: normal (0,0,−1).
    let (mut ov, mut ex) = wall_contact::<FR>(law, r, h, r - xi[2], [0.0, 0.0, -1.0], vi, wi, h0, acc);
    // Tube of radius R_t: outward radial normal.
    let rho2 = xi[0] * xi[0] + xi[1] * xi[1];
    let reach = p.tube_radius - r;
    if rho2 > reach * reach {
        let rho = rho2.sqrt();
        let nrm = [xi[0] / rho, xi[1] / rho, 0.0];
        let (o, e) = wall_contact::<FR>(law, r, h, rho - reach, nrm, vi, wi, h1, acc);
        (ov, ex) = (ov.max(o), ex.max(e));
    } else {
        *h1 = [0.0; 3];
    }
    if p.lid {
        let (o, e) = wall_contact::<FR>(law, r, h, xi[2] + r - p.height, [0.0, 0.0, 1.0], vi, wi, h2, acc);
        (ov, ex) = (ov.max(o), ex.max(e));
    }
    (ov, ex)
}

/// Vertical force of each wall (plate, tube, lid) on the particles at the current state, from
/// the contact law with copies of the stored histories (nothing changes). For momentum budgets:
/// the part of the bed's weight the walls carry.
pub fn wall_loads(p: &DemParams, x: &[V3], v: &[V3], w: &[V3], list: &WallList) -> [f64; 3] {
    let (law, r, h) = (&p.wall, p.radius, p.dt);
    let reach = p.tube_radius - r;
    let mut load = [0.0; 3];
    for (&i, hist) in list.idx.iter().zip(&list.hist) {
        let (xi, vi, wi) = (x[i as usize], v[i as usize], w[i as usize]);
        let rho = (xi[0] * xi[0] + xi[1] * xi[1]).sqrt().max(f64::MIN_POSITIVE);
        let walls = [
            (r - xi[2], [0.0, 0.0, -1.0]),
            (rho - reach, [xi[0] / rho, xi[1] / rho, 0.0]),
            (if p.lid { xi[2] + r - p.height } else { -1.0 }, [0.0, 0.0, 1.0]),
        ];
        for (k, (delta, nrm)) in walls.into_iter().enumerate() {
            let (mut hk, mut acc) = (hist[k], [0.0; 6]);
            wall_contact::<true>(law, r, h, delta, nrm, vi, wi, &mut hk, &mut acc);
            load[k] += acc[2];
        }
    }
    load
}
