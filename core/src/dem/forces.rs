//! The two parallel passes of a DEM step, bit-reproducible for a given work split (chunk count):
//! 1. pair pass: every listed pair once (half list), contiguous particle chunks in parallel, each
//!    adding the pair forces on i and j into its own buffer (no atomics, no races);
//! 2. particle pass: sum the chunk buffers for each particle in chunk order, add walls, gravity
//!    and the external force, and (fused) advance it by AB3.

use super::contact::{contact_force, ContactLaw, V3};
use super::pair_batch::{Batch, CAP};
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

/// Work split of the pair pass: contiguous particle chunks [a, b), each accumulating its pair
/// forces (on i and on j) into a private buffer covering particles [a, e), e = 1 + the largest
/// partner index of the chunk. The chunks depend only on the list and the thread count, and the
/// buffers are summed in chunk order, so a run is bit-reproducible for a given thread count.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// Per chunk: a, b, e.
    pub bounds: Vec<[usize; 3]>,
    /// Start of each chunk's buffer in `f` and `t`.
    pub start: Vec<usize>,
    pub f: Vec<V3>,
    pub t: Vec<V3>,
}

impl Scratch {
    /// Plan `chunks` chunks (fewer for small systems) over the list.
    pub fn plan(nl: &NeighborList, n: usize, chunks: usize) -> Scratch {
        let nc = chunks.clamp(1, n.div_ceil(512).max(1));
        let mut bounds = Vec::with_capacity(nc);
        let mut start = Vec::with_capacity(nc + 1);
        start.push(0);
        for c in 0..nc {
            let (a, b) = (c * n / nc, (c + 1) * n / nc);
            let mut e = b;
            for i in a..b {
                let (k0, k1) = (nl.offsets[i] as usize, nl.offsets[i + 1] as usize);
                if k1 > k0 {
                    e = e.max(nl.nbr[k1 - 1] as usize + 1);
                }
            }
            bounds.push([a, b, e]);
            start.push(start[c] + e - a);
        }
        let len = start[nc];
        Scratch { bounds, start, f: vec![[0.0; 3]; len], t: vec![[0.0; 3]; len] }
    }
}

/// Pass 1: all listed pairs, forces and torques accumulated into the chunk buffers.
pub fn pair_pass<const FR: bool>(
    p: &DemParams,
    x: &[V3],
    v: &[V3],
    w: &[V3],
    nl: &mut NeighborList,
    sc: &mut Scratch,
) -> Stats {
    let offsets = &nl.offsets;
    let nbr = &nl.nbr;
    let mut work = Vec::with_capacity(sc.bounds.len());
    let (mut sh_rest, mut f_rest, mut t_rest) = (&mut nl.shear[..], &mut sc.f[..], &mut sc.t[..]);
    for &[a, b, e] in &sc.bounds {
        let (sh, r1) = sh_rest.split_at_mut((offsets[b] - offsets[a]) as usize);
        let (f, r2) = f_rest.split_at_mut(e - a);
        let (t, r3) = t_rest.split_at_mut(e - a);
        (sh_rest, f_rest, t_rest) = (r1, r2, r3);
        work.push((a, b, sh, f, t));
    }
    let (d, r) = (2.0 * p.radius, p.radius);
    let d2 = d * d;
    let (law, h) = (&p.pair, p.dt);
    work.into_par_iter()
        .map(|(a, b, sh, fb, tb)| {
            fb.fill([0.0; 3]);
            if FR {
                tb.fill([0.0; 3]);
            }
            let mut st = Stats::ZERO;
            let base = offsets[a] as usize;
            let mut batch = Batch::new();
            let flush = |batch: &mut Batch, sh: &mut [V3], fb: &mut [V3], tb: &mut [V3], st: &mut Stats| {
                let (ov, ex) = batch.evaluate::<FR>(law, r, h, v, w, sh, base);
                st.overlap = st.overlap.max(ov);
                st.coulomb_excess = st.coulomb_excess.max(ex);
                for l in 0..batch.m {
                    let (ii, jj) = (batch.i[l] as usize - a, batch.j[l] as usize - a);
                    for q in 0..3 {
                        fb[ii][q] += batch.f[q][l];
                        fb[jj][q] -= batch.f[q][l];
                    }
                    if FR {
                        // Both partners feel R n × F_t (contact points ±R n, forces ±F_t).
                        for q in 0..3 {
                            tb[ii][q] += batch.c[q][l];
                            tb[jj][q] += batch.c[q][l];
                        }
                    }
                }
                batch.m = 0;
            };
            let mut m = 0; // lanes filled (kept in a register; batch.m is set before a flush)
            for i in a..b {
                let xi = x[i];
                let row = &nbr[offsets[i] as usize..offsets[i + 1] as usize];
                for (kr, &j) in row.iter().enumerate() {
                    let j = j as usize;
                    let xj = x[j];
                    let dx = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                    let r2 = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
                    let k = offsets[i] as usize + kr;
                    if r2 >= d2 {
                        if FR {
                            sh[k - base] = [0.0; 3];
                        }
                        continue;
                    }
                    batch.set(m, k, i, j, dx, r2);
                    m += 1;
                    if m == CAP {
                        batch.m = m;
                        flush(&mut batch, sh, fb, tb, &mut st);
                        m = 0;
                    }
                }
            }
            batch.m = m;
            flush(&mut batch, sh, fb, tb, &mut st);
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
    p: &DemParams, i: usize, xi: V3, vi: V3, wi: V3, wall: &mut [V3; 3], ext: V3, sc: &Scratch, st: &mut Stats,
) -> (V3, V3) {
    let mut f = ext;
    let mut t = [0.0; 3];
    for (c, &[a, _, e]) in sc.bounds.iter().enumerate() {
        if a <= i && i < e {
            let k = sc.start[c] + i - a;
            let q = sc.f[k];
            f = [f[0] + q[0], f[1] + q[1], f[2] + q[2]];
            if FR {
                let c = sc.t[k];
                t = [t[0] + c[0], t[1] + c[1], t[2] + c[2]];
            }
        }
    }
    let r = p.radius;
    if FR {
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
    p: &DemParams, x: &[V3], v: &[V3], w: &[V3], past: &mut [Past], ext: &[V3], sc: &Scratch, a: &mut [V3], alpha: &mut [V3],
) -> Stats {
    past.par_chunks_mut(BLOCK)
        .zip(a.par_chunks_mut(BLOCK))
        .zip(alpha.par_chunks_mut(BLOCK))
        .enumerate()
        .map(|(b, ((ps, ab), lb))| {
            let mut st = Stats::ZERO;
            for l in 0..ps.len() {
                let i = b * BLOCK + l;
                (ab[l], lb[l]) = accel::<FR>(p, i, x[i], v[i], w[i], &mut ps[l].wall, ext[i], sc, &mut st);
            }
            st
        })
        .reduce(|| Stats::ZERO, Stats::max)
}

/// Pass 2, fused: accelerations and the multistep update (weights `hb` = h·b) in one sweep.
#[allow(clippy::too_many_arguments)]
pub fn update_pass<const FR: bool>(
    p: &DemParams, hb: [f64; 3], x: &mut [V3], v: &mut [V3], w: &mut [V3], past: &mut [Past], ext: &[V3],
    sc: &Scratch,
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
                let (a, alpha) = accel::<FR>(p, i, xi, vi, wi, &mut q.wall, ext[i], sc, &mut st);
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
