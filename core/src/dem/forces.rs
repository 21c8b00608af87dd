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

use super::batch::{Batch, Entries, Entry, PairInputs, CAP};
use super::contact::V3;
use super::kernel::{Isa, Kernel};
use super::neighbors::{Hist, NeighborList};
use super::pair_batch::evaluate;
use super::pair_scatter::{scatter, PairSum};
#[cfg(target_arch = "x86_64")]
use super::pair_simd::{scan8, LANES};
pub(crate) use super::work_split::Scratch;
use super::DemParams;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Force and n × F_t sums of one particle.
pub type Acc = [f64; 6];

/// A past derivative as stored: single precision. The multistep update reads it with weights
/// −16/12 and 5/12 beside the current derivative at full precision, so its rounding (relative
/// 2⁻²⁴) moves a step by at most 2⁻²⁴·(21/12)·h·max|f|: ~1e-7 of an increment, far under the
/// contact law's own error (test `free_fall_with_single_precision_history_is_exact_to_1e_7`).
/// Half the bytes of the history, which the particle pass streams every step.
pub type PastV3 = [f32; 3];

/// Past derivatives for the multistep scheme, two of each (structure of arrays): velocities
/// (for x), accelerations (for v), angular accelerations (for ω). `ring` (in the system) says
/// which slot is the newer one, so a step overwrites the older slot instead of shifting both.
/// Checkpoints hold them as f64 (the format of earlier builds, which still resume; f32 → f64
/// → f32 is exact, so a resumed run continues bit for bit).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Past {
    #[serde(with = "wide_slots")]
    pub v: [Vec<PastV3>; 2],
    #[serde(with = "wide_slots")]
    pub a: [Vec<PastV3>; 2],
    #[serde(with = "wide_slots")]
    pub alpha: [Vec<PastV3>; 2],
}

impl Past {
    pub fn zeros(n: usize) -> Past {
        let z = || [vec![[0.0; 3]; n], vec![[0.0; 3]; n]];
        Past { v: z(), a: z(), alpha: z() }
    }
    /// The six slots (v, a, α; two each).
    pub fn slots_mut(&mut self) -> impl Iterator<Item = &mut Vec<PastV3>> {
        self.v.iter_mut().chain(&mut self.a).chain(&mut self.alpha)
    }
}

/// A derivative to its stored precision.
#[inline(always)]
pub fn narrow(f: V3) -> PastV3 {
    f.map(|c| c as f32)
}

/// A stored derivative as the update reads it (exact).
#[inline(always)]
pub fn widen(f: PastV3) -> V3 {
    f.map(f64::from)
}

/// The two slots of a past derivative in a checkpoint: as `[Vec<[f64; 3]>; 2]` (the same bytes
/// as earlier builds wrote).
mod wide_slots {
    use super::{narrow, widen, PastV3};
    use serde::ser::SerializeTuple;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    struct Wide<'a>(&'a [PastV3]);
    impl Serialize for Wide<'_> {
        fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            s.collect_seq(self.0.iter().map(|&r| widen(r)))
        }
    }

    pub fn serialize<S: Serializer>(slots: &[Vec<PastV3>; 2], s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(2)?;
        t.serialize_element(&Wide(&slots[0]))?;
        t.serialize_element(&Wide(&slots[1]))?;
        t.end()
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[Vec<PastV3>; 2], D::Error> {
        let wide = <[Vec<[f64; 3]>; 2]>::deserialize(d)?;
        Ok(wide.map(|s| s.into_iter().map(narrow).collect()))
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

/// Pass 1: all listed pairs, forces and n × F_t accumulated into the chunk buffers, on the
/// `kernel` path (the portable one when the CPU lacks it). Panics unless `sc` was planned for
/// `nl` and the arrays hold one row per particle.
pub(crate) fn pair_pass<const FR: bool>(
    p: &DemParams,
    state: (&[V3], &[V3], &[V3]),
    nl: &mut NeighborList,
    sc: &mut Scratch,
    kernel: Kernel,
) -> Stats {
    pair_pass_with::<FR>(p, state, nl, sc, kernel, None)
}

/// Rows per piece of a pass that keeps the histories (Heun's second evaluation): about 15k
/// entries, 0.2 MB of copies per chunk in flight.
pub(crate) const KEEP_PIECE_ROWS: usize = 4096;

/// `pair_pass`, which with `keep_in_pieces: Some(rows)` leaves the list's histories and touch
/// flags as they were (Heun's second evaluation): each chunk then works through its rows `rows`
/// at a time on a copy of their histories, so that only those are copied, not the whole list.
/// The same forces, bit for bit: a chunk's touching pairs reach its buffer in the same order.
pub(crate) fn pair_pass_with<const FR: bool>(
    p: &DemParams,
    (x, v, w): (&[V3], &[V3], &[V3]),
    nl: &mut NeighborList,
    sc: &mut Scratch,
    kernel: Kernel,
    keep_in_pieces: Option<usize>,
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
    work.into_par_iter()
        .map(|(a, b, sh, to, acc)| {
            let e = a + acc.len();
            let args = ChunkArgs::new(p, a, b, offsets, owner, nbr, (&x[a..e], &v[a..e], &w[a..e]));
            match keep_in_pieces {
                Some(rows) if FR => chunk_pairs_keeping::<FR>(kernel, &args, (sh, to), acc, rows.max(1)),
                _ => chunk_pairs_on::<FR>(kernel, &args, sh, to, acc),
            }
        })
        .reduce(|| Stats::ZERO, Stats::max)
}

/// One chunk whose histories and flags (`sh`, `to`) stay as they were: its rows `rows` at a time,
/// each piece on a copy of its entries' histories, all into the same buffer.
fn chunk_pairs_keeping<const FR: bool>(
    kernel: Kernel,
    args: &ChunkArgs,
    (sh, to): (&[Hist], &[u8]),
    acc: &mut [PairSum],
    rows: usize,
) -> Stats {
    let (a, b, offsets) = (args.entries.first, args.b, args.offsets);
    let (mut sh_copy, mut to_copy) = (Vec::new(), Vec::new());
    let mut st = Stats::ZERO;
    acc.fill(PairSum::default()); // also for a chunk without rows
    for from in (a..b).step_by(rows) {
        let end = (from + rows).min(b);
        let (k0, k1) = ((offsets[from] - offsets[a]) as usize, (offsets[end] - offsets[a]) as usize);
        sh_copy.clear();
        sh_copy.extend_from_slice(&sh[k0..k1]);
        to_copy.clear();
        to_copy.extend_from_slice(&to[k0..k1]);
        st = st.max(chunk_pairs_on::<FR>(kernel, &args.rows(from, end), &mut sh_copy, &mut to_copy, acc));
    }
    st
}

/// Read-only inputs of one chunk of the pair pass: rows a..b, the entries of the half list
/// from `offsets[a]` to `offsets[b]`, and the positions, velocities and spins of the chunk's
/// window, particles a..e (rows and partners). A piece of it (`rows`) scans rows from..b only,
/// into the buffer that the pieces before it filled.
pub(crate) struct ChunkArgs<'a> {
    pub pair: PairInputs<'a>,
    pub entries: Entries<'a>,
    pub from: usize,
    pub b: usize,
    pub offsets: &'a [u32],
}

impl<'a> ChunkArgs<'a> {
    /// Chunk a..b of `p`'s pair law over the list (`offsets`, `owner`, `nbr`), window (x, v, w).
    pub fn new(
        p: &'a DemParams,
        a: usize,
        b: usize,
        offsets: &'a [u32],
        owner: &'a [u16],
        nbr: &'a [u32],
        (x, v, w): (&'a [V3], &'a [V3], &'a [V3]),
    ) -> Self {
        let (r, h) = (p.radius, p.dt);
        ChunkArgs {
            pair: PairInputs { law: &p.pair, audit: p.audit, r, h, v, w },
            entries: Entries { owner, nbr, first: a, x, d2: 4.0 * r * r },
            from: a,
            b,
            offsets,
        }
    }

    /// Rows from..b of the chunk (a ≤ from ≤ b ≤ its b), on the same window and buffer.
    pub fn rows(&self, from: usize, b: usize) -> ChunkArgs<'a> {
        assert!(self.entries.first <= from && from <= b && b <= self.b, "a piece inside the chunk");
        ChunkArgs { pair: self.pair, entries: self.entries, from, b, offsets: self.offsets }
    }
}

/// One chunk of the pair pass on the `kernel` path (the portable one when the CPU lacks it).
pub(crate) fn chunk_pairs_on<const FR: bool>(
    kernel: Kernel,
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    #[cfg(target_arch = "x86_64")]
    match kernel {
        Kernel::Avx512 => {
            if let Some(isa) = Isa::avx512() {
                // SAFETY: `isa` proves the features the function is compiled for.
                return unsafe { chunk_pairs_avx512::<FR>(isa, c, sh, to, acc) };
            }
        }
        Kernel::Avx2 => {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has the feature the function is compiled for.
                return unsafe { chunk_pairs_avx2::<FR>(c, sh, to, acc) };
            }
        }
        Kernel::Portable => {}
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = kernel;
    chunk_pairs::<FR, false>(Isa::PORTABLE, c, sh, to, acc)
}

/// # Safety
/// The CPU has avx512f, avx512vl and bmi2 (which `isa` proves).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,bmi2")]
unsafe fn chunk_pairs_avx512<const FR: bool>(
    isa: Isa<true>,
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    chunk_pairs::<FR, true>(isa, c, sh, to, acc)
}

/// # Safety
/// The CPU has avx2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn chunk_pairs_avx2<const FR: bool>(
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    chunk_pairs::<FR, false>(Isa::PORTABLE, c, sh, to, acc)
}

/// The pair pass over rows a..b: distance checks, touching pairs batched and evaluated, forces
/// added into `acc` (particles a..). Particles are read only in the window a..e, and the batch
/// lanes hold indices into it (particle − a). Every index is checked (the list may come from a
/// checkpoint): a bad one panics.
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(unused_mut, unused_variables))] // the vector path is x86-64 only
fn chunk_pairs<const FR: bool, const V: bool>(
    isa: Isa<V>,
    c: &ChunkArgs,
    sh: &mut [Hist],
    to: &mut [u8],
    acc: &mut [PairSum],
) -> Stats {
    let (e, a) = (&c.entries, c.entries.first);
    let (owner, nbr, x, d2) = (e.owner, e.nbr, e.x, e.d2);
    if c.from == a {
        acc.fill(PairSum::default()); // a later piece adds to the sums of the ones before it
    }
    let mut st = Stats::ZERO;
    let (base, end) = (c.offsets[c.from] as usize, c.offsets[c.b] as usize);
    let mut batch = Batch::new();
    // One flat loop over the chunk's entries (the row of entry k is a + owner[k]): no row loop,
    // no data-dependent branch. Every entry is written into lane m; only touching ones
    // advance m.
    let mut m = 0;
    assert!(owner.len() == nbr.len() && base <= end && end <= nbr.len(), "chunk entries");
    assert!(acc.len() == x.len() && c.pair.v.len() == x.len() && (c.pair.w.len() == x.len() || !FR), "chunk window");
    assert!(!FR || (sh.len() == end - base && to.len() == end - base), "chunk histories");
    let mut k = base;
    #[cfg(target_arch = "x86_64")]
    if let Some(avx) = isa.as_avx512() {
        while k + LANES <= end {
            if m > CAP - LANES {
                batch.m = m;
                flush::<FR, V>(isa, &mut batch, &c.pair, sh, base, acc, &mut st);
                m = 0;
            }
            m = scan8::<FR>(avx, e, k, base, to, &mut batch, m);
            k += LANES;
        }
        if m == CAP {
            batch.m = m;
            flush::<FR, V>(isa, &mut batch, &c.pair, sh, base, acc, &mut st);
            m = 0;
        }
    }
    for k in k..end {
        let (i, j) = (owner[k] as usize, nbr[k].wrapping_sub(a as u32) as usize);
        let (xi, xj) = (x[i], x[j]);
        let dx = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
        let r2 = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
        let touching = r2 < d2;
        if FR {
            // The history is live only while the pair keeps touching.
            let t = &mut to[k - base];
            batch.was[m] = *t;
            *t = touching as u8;
        }
        batch.set(m, Entry { k, i, j }, dx, r2, d2);
        m += touching as usize;
        if m == CAP {
            batch.m = m;
            flush::<FR, V>(isa, &mut batch, &c.pair, sh, base, acc, &mut st);
            m = 0;
        }
    }
    batch.m = m;
    flush::<FR, V>(isa, &mut batch, &c.pair, sh, base, acc, &mut st);
    st
}

/// Evaluate a batch and add its forces into `acc` (the chunk window, as the lane indices).
#[inline(always)]
fn flush<const FR: bool, const V: bool>(
    isa: Isa<V>,
    batch: &mut Batch,
    inp: &PairInputs,
    sh: &mut [Hist],
    base: usize,
    acc: &mut [PairSum],
    st: &mut Stats,
) {
    let (ov, ex) = evaluate::<FR, V>(isa, batch, inp, sh, base);
    st.overlap = st.overlap.max(ov);
    st.coulomb_excess = st.coulomb_excess.max(ex);
    scatter::<FR, V>(isa, batch, acc);
    batch.m = 0;
}
