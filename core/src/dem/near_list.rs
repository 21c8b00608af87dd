//! The near list: the entries of the Verlet list whose gap (centre distance − d) was below a
//! small `gap` at its last refresh, or whose contact history is live, kept in the Verlet list's
//! order. The pair pass walks it instead of the whole list (5.3 entries per particle in the
//! settled bed, 2.5 of them touching), and the live contact histories are stored with it: a
//! refresh takes them from the previous near list, a Verlet-list build from the histories it
//! carried by particle id.
//!
//! Validity: while no particle has moved more than gap/2 since the refresh, a pair left out
//! (gap ≥ `gap` then) cannot touch. At a refresh the Verlet list must hold every pair closer than
//! d + gap, which it does while no particle has moved more than (skin − gap)/2 since its build;
//! `DemSystem` rebuilds it otherwise. Because the entries keep their order, the touching pairs
//! reach the contact kernel in the same order as from the whole list: in one work chunk, the same
//! forces bit for bit (the chunk split follows the entry counts, so with several chunks the force
//! sums may group differently and differ in rounding).

use super::contact::V3;
use super::neighbors::NeighborList;
use rayon::prelude::*;

/// Rows per work block of a refresh (fixed, so results do not depend on the thread count).
const BLOCK: usize = 1024;

/// The near list and, for each of its entries, the entry of the Verlet list it came from.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct NearList {
    pub list: NeighborList,
    pub src: Vec<u32>,
}

/// Where the contact histories of a selection come from.
#[derive(Clone, Copy)]
pub enum Histories<'a> {
    /// The Verlet list's own (`shear`, `touch`; right after a build, carried by id).
    Outer,
    /// The near list drawn from the same Verlet list before (matched by entry).
    Near(&'a NearList),
}

impl NearList {
    /// The entries of `outer` with gap < `gap` at positions `x`, or with a live history (whose
    /// history and flag come along), in `outer`'s order.
    pub fn select(outer: &NeighborList, x: &[V3], diameter: f64, gap: f64, hist: Histories) -> NearList {
        let mut out = NearList::default();
        out.select_into(outer, x, diameter, gap, hist, &mut Vec::new());
        out
    }

    /// `select` into this list's storage (its old contents are dropped; reusing the memory
    /// spares the page faults of fresh allocations). `keep` is scratch, one flag per entry of
    /// `outer`. Two parallel sweeps: flags and row counts, then the rows written in place.
    pub fn select_into(&mut self, outer: &NeighborList, x: &[V3], diameter: f64, gap: f64, hist: Histories, keep: &mut Vec<u8>) {
        let n = outer.offsets.len().saturating_sub(1);
        assert!(x.len() == n && outer.shear.len() == outer.nbr.len() && outer.touch.len() == outer.nbr.len(), "list shape");
        let old = match hist {
            Histories::Near(old) => {
                assert!(old.list.offsets.len() == n + 1 && old.src.len() == old.list.nbr.len(), "near list of another list");
                Some(old)
            }
            Histories::Outer => None,
        };
        let reach2 = (diameter + gap) * (diameter + gap);
        // Old near entry matching list entry k of row i (a cursor per row: the old row is a
        // subsequence of the list row).
        let cursor = |i: usize| old.map_or(0, |o| o.list.offsets[i] as usize);
        let matches = |p: usize, i: usize, k: usize| old.is_some_and(|o| p < o.list.offsets[i + 1] as usize && o.src[p] as usize == k);
        keep.clear();
        keep.resize(outer.nbr.len(), 0);
        let mut counts = vec![0u32; n];
        let rows = |b: usize| b * BLOCK..((b + 1) * BLOCK).min(n);
        let entries = |r: &std::ops::Range<usize>| outer.offsets[r.start] as usize..outer.offsets[r.end] as usize;
        let blocks: Vec<_> = (0..n.div_ceil(BLOCK)).map(rows).collect();
        // Sweep 1: flags and counts.
        let mut kb = Vec::with_capacity(blocks.len());
        let (mut krest, mut crest) = (&mut keep[..], &mut counts[..]);
        for r in &blocks {
            let (k0, k1) = std::mem::take(&mut krest).split_at_mut(entries(r).len());
            let (c0, c1) = std::mem::take(&mut crest).split_at_mut(r.len());
            (krest, crest) = (k1, c1);
            kb.push((r.clone(), k0, c0));
        }
        kb.into_par_iter().for_each(|(r, kf, cnt)| {
            let base = outer.offsets[r.start] as usize;
            for i in r.clone() {
                let (xi, mut p) = (x[i], cursor(i));
                for k in outer.offsets[i] as usize..outer.offsets[i + 1] as usize {
                    let live = match old {
                        None => outer.touch[k] != 0,
                        Some(o) if matches(p, i, k) => {
                            p += 1;
                            o.list.touch[p - 1] != 0
                        }
                        Some(_) => false,
                    };
                    let xj = x[outer.nbr[k] as usize];
                    let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                    let take = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach2 || live;
                    kf[k - base] = take as u8;
                    cnt[i - r.start] += take as u32;
                }
                assert!(old.is_none_or(|o| p == o.list.offsets[i + 1] as usize), "old near row {i} is not a subsequence of the list row");
            }
        });
        // Offsets, then sweep 2: each block's rows written into its part of the storage.
        let l = &mut self.list;
        l.offsets.clear();
        l.offsets.push(0);
        for c in &counts {
            l.offsets.push(l.offsets.last().unwrap() + c);
        }
        let total = l.offsets[n] as usize;
        self.src.resize(total, 0);
        l.nbr.resize(total, 0);
        l.shear.resize(total, [0.0; 3]);
        l.touch.resize(total, 0);
        let offsets = &l.offsets;
        let mut work = Vec::with_capacity(blocks.len());
        let (mut s, mut j, mut h, mut t) = (&mut self.src[..], &mut l.nbr[..], &mut l.shear[..], &mut l.touch[..]);
        for r in blocks {
            let len = (offsets[r.end] - offsets[r.start]) as usize;
            let (s0, s1) = std::mem::take(&mut s).split_at_mut(len);
            let (j0, j1) = std::mem::take(&mut j).split_at_mut(len);
            let (h0, h1) = std::mem::take(&mut h).split_at_mut(len);
            let (t0, t1) = std::mem::take(&mut t).split_at_mut(len);
            (s, j, h, t) = (s1, j1, h1, t1);
            work.push((r, s0, j0, h0, t0));
        }
        let keep = &keep[..];
        work.into_par_iter().for_each(|(r, src, nbr, shear, touch)| {
            let mut e = 0;
            for i in r {
                let mut p = cursor(i);
                for k in outer.offsets[i] as usize..outer.offsets[i + 1] as usize {
                    let (sh, to) = match old {
                        None => (outer.shear[k], outer.touch[k]),
                        Some(o) if matches(p, i, k) => {
                            p += 1;
                            (o.list.shear[p - 1], o.list.touch[p - 1])
                        }
                        Some(_) => ([0.0; 3], 0),
                    };
                    if keep[k] != 0 {
                        (src[e], nbr[e], shear[e], touch[e]) = (k as u32, outer.nbr[k], sh, to);
                        e += 1;
                    }
                }
            }
        });
    }
}

