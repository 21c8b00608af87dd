//! The near list: the entries of the Verlet list whose gap (centre distance − d) was below a
//! small `gap` at its last refresh, or whose contact history is live, kept in the Verlet list's
//! order. The pair pass walks it instead of the whole list (5.3 entries per particle in the
//! settled bed, 2.5 of them touching), and the live contact histories are stored with it: a
//! refresh takes them from the previous near list (in its own storage, `near_refresh`), a
//! Verlet-list build from the live histories carried by particle id (`id_histories`).
//!
//! Validity: while no particle has moved more than gap/2 since the refresh, a pair left out
//! (gap ≥ `gap` then) cannot touch. At a refresh the Verlet list must hold every pair closer than
//! d + gap, which it does while no particle has moved more than (skin − gap)/2 since its build;
//! `DemSystem` rebuilds it otherwise. Because the entries keep their order, the touching pairs
//! reach the contact kernel in the same order as from the whole list: in one work chunk, the same
//! forces bit for bit (the chunk split follows the entry counts, so with several chunks the force
//! sums may group differently and differ in rounding).

use super::contact::V3;
use super::id_histories::IdHistories;
use super::neighbors::NeighborList;
use super::verlet_list::ListRows;
use crate::buffers::resize_reused;
use rayon::prelude::*;

/// Rows per work block of a refresh (fixed, so results do not depend on the thread count).
const BLOCK: usize = 1024;

/// The near list. Each entry is matched to the Verlet list's by its partner within the row (a
/// row lists each partner once, and the near row is a subsequence of the Verlet row).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct NearList {
    pub list: NeighborList,
    /// Where checkpoints of earlier builds kept each entry's Verlet-list entry: read and
    /// dropped, written empty, so that those checkpoints still resume.
    retired_src: Retired,
}

/// A field of earlier checkpoints: a list of u32 (written empty, read and dropped).
#[derive(Clone, Debug, Default)]
struct Retired;

impl serde::Serialize for Retired {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(std::iter::empty::<u32>())
    }
}

impl<'de> serde::Deserialize<'de> for Retired {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Retired, D::Error> {
        <Vec<u32> as serde::Deserialize>::deserialize(d).map(|_| Retired)
    }
}

/// A selection code: the list entry is left out, kept (with the list's history, if any), or
/// kept with the history of the old near entry of the same partner.
pub(super) const SKIP: u8 = 0;
pub(super) const TAKE: u8 = 1;
pub(super) const TAKE_OLD: u8 = 2;

/// Where the contact histories of a selection come from.
#[derive(Clone, Copy)]
pub enum Histories<'a> {
    /// The live histories of the near list before a re-sort, by particle id (`ids`: the id of
    /// each row now).
    Carried(&'a IdHistories, &'a [u32]),
    /// The near list drawn from the same Verlet list before (matched by entry); runs refresh
    /// in place instead (`near_refresh`), tested against this.
    #[cfg_attr(not(test), allow(dead_code))]
    Near(&'a NearList),
}

impl NearList {
    /// The entries of `outer` with gap < `gap` at positions `x`, or with a live history (whose
    /// history and flag come along), in `outer`'s order.
    #[cfg(test)]
    pub fn select(outer: &impl ListRows, x: &[V3], diameter: f64, gap: f64, hist: Histories) -> NearList {
        let mut out = NearList::default();
        out.select_into(outer, x, diameter, gap, hist);
        out
    }

    /// `select` into this list's storage (its old contents are dropped; reusing the memory
    /// spares the page faults of fresh allocations). A selection code per entry of `outer`, held
    /// only while it runs (a byte per Verlet-list entry): `SKIP`, `TAKE` (with `outer`'s
    /// history; none under `Histories::Near`) or `TAKE_OLD` (with the history of the old near
    /// entry of the same partner, found again in sweep 2 by walking the old row beside the list
    /// row). Two parallel sweeps: codes and row offsets, then the rows copied into place.
    pub fn select_into(&mut self, outer: &impl ListRows, x: &[V3], diameter: f64, gap: f64, hist: Histories) {
        let off_in = outer.offsets();
        let n = off_in.len().saturating_sub(1);
        let total_in = outer.entries();
        assert!(x.len() == n, "one position per list row");
        assert!(off_in.last().is_none_or(|&o| o as usize == total_in), "list offsets");
        let empty = NearList::default();
        let (old, carried) = match hist {
            Histories::Near(old) => {
                assert!(old.list.offsets.len() == n + 1, "near list of another list");
                (old, None)
            }
            Histories::Carried(h, ids) => {
                assert!(ids.len() == n, "one id per list row");
                (&empty, Some((h, ids)))
            }
        };
        let from_old = matches!(hist, Histories::Near(_));
        let (code, new_off) = select_codes(outer, x, diameter, gap, hist);
        // Sweep 2: each block's kept entries copied into its part of the storage.
        let l = &mut self.list;
        l.offsets = new_off;
        let total = l.offsets[n] as usize;
        resize_reused(&mut l.nbr, total, 0);
        resize_reused(&mut l.shear, total, [0.0; 3]);
        resize_reused(&mut l.touch, total, 0);
        let offsets = &l.offsets;
        let blocks = blocks_of(n);
        let mut work = Vec::with_capacity(blocks.len());
        let (mut j, mut h, mut t) = (&mut l.nbr[..], &mut l.shear[..], &mut l.touch[..]);
        for r in blocks {
            let len = (offsets[r.end] - offsets[r.start]) as usize;
            let (j0, j1) = std::mem::take(&mut j).split_at_mut(len);
            let (h0, h1) = std::mem::take(&mut h).split_at_mut(len);
            let (t0, t1) = std::mem::take(&mut t).split_at_mut(len);
            (j, h, t) = (j1, h1, t1);
            work.push((r, j0, h0, t0));
        }
        let code = &code[..];
        work.into_par_iter().for_each(|(rows, nbr, shear, touch)| {
            let mut e = 0;
            for i in rows {
                // Cursor over the old near row i, as in sweep 1.
                let (mut p, p_end) =
                    if from_old { (old.list.offsets[i] as usize, old.list.offsets[i + 1] as usize) } else { (0, 0) };
                let row = off_in[i] as usize..off_in[i + 1] as usize;
                for (k, &c) in row.clone().zip(&code[row]) {
                    let j = outer.partner(i, k);
                    let matched = p < p_end && old.list.nbr[p] == j;
                    if c != SKIP {
                        let (sh, to) = match (c, carried) {
                            (TAKE, Some((h, ids))) => h.get(ids[i], ids[j as usize]).map_or(([0.0; 3], 0), |s| (s, 1)),
                            (TAKE, None) => ([0.0; 3], 0),
                            _ => (old.list.shear[p], old.list.touch[p]),
                        };
                        (nbr[e], shear[e], touch[e]) = (j, sh, to);
                        e += 1;
                    }
                    p += matched as usize;
                }
            }
        });
    }
}

/// The row blocks of a selection's sweeps.
pub(super) fn blocks_of(n: usize) -> Vec<std::ops::Range<usize>> {
    (0..n.div_ceil(BLOCK)).map(|b| b * BLOCK..((b + 1) * BLOCK).min(n)).collect()
}

/// Sweep 1 of a selection, in parallel blocks: a code per entry of `outer` (`SKIP`,
/// `TAKE`, or `TAKE_OLD` where the old near list of `hist` has the entry), and the offsets of the
/// new list's rows (the kept entries counted, then summed in place). Reads the old near list only.
pub(super) fn select_codes(
    outer: &impl ListRows,
    x: &[V3],
    diameter: f64,
    gap: f64,
    hist: Histories,
) -> (Vec<u8>, Vec<u32>) {
    let (old, carried) = match hist {
        Histories::Near(old) => (Some(old), None),
        Histories::Carried(h, ids) => (None, Some((h, ids))),
    };
    let off = outer.offsets();
    let n = off.len().saturating_sub(1);
    let reach2 = (diameter + gap) * (diameter + gap);
    let mut code = vec![0u8; outer.entries()];
    // Each row's kept entries at its end, summed into offsets below.
    let mut offsets = vec![0u32; n + 1];
    let blocks = blocks_of(n);
    let entries = |r: &std::ops::Range<usize>| off[r.start] as usize..off[r.end] as usize;
    let mut work = Vec::with_capacity(blocks.len());
    let (mut crest, mut nrest) = (&mut code[..], &mut offsets[1..]);
    for r in &blocks {
        let (c0, c1) = std::mem::take(&mut crest).split_at_mut(entries(r).len());
        let (n0, n1) = std::mem::take(&mut nrest).split_at_mut(r.len());
        (crest, nrest) = (c1, n1);
        work.push((r.clone(), c0, n0));
    }
    work.into_par_iter().for_each(|(r, codes, cnt)| {
        let base = off[r.start] as usize;
        for i in r.clone() {
            let xi = x[i];
            // Cursor over the old near row i, a subsequence of the list row.
            let (mut p, p_end) = match old {
                Some(old) => (old.list.offsets[i] as usize, old.list.offsets[i + 1] as usize),
                None => (0, 0),
            };
            for k in off[i] as usize..off[i + 1] as usize {
                let j = outer.partner(i, k);
                let matched = p < p_end && old.is_some_and(|o| o.list.nbr[p] == j);
                let live = match (old, carried) {
                    (Some(o), _) => matched && o.list.touch[p] != 0,
                    (None, Some((h, ids))) => h.get(ids[i], ids[j as usize]).is_some(),
                    (None, None) => false,
                };
                let xj = x[j as usize];
                let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                let take = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach2 || live;
                let c = if matched { TAKE_OLD } else { TAKE };
                codes[k - base] = if take { c } else { SKIP };
                cnt[i - r.start] += take as u32;
                p += matched as usize;
            }
            assert!(p == p_end, "old near row {i} is not a subsequence of the list row");
        }
    });
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    (code, offsets)
}
