//! The two parallel passes of a DEM step, both deterministic for any thread count:
//! 1. pair pass: every listed pair once (half list), force on the first particle into a per-pair
//!    array, blocks of particles in parallel (each block owns its contiguous slice of pairs);
//! 2. particle pass: gather each particle's pair forces in a fixed order (its own row, then its
//!    transpose row), add walls, gravity and the external force, and (fused) advance it by AB.

use super::contact::{contact_force, ContactLaw, V3};
use super::integrator::ab_update;
use super::neighbors::{NeighborList, BLOCK};
use super::DemParams;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Per-particle past values for the multistep scheme and the wall contact histories.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Past {
    /// v_{n−1}, v_{n−2}.
    pub v: [V3; 2],
    /// a_{n−1}, a_{n−2}.
    pub a: [V3; 2],
    /// Angular accelerations at n−1, n−2.
    pub alpha: [V3; 2],
    /// Position at the last neighbour-list build.
    pub x_build: V3,
    /// Tangential displacement at the plate, the tube and the lid.
    pub wall: [V3; 3],
}

/// Maxima seen in a pass (max is exact and order-free, so these stay deterministic).
#[derive(Clone, Copy, Debug)]
pub struct Stats {
    pub overlap: f64,
    pub coulomb_excess: f64,
    pub disp2: f64,
}

impl Stats {
    pub const ZERO: Stats = Stats { overlap: 0.0, coulomb_excess: f64::NEG_INFINITY, disp2: 0.0 };
    pub fn max(self, o: Stats) -> Stats {
        Stats {
            overlap: self.overlap.max(o.overlap),
            coulomb_excess: self.coulomb_excess.max(o.coulomb_excess),
            disp2: self.disp2.max(o.disp2),
        }
    }
}

/// Split `s` into consecutive pieces at the pair offsets of each particle block.
fn split_blocks<'a, T>(mut s: &'a mut [T], offsets: &[u32], nblocks: usize, n: usize) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(nblocks);
    for b in 0..nblocks {
        let (a, e) = (offsets[b * BLOCK] as usize, offsets[((b + 1) * BLOCK).min(n)] as usize);
        if s.is_empty() {
            out.push(&mut [][..]);
            continue;
        }
        let (head, tail) = s.split_at_mut(e - a);
        out.push(head);
        s = tail;
    }
    out
}

/// Pass 1: force on particle i of every listed pair (i, j) into `pf`, n × F_t into `pc`.
pub fn pair_pass<const FR: bool>(
    p: &DemParams,
    x: &[V3],
    v: &[V3],
    w: &[V3],
    nl: &mut NeighborList,
    pf: &mut [V3],
    pc: &mut [V3],
) -> Stats {
    let n = x.len();
    let nb = n.div_ceil(BLOCK);
    let offsets = &nl.offsets;
    let nbr = &nl.nbr;
    let shear = split_blocks(&mut nl.shear, offsets, nb, n);
    let pfs = split_blocks(pf, offsets, nb, n);
    let pcs = split_blocks(pc, offsets, nb, n);
    let (d, r) = (2.0 * p.radius, p.radius);
    let d2 = d * d;
    let (law, h) = (&p.pair, p.dt);
    shear
        .into_par_iter()
        .zip(pfs)
        .zip(pcs)
        .enumerate()
        .map(|(b, ((sh, pfb), pcb))| {
            let mut st = Stats::ZERO;
            let base = offsets[b * BLOCK] as usize;
            for i in b * BLOCK..((b + 1) * BLOCK).min(n) {
                let (xi, vi) = (x[i], v[i]);
                let wi = if FR { w[i] } else { [0.0; 3] };
                for k in offsets[i] as usize..offsets[i + 1] as usize {
                    let kk = k - base;
                    let j = nbr[k] as usize;
                    let dx = [x[j][0] - xi[0], x[j][1] - xi[1], x[j][2] - xi[2]];
                    let r2 = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
                    if r2 >= d2 {
                        pfb[kk] = [0.0; 3];
                        if FR {
                            sh[kk] = [0.0; 3];
                            pcb[kk] = [0.0; 3];
                        }
                        continue;
                    }
                    let dist = r2.sqrt();
                    let inv = 1.0 / dist;
                    let nrm = [dx[0] * inv, dx[1] * inv, dx[2] * inv];
                    let delta = d - dist;
                    let vrel = [vi[0] - v[j][0], vi[1] - v[j][1], vi[2] - v[j][2]];
                    let ws = if FR { [r * (wi[0] + w[j][0]), r * (wi[1] + w[j][1]), r * (wi[2] + w[j][2])] } else { [0.0; 3] };
                    let mut s = if FR { sh[kk] } else { [0.0; 3] };
                    let cf = contact_force::<FR>(law, delta, nrm, vrel, ws, &mut s, h);
                    pfb[kk] = cf.f;
                    if FR {
                        sh[kk] = s;
                        pcb[kk] = cf.c;
                        st.coulomb_excess = st.coulomb_excess.max(cf.excess);
                    }
                    st.overlap = st.overlap.max(delta);
                }
            }
            st
        })
        .reduce(|| Stats::ZERO, Stats::max)
}

/// One wall contact of particle i: add its force and torque.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn wall_contact<const FR: bool>(
    law: &ContactLaw, r: f64, h: f64, delta: f64, nrm: V3, vi: V3, wi: V3, hist: &mut V3, f: &mut V3, t: &mut V3,
    st: &mut Stats,
) {
    if delta <= 0.0 {
        *hist = [0.0; 3];
        return;
    }
    let ws = [r * wi[0], r * wi[1], r * wi[2]];
    let cf = contact_force::<FR>(law, delta, nrm, vi, ws, hist, h);
    for k in 0..3 {
        f[k] += cf.f[k];
        t[k] += r * cf.c[k];
    }
    st.overlap = st.overlap.max(delta);
    if FR {
        st.coulomb_excess = st.coulomb_excess.max(cf.excess);
    }
}

/// Linear and angular acceleration of particle i at the current state (walls update `wall`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn accel<const FR: bool>(
    p: &DemParams, i: usize, xi: V3, vi: V3, wi: V3, wall: &mut [V3; 3], ext: V3, nl: &NeighborList, pf: &[V3],
    pc: &[V3], st: &mut Stats,
) -> (V3, V3) {
    let mut f = ext;
    let mut t = [0.0; 3];
    for k in nl.offsets[i] as usize..nl.offsets[i + 1] as usize {
        let q = pf[k];
        f = [f[0] + q[0], f[1] + q[1], f[2] + q[2]];
        if FR {
            let c = pc[k];
            t = [t[0] + c[0], t[1] + c[1], t[2] + c[2]];
        }
    }
    for &k in &nl.rev_pairs[nl.rev_offsets[i] as usize..nl.rev_offsets[i + 1] as usize] {
        let q = pf[k as usize];
        f = [f[0] - q[0], f[1] - q[1], f[2] - q[2]];
        if FR {
            let c = pc[k as usize];
            t = [t[0] + c[0], t[1] + c[1], t[2] + c[2]];
        }
    }
    let r = p.radius;
    if FR {
        // Both partners of a pair feel R n × F_t (contact points ±R n, forces ±F_t).
        t = [r * t[0], r * t[1], r * t[2]];
    }
    let (law, h) = (&p.wall, p.dt);
    // Distributor plate z = 0: normal (0,0,−1).
    let [w0, w1, w2] = wall;
    wall_contact::<FR>(law, r, h, r - xi[2], [0.0, 0.0, -1.0], vi, wi, w0, &mut f, &mut t, st);
    // Tube of radius R_t: outward radial normal.
    let rho2 = xi[0] * xi[0] + xi[1] * xi[1];
    let reach = p.tube_radius - r;
    if rho2 > reach * reach {
        let rho = rho2.sqrt();
        let nrm = [xi[0] / rho, xi[1] / rho, 0.0];
        wall_contact::<FR>(law, r, h, rho - reach, nrm, vi, wi, w1, &mut f, &mut t, st);
    } else {
        *w1 = [0.0; 3];
    }
    if p.lid {
        wall_contact::<FR>(law, r, h, xi[2] + r - p.height, [0.0, 0.0, 1.0], vi, wi, w2, &mut f, &mut t, st);
    }
    let im = 1.0 / p.mass;
    let g = p.extra_damping;
    let a = [f[0] * im - g * vi[0], f[1] * im - g * vi[1], f[2] * im - p.gravity - g * vi[2]];
    let alpha = if FR {
        let ii = 1.0 / p.inertia;
        [t[0] * ii - g * wi[0], t[1] * ii - g * wi[1], t[2] * ii - g * wi[2]]
    } else {
        [0.0; 3]
    };
    (a, alpha)
}

/// Pass 2 for start-up: accelerations only, into `a` and `alpha`.
#[allow(clippy::too_many_arguments)]
pub fn accel_pass<const FR: bool>(
    p: &DemParams, x: &[V3], v: &[V3], w: &[V3], past: &mut [Past], ext: &[V3], nl: &NeighborList, pf: &[V3],
    pc: &[V3], a: &mut [V3], alpha: &mut [V3],
) -> Stats {
    past.par_chunks_mut(BLOCK)
        .zip(a.par_chunks_mut(BLOCK))
        .zip(alpha.par_chunks_mut(BLOCK))
        .enumerate()
        .map(|(b, ((ps, ab), lb))| {
            let mut st = Stats::ZERO;
            for l in 0..ps.len() {
                let i = b * BLOCK + l;
                (ab[l], lb[l]) = accel::<FR>(p, i, x[i], v[i], w[i], &mut ps[l].wall, ext[i], nl, pf, pc, &mut st);
            }
            st
        })
        .reduce(|| Stats::ZERO, Stats::max)
}

/// Pass 2, fused: accelerations and the multistep update (weights `hb` = h·b) in one sweep.
#[allow(clippy::too_many_arguments)]
pub fn update_pass<const FR: bool>(
    p: &DemParams, hb: [f64; 3], x: &mut [V3], v: &mut [V3], w: &mut [V3], past: &mut [Past], ext: &[V3],
    nl: &NeighborList, pf: &[V3], pc: &[V3],
) -> Stats {
    x.par_chunks_mut(BLOCK)
        .zip(v.par_chunks_mut(BLOCK))
        .zip(w.par_chunks_mut(BLOCK))
        .zip(past.par_chunks_mut(BLOCK))
        .enumerate()
        .map(|(b, (((xs, vs), ws), ps))| {
            let mut st = Stats::ZERO;
            for l in 0..xs.len() {
                let i = b * BLOCK + l;
                let (xi, vi, wi) = (xs[l], vs[l], ws[l]);
                let q = &mut ps[l];
                let (a, alpha) = accel::<FR>(p, i, xi, vi, wi, &mut q.wall, ext[i], nl, pf, pc, &mut st);
                let xn = ab_update(xi, vi, q.v[0], q.v[1], hb);
                vs[l] = ab_update(vi, a, q.a[0], q.a[1], hb);
                q.v = [vi, q.v[0]];
                q.a = [a, q.a[0]];
                if FR {
                    ws[l] = ab_update(wi, alpha, q.alpha[0], q.alpha[1], hb);
                    q.alpha = [alpha, q.alpha[0]];
                }
                let dd = [xn[0] - q.x_build[0], xn[1] - q.x_build[1], xn[2] - q.x_build[2]];
                st.disp2 = st.disp2.max(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
                xs[l] = xn;
            }
            st
        })
        .reduce(|| Stats::ZERO, Stats::max)
}
