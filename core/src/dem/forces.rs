//! The two parallel passes of a DEM step, bit-reproducible for a given work split (chunk count):
//! 1. pair pass: every listed pair once (half list), contiguous particle chunks in parallel, each
//!    adding the pair forces on i and j into its own buffer (no atomics, no races; rows in
//!    single precision, `pair_scatter`); a listed pair costs a distance check, only touching
//!    pairs go to the batched contact kernel;
//! 2. the particle pass (`particle_pass`): per block, sum the chunk buffers in chunk order, add
//!    walls (only for the wall list), gravity and the external force, and advance by AB3.
//!
//! This file holds the shared types and pass 1. `team_step` runs both passes as one broadcast
//! (the multistep steps); `pair_pass` alone serves the start-up and the fallback.

use super::contact::{ContactLaw, V3};
use super::neighbors::{Hist, NeighborList};
use super::pair_batch::{Batch, CAP};
use super::pair_scatter::{scatter, PairSum};
#[cfg(target_arch = "x86_64")]
use super::pair_simd::{scan8, LANES};
pub use super::work_split::Scratch;
use super::DemParams;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Force and n × F_t sums of one particle.
pub type Acc = [f64; 6];

/// Past derivatives for the multistep scheme, two of each (structure of arrays): velocities
/// (for x), accelerations (for v), angular accelerations (for ω). `ring` (in the system) says
/// which slot is the newer one, so a step overwrites the older slot instead of shifting both.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Past {
    pub v: [Vec<V3>; 2],
    pub a: [Vec<V3>; 2],
    pub alpha: [Vec<V3>; 2],
}

impl Past {
    pub fn zeros(n: usize) -> Past {
        let z = || [vec![[0.0; 3]; n], vec![[0.0; 3]; n]];
        Past { v: z(), a: z(), alpha: z() }
    }
    /// Particle i now is particle order[i] before.
    pub fn permute(&mut self, order: &[u32]) {
        for s in self.v.iter_mut().chain(&mut self.a).chain(&mut self.alpha) {
            *s = order.iter().map(|&o| s[o as usize]).collect();
        }
    }
}

/// Maxima seen in a pass (max is exact and order-free, so these stay deterministic).
#[derive(Clone, Copy, Debug)]
pub struct Stats {
    pub overlap: f64,
    pub coulomb_excess: f64,
    pub disp2: f64,
    /// Largest |component| of a position's change in the step, and of a new position (m).
    pub moved: f64,
    pub extent: f64,
}

impl Stats {
    pub const ZERO: Stats =
        Stats { overlap: 0.0, coulomb_excess: f64::NEG_INFINITY, disp2: 0.0, moved: 0.0, extent: 0.0 };
    pub fn max(self, o: Stats) -> Stats {
        Stats {
            overlap: self.overlap.max(o.overlap),
            coulomb_excess: self.coulomb_excess.max(o.coulomb_excess),
            disp2: self.disp2.max(o.disp2),
            moved: self.moved.max(o.moved),
            extent: self.extent.max(o.extent),
        }
    }
}

/// Which code the pair pass runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernels {
    /// The vector kernels the CPU has (AVX-512, AVX2), picked at run time.
    Best,
    /// The portable code alone (tests compare the two).
    Portable,
}

/// Pass 1: all listed pairs, forces and n × F_t accumulated into the chunk buffers.
pub fn pair_pass<const FR: bool>(
    p: &DemParams,
    x: &[V3],
    v: &[V3],
    w: &[V3],
    nl: &mut NeighborList,
    sc: &mut Scratch,
    kernels: Kernels,
) -> Stats {
    let offsets = &nl.offsets;
    let nbr = &nl.nbr;
    let owner = &sc.owner[..];
    let mut work = Vec::with_capacity(sc.bounds.len());
    let (mut sh_rest, mut to_rest, mut acc_rest) = (&mut nl.shear[..], &mut nl.touch[..], &mut sc.acc[..]);
    for &[a, b, e] in &sc.bounds {
        let len = (offsets[b] - offsets[a]) as usize;
        let (sh, r1) = sh_rest.split_at_mut(if FR { len } else { 0 });
        let (to, r2) = to_rest.split_at_mut(if FR { len } else { 0 });
        let (acc, r3) = acc_rest.split_at_mut(e - a);
        (sh_rest, to_rest, acc_rest) = (r1, r2, r3);
        work.push((a, b, sh, to, acc));
    }
    let (r, d2) = (p.radius, 4.0 * p.radius * p.radius);
    let (law, h, audit) = (&p.pair, p.dt, p.audit);
    work.into_par_iter()
        .map(|(a, b, sh, to, acc)| {
            let e = a + acc.len();
            let args =
                ChunkArgs { law, audit, r, h, d2, a, b, offsets, nbr, owner, x: &x[a..e], v: &v[a..e], w: &w[a..e] };
            match kernels {
                Kernels::Best => chunk_pairs_dispatch::<FR>(&args, sh, to, acc),
                Kernels::Portable => chunk_pairs::<FR, false>(&args, sh, to, acc),
            }
        })
        .reduce(|| Stats::ZERO, Stats::max)
}

/// Read-only inputs of one chunk of the pair pass.
pub(super) struct ChunkArgs<'a> {
    pub law: &'a ContactLaw,
    /// Measure the Coulomb excess of every contact (`DemParams::audit`).
    pub audit: bool,
    pub r: f64,
    pub h: f64,
    pub d2: f64,
    pub a: usize,
    pub b: usize,
    pub offsets: &'a [u32],
    pub nbr: &'a [u32],
    pub owner: &'a [u32],
    /// Positions, velocities and spins of the chunk's window, particles a..e (rows and partners).
    pub x: &'a [V3],
    pub v: &'a [V3],
    pub w: &'a [V3],
}

pub(super) fn chunk_pairs_dispatch<const FR: bool>(
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("bmi2")
        {
            // SAFETY: the CPU supports the features the function is compiled for.
            return unsafe { chunk_pairs_avx512::<FR>(c, sh, to, acc) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: as above.
            return unsafe { chunk_pairs_avx2::<FR>(c, sh, to, acc) };
        }
    }
    chunk_pairs::<FR, false>(c, sh, to, acc)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,bmi2")]
unsafe fn chunk_pairs_avx512<const FR: bool>(
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    chunk_pairs::<FR, true>(c, sh, to, acc)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn chunk_pairs_avx2<const FR: bool>(
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    chunk_pairs::<FR, false>(c, sh, to, acc)
}

/// The pair pass over rows a..b: distance checks, touching pairs batched and evaluated, forces
/// added into `acc` (particles a..). Particles are read only in the window a..e, and the batch
/// lanes hold indices into it (particle − a).
#[inline(always)]
fn chunk_pairs<const FR: bool, const V: bool>(
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    let &ChunkArgs { law, audit, r, h, d2, a, b, offsets, nbr, owner, x, v, w } = c;
    acc.fill(PairSum::default());
    let mut st = Stats::ZERO;
    let (base, end) = (offsets[a] as usize, offsets[b] as usize);
    let mut batch = Batch::new();
    // One flat loop over the chunk's entries (the row of entry k is owner[k]): no row loop,
    // no data-dependent branch. Every entry is written into lane m; only touching ones
    // advance m.
    let mut m = 0;
    assert!(owner.len() == nbr.len() && end <= nbr.len() && x.len() <= i32::MAX as usize / 3);
    assert!(acc.len() == x.len() && v.len() == x.len() && (w.len() == x.len() || !FR), "chunk window");
    let mut k = base;
    #[cfg(target_arch = "x86_64")]
    if V {
        while k + LANES <= end {
            if m > CAP - LANES {
                batch.m = m;
                flush::<FR, V>(&mut batch, law, audit, r, h, v, w, sh, base, acc, &mut st);
                m = 0;
            }
            // SAFETY: V is set only by the caller compiled for (and checked to have) the
            // features; bounds as asserted above and in `Scratch::plan`.
            m = unsafe { scan8::<FR>(k, base, a, owner, nbr, x, d2, to, &mut batch, m) };
            k += LANES;
        }
        if m == CAP {
            batch.m = m;
            flush::<FR, V>(&mut batch, law, audit, r, h, v, w, sh, base, acc, &mut st);
            m = 0;
        }
    }
    for k in k..end {
        // SAFETY: k < end ≤ nbr.len() = owner.len() (asserted); `Scratch::plan` checked
        // a ≤ i < j < e for every pair of the chunk, and the chunk's `to` covers k - base.
        let (i, j) = unsafe { (*owner.get_unchecked(k) as usize - a, *nbr.get_unchecked(k) as usize - a) };
        let (xi, xj) = unsafe { (*x.get_unchecked(i), *x.get_unchecked(j)) };
        let dx = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
        let r2 = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
        let touching = r2 < d2;
        if FR {
            // The history is live only while the pair keeps touching.
            let t = unsafe { to.get_unchecked_mut(k - base) };
            batch.was[m] = *t;
            *t = touching as u8;
        }
        batch.set(m, k, i, j, dx, r2, d2);
        m += touching as usize;
        if m == CAP {
            batch.m = m;
            flush::<FR, V>(&mut batch, law, audit, r, h, v, w, sh, base, acc, &mut st);
            m = 0;
        }
    }
    batch.m = m;
    flush::<FR, V>(&mut batch, law, audit, r, h, v, w, sh, base, acc, &mut st);
    st
}

/// Evaluate a batch and add its forces into `acc` (the chunk window, as the lane indices).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn flush<const FR: bool, const V: bool>(
    batch: &mut Batch,
    law: &ContactLaw,
    audit: bool,
    r: f64,
    h: f64,
    v: &[V3],
    w: &[V3],
    sh: &mut [Hist],
    base: usize,
    acc: &mut [PairSum],
    st: &mut Stats,
) {
    let (ov, ex) = batch.evaluate::<FR, V>(law, audit, r, h, v, w, sh, base);
    st.overlap = st.overlap.max(ov);
    st.coulomb_excess = st.coulomb_excess.max(ex);
    scatter::<FR, V>(batch, acc);
    batch.m = 0;
}
