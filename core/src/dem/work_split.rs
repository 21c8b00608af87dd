//! The work split of the pair pass (`Scratch`): contiguous particle chunks of about equal work,
//! each with a private force buffer, planned once per neighbour-list build. A checkpoint carries
//! the plan's cuts, so that a restored run sums its pair forces in the same order.

use super::neighbors::NeighborList;
use super::pair_scatter::PairSum;
use crate::buffers::resize_reused;
use rayon::prelude::*;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Extra work units of a touching pair over a listed one in the chunk cuts. Timed per thread
/// on the settled bench bed (docs/BENCHMARKS.md, "Sharing the work"): weights 0 / 2 / 4 left
/// the first of two threads 7% slower / 1% slower / 5% faster in the pair pass.
const TOUCH_WEIGHT: usize = 2;

/// Rows per chunk at most, so that an entry's row within its chunk fits in 16 bits (`owner`).
pub(crate) const MAX_CHUNK_ROWS: usize = 1 << 16;

/// Work split of the pair pass: contiguous particle chunks [a, b), each accumulating its pair
/// forces (on i and on j) into a private buffer covering particles [a, e), e = 1 + the largest
/// partner index of the chunk. The cuts depend on the list, its touch flags when planned and the
/// chunk count, and the buffers are summed in chunk order, so a run is bit-reproducible for a
/// given chunk count as long as a plan lives until the list changes — through a checkpoint too
/// (the flags have changed since the plan was made, so a new plan could cut elsewhere).
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// Per chunk: a, b, e.
    pub bounds: Vec<[usize; 3]>,
    /// Start of each chunk's buffer in `acc`.
    pub start: Vec<usize>,
    pub acc: Vec<PairSum>,
    /// Row (first particle) of every list entry, less its chunk's first row.
    pub owner: Vec<u16>,
    /// The chunk count the plan was made for.
    chunks: usize,
    /// A restored plan (its chunk count and cuts), taken by the next `replan` for that count.
    carried: Option<CarriedPlan>,
}

/// What a checkpoint holds of a plan: the chunk count asked for and the nc + 1 cuts.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct CarriedPlan {
    chunks: usize,
    cuts: Vec<usize>,
}

impl Serialize for Scratch {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let live = (!self.bounds.is_empty()).then(|| CarriedPlan { chunks: self.chunks, cuts: self.cuts() });
        live.or_else(|| self.carried.clone()).serialize(s)
    }
}

impl<'de> Deserialize<'de> for Scratch {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Scratch, D::Error> {
        Ok(Scratch { carried: Option::deserialize(d)?, ..Scratch::default() })
    }
}

/// The chunk buffers as the particle pass reads them: a read-only view that hands out only the
/// rows asked for (`rows`), so that in the team step a block can read the buffers of finished
/// chunks while other chunks still write theirs.
#[derive(Clone, Copy)]
pub struct Sums<'a> {
    pub bounds: &'a [[usize; 3]],
    start: &'a [usize],
    acc: *const PairSum,
    len: usize,
    life: std::marker::PhantomData<&'a [PairSum]>,
}

// SAFETY: a read-only view; `Sums::new` borrows the buffers, `Sums::from_raw`'s caller keeps
// every row read through it unwritten while it is read.
unsafe impl Send for Sums<'_> {}
unsafe impl Sync for Sums<'_> {}

impl<'a> Sums<'a> {
    pub fn new(bounds: &'a [[usize; 3]], start: &'a [usize], acc: &'a [PairSum]) -> Self {
        // SAFETY: `acc` is borrowed (shared) for 'a.
        unsafe { Self::from_raw(bounds, start, acc.as_ptr(), acc.len()) }
    }

    /// # Safety
    /// `acc` points to `len` buffers rows valid for 'a, and no row read through `rows` is
    /// written while the returned slice lives.
    pub unsafe fn from_raw(bounds: &'a [[usize; 3]], start: &'a [usize], acc: *const PairSum, len: usize) -> Self {
        assert!(
            start.len() > bounds.len() && bounds.iter().zip(start).all(|(&[a, _, e], &s)| s + e - a <= len),
            "chunk buffers"
        );
        Sums { bounds, start, acc, len, life: std::marker::PhantomData }
    }

    /// Chunk c's buffer rows of particles s..t (within its window a..e).
    pub fn rows(&self, c: usize, s: usize, t: usize) -> &'a [PairSum] {
        let [a, _, e] = self.bounds[c];
        assert!(a <= s && s <= t && t <= e, "rows {s}..{t} outside chunk window {a}..{e}");
        let lo = self.start[c] + s - a;
        assert!(lo + t - s <= self.len);
        // SAFETY: in bounds (checked in `from_raw` and above); not written meanwhile (contract).
        unsafe { std::slice::from_raw_parts(self.acc.add(lo), t - s) }
    }
}

impl Scratch {
    pub fn sums(&self) -> Sums<'_> {
        Sums::new(&self.bounds, &self.start, &self.acc)
    }

    /// Plan `chunks` chunks (fewer for small systems) over the list.
    #[cfg(test)]
    pub fn plan(nl: &NeighborList, n: usize, chunks: usize) -> Scratch {
        let mut sc = Scratch::default();
        sc.replan(nl, n, chunks);
        sc
    }

    /// The chunk boundaries: a of each chunk, then b of the last.
    fn cuts(&self) -> Vec<usize> {
        let last = self.bounds.last().map(|b| b[1]);
        self.bounds.iter().map(|b| b[0]).chain(last).collect()
    }

    /// `plan` in this scratch's storage (reused: no fresh pages for the buffers); a plan carried
    /// through a checkpoint for this chunk count and list length is kept.
    pub fn replan(&mut self, nl: &NeighborList, n: usize, chunks: usize) {
        // The pair pass indexes without bounds checks: check the list once here (it may come
        // from a checkpoint) — rows ascending within 0..n, histories and flags one per entry.
        let total = nl.nbr.len();
        assert!(
            nl.offsets.len() == n + 1 && nl.offsets[0] == 0 && nl.offsets[n] as usize == total,
            "neighbour list shape"
        );
        assert!(nl.offsets.windows(2).all(|o| o[0] <= o[1]), "neighbour list offsets");
        assert!(nl.shear.len() == total && nl.touch.len() == total, "contact history length");
        let carried = self.carried.take().filter(|p| p.chunks == chunks && p.cuts.last() == Some(&n));
        let cuts = match carried {
            Some(p) => p.cuts,
            None => Self::balanced_cuts(nl, n, chunks),
        };
        self.plan_at(nl, n, &rows_capped(cuts));
        self.chunks = chunks;
    }

    /// Cuts of about equal work.
    fn balanced_cuts(nl: &NeighborList, n: usize, chunks: usize) -> Vec<usize> {
        let nc = chunks.clamp(1, n.div_ceil(512).max(1));
        // Chunk c ends where the work reaches (c+1)/nc of the total, so that the chunks take
        // about the same time: one unit per particle and per list entry, TOUCH_WEIGHT more per
        // pair that touched in the last step (the flags; all zero before the first step).
        let mut touched = vec![0usize; n + 1];
        touched[1..].par_iter_mut().enumerate().for_each(|(i, t)| {
            *t = nl.touch[nl.offsets[i] as usize..nl.offsets[i + 1] as usize].iter().map(|&f| f as usize).sum();
        });
        for i in 0..n {
            touched[i + 1] += touched[i];
        }
        let work = |i: usize| nl.offsets[i] as usize + i + TOUCH_WEIGHT * touched[i];
        let cut = |c: usize| {
            let (mut lo, mut hi) = (0, n);
            while lo < hi {
                let mid = (lo + hi) / 2;
                if work(mid) * nc < c * work(n) {
                    lo = mid + 1
                } else {
                    hi = mid
                }
            }
            lo
        };
        (0..=nc).map(cut).collect()
    }

    /// The plan of chunks [cuts[c], cuts[c + 1]), none longer than `MAX_CHUNK_ROWS`.
    fn plan_at(&mut self, nl: &NeighborList, n: usize, cuts: &[usize]) {
        let (total, nc) = (nl.nbr.len(), cuts.len() - 1);
        let ordered = cuts.windows(2).all(|c| c[0] <= c[1] && c[1] - c[0] <= MAX_CHUNK_ROWS);
        assert!(cuts[0] == 0 && cuts[nc] == n && ordered, "chunk cuts {cuts:?}");
        let cut = |c: usize| cuts[c];
        let (mut acc, mut owner) = (std::mem::take(&mut self.acc), std::mem::take(&mut self.owner));
        resize_reused(&mut owner, total, 0);
        // Per chunk, in parallel: check every partner (i < j < n), find the halo end e, and
        // write each entry's row.
        let mut parts = Vec::with_capacity(nc);
        let mut rest = &mut owner[..];
        for c in 0..nc {
            let (a, b) = (cut(c), cut(c + 1));
            let (o, r) = std::mem::take(&mut rest).split_at_mut((nl.offsets[b] - nl.offsets[a]) as usize);
            rest = r;
            parts.push((a, b, o));
        }
        let bounds: Vec<[usize; 3]> = parts
            .into_par_iter()
            .map(|(a, b, own)| {
                let (mut e, base) = (b, nl.offsets[a] as usize);
                for i in a..b {
                    let (k0, k1) = (nl.offsets[i] as usize, nl.offsets[i + 1] as usize);
                    for (k, &j) in (k0..k1).zip(&nl.nbr[k0..k1]) {
                        assert!(j as usize > i && (j as usize) < n, "half list holds i < j < n only");
                        e = e.max(j as usize + 1);
                        own[k - base] = (i - a) as u16;
                    }
                }
                [a, b, e]
            })
            .collect();
        let mut start = Vec::with_capacity(nc + 1);
        start.push(0);
        for (c, &[a, _, e]) in bounds.iter().enumerate() {
            start.push(start[c] + e - a);
        }
        // Rows kept from the last plan are not cleared: each chunk zeroes its rows before its
        // pass (`forces::chunk_pairs`), and nothing reads them before that.
        resize_reused(&mut acc, start[nc], PairSum::default());
        (self.bounds, self.start, self.acc, self.owner) = (bounds, start, acc, owner);
    }
}

/// `cuts` with every chunk longer than `MAX_CHUNK_ROWS` rows cut into equal parts that are not
/// (a plan of a bed past 4 × 65,536 particles, or one from a checkpoint).
fn rows_capped(cuts: Vec<usize>) -> Vec<usize> {
    let mut out = vec![cuts[0]];
    for c in cuts.windows(2) {
        let parts = (c[1] - c[0]).div_ceil(MAX_CHUNK_ROWS).max(1); // an empty chunk stays one
        out.extend((1..=parts).map(|p| c[0] + (c[1] - c[0]) * p / parts));
    }
    out
}
