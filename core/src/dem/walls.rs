//! Wall contacts (distributor plate z = 0, tube of radius R_t, optional lid z = H) with the
//! particle-wall contact law (PHYSICS.md 2; paper section 2.1). Only particles that can reach a
//! wall before the next list rebuild are checked: the wall list holds every particle within one
//! skin of a wall at the last rebuild (a rebuild comes before anything moves half a skin), with
//! the tangential histories of its three walls.

use super::contact::{contact_force, V3};
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
}

/// One wall contact of a particle with velocity and spin (v, ω): overlap `delta` along the outward
/// normal `nrm`, the particle-wall law of `p`; hands wall `k`'s force and n × F_t to `on`.
/// Returns (overlap, Coulomb excess, −∞ unless `p.audit`) for the diagnostics.
#[inline(always)]
fn wall_contact<const FR: bool>(
    p: &DemParams,
    k: usize,
    delta: f64,
    nrm: V3,
    (vi, wi): (V3, V3),
    hist: &mut V3,
    on: &mut impl FnMut(usize, &[f64; 6]),
) -> (f64, f64) {
    if delta <= 0.0 {
        *hist = [0.0; 3];
        return (0.0, f64::NEG_INFINITY);
    }
    let r = p.radius;
    let ws = [r * wi[0], r * wi[1], r * wi[2]];
    let cf = contact_force::<FR>(&p.wall, delta, nrm, vi, ws, hist, p.dt);
    on(k, &[cf.f[0], cf.f[1], cf.f[2], cf.c[0], cf.c[1], cf.c[2]]);
    (delta, if FR && p.audit { cf.excess } else { f64::NEG_INFINITY })
}

/// Every wall contact of a particle at `xi`: wall k (0 plate, 1 tube, 2 lid) hands its force
/// and n × F_t to `on`; returns the largest overlap and Coulomb excess.
#[inline(always)]
fn each_wall<const FR: bool>(
    p: &DemParams,
    xi: V3,
    vi: V3,
    wi: V3,
    hist: &mut [V3; 3],
    mut on: impl FnMut(usize, &[f64; 6]),
) -> (f64, f64) {
    let r = p.radius;
    let [h0, h1, h2] = hist;
    // Distributor plate z = 0: normal (0,0,−1).
    let (mut ov, mut ex) = wall_contact::<FR>(p, 0, r - xi[2], [0.0, 0.0, -1.0], (vi, wi), h0, &mut on);
    // Tube of radius R_t: outward radial normal.
    let rho2 = xi[0] * xi[0] + xi[1] * xi[1];
    let reach = p.tube_radius - r;
    if rho2 > reach * reach {
        let rho = rho2.sqrt();
        let nrm = [xi[0] / rho, xi[1] / rho, 0.0];
        let (o, e) = wall_contact::<FR>(p, 1, rho - reach, nrm, (vi, wi), h1, &mut on);
        (ov, ex) = (ov.max(o), ex.max(e));
    } else {
        *h1 = [0.0; 3];
    }
    if p.lid {
        let (o, e) = wall_contact::<FR>(p, 2, xi[2] + r - p.height, [0.0, 0.0, 1.0], (vi, wi), h2, &mut on);
        (ov, ex) = (ov.max(o), ex.max(e));
    }
    (ov, ex)
}

/// All wall forces on a particle at `xi` (force and n × F_t summed into `acc`); returns the
/// largest overlap and Coulomb excess.
#[inline]
pub fn wall_forces<const FR: bool>(
    p: &DemParams,
    xi: V3,
    vi: V3,
    wi: V3,
    hist: &mut [V3; 3],
    acc: &mut [f64; 6],
) -> (f64, f64) {
    each_wall::<FR>(p, xi, vi, wi, hist, |_, fc| {
        for (a, f) in acc.iter_mut().zip(fc) {
            *a += f;
        }
    })
}

/// Vertical force of each wall (plate, tube, lid) on the particles at the current state, from
/// the contact law with copies of the stored histories (nothing changes). For momentum budgets:
/// the part of the bed's weight the walls carry.
pub fn wall_loads(p: &DemParams, x: &[V3], v: &[V3], w: &[V3], list: &WallList) -> [f64; 3] {
    let mut load = [0.0; 3];
    for (&i, hist) in list.idx.iter().zip(&list.hist) {
        let i = i as usize;
        each_wall::<true>(p, x[i], v[i], w[i], &mut hist.clone(), |k, fc| load[k] += fc[2]);
    }
    load
}
