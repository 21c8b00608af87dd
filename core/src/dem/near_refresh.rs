//! The near list redrawn from the same Verlet list in its own storage (`NearList::refresh`):
//! what `select_into` with `Histories::Near` gives, entry for entry, without a second list. A
//! second list would be the largest buffer of a run that is not the state itself (70 B per
//! particle of about 600, docs/BENCHMARKS.md "Scaling").
//!
//! Each new row i is made from old row i and Verlet row i alone, so the rows can be moved in
//! place. Row i is read into a small buffer, then written to its new place [N_i, N_{i+1}); any
//! old entry there of a row not yet read (at or past O_{i+1}) is first queued, in order, and the
//! rows read from the queue before the storage. The queue holds at most the largest growth of the
//! list up to a row. The rows are cut into parts done in parallel, each writing only its new range
//! [N_a, N_b): the old entries of a part that another part's range covers (the head [O_a, N_a)
//! when the part moved right, the tail [N_b, O_b) when the next part moved left) are copied out
//! before the parts start.

use super::contact::V3;
use super::near_list::{select_codes, Histories, NearList, SKIP, TAKE};
use super::neighbors::Hist;
use super::verlet_list::ListRows;
use rayon::prelude::*;
use std::collections::VecDeque;

/// A near-list entry: partner, contact history, touch flag.
type Entry = (u32, Hist, u8);

/// Rows per part of a refresh (fixed, so that results do not depend on the thread count; they
/// do not depend on the parts either).
const PART_ROWS: usize = 16 * 1024;

/// The storage of one part: its new range of the list's arrays, starting at entry `base`.
struct PartStore<'a> {
    base: usize,
    nbr: &'a mut [u32],
    shear: &'a mut [Hist],
    touch: &'a mut [u8],
}

impl PartStore<'_> {
    fn get(&self, p: usize) -> Entry {
        let e = p - self.base;
        (self.nbr[e], self.shear[e], self.touch[e])
    }
    fn set(&mut self, p: usize, (j, h, t): Entry) {
        let e = p - self.base;
        (self.nbr[e], self.shear[e], self.touch[e]) = (j, h, t);
    }
}

/// One part's rows [a, b) and the old entries copied out for it.
struct Part<'a> {
    rows: std::ops::Range<usize>,
    store: PartStore<'a>,
    /// Old entries [O_a, N_a), when the previous part's range covers them.
    head: Vec<Entry>,
    /// Old entries [N_b, O_b) (from `tail_start` = N_b), when the next part's range covers them.
    tail: Vec<Entry>,
    tail_start: usize,
}

impl NearList {
    /// Redraw this list, drawn from `outer` before, from `outer` at positions `x` in its own
    /// storage: the same entries, histories and flags as `select_into` with `Histories::Near`.
    pub fn refresh(&mut self, outer: &impl ListRows, x: &[V3], diameter: f64, gap: f64) {
        self.refresh_in_parts(outer, x, diameter, gap, PART_ROWS);
    }

    /// `refresh` with parts of `part_rows` rows (tests cut small parts).
    pub(super) fn refresh_in_parts(
        &mut self,
        outer: &impl ListRows,
        x: &[V3],
        diameter: f64,
        gap: f64,
        part_rows: usize,
    ) {
        let n = outer.offsets().len().saturating_sub(1);
        assert!(x.len() == n && self.list.offsets.len() == n + 1, "near list of another list");
        // A selection code per Verlet-list entry, held only while the refresh runs.
        let (code, new_off) = select_codes(outer, x, diameter, gap, Histories::Near(self));
        let l = &mut self.list;
        let old_off = std::mem::take(&mut l.offsets);
        let new_total = new_off[n] as usize;
        let parts = part_cuts(&old_off, &new_off, part_rows);
        // Old entries that another part's range covers, copied out while nothing has moved.
        let copy =
            |r: std::ops::Range<usize>| -> Vec<Entry> { r.map(|p| (l.nbr[p], l.shear[p], l.touch[p])).collect() };
        let saved: Vec<(Vec<Entry>, Vec<Entry>)> = parts
            .iter()
            .map(|r| {
                let (oa, na, ob, nb) = (old_off[r.start], new_off[r.start], old_off[r.end], new_off[r.end]);
                let head = if na > oa { copy(oa as usize..na as usize) } else { Vec::new() };
                let tail = if nb < ob { copy(nb as usize..ob as usize) } else { Vec::new() };
                (head, tail)
            })
            .collect();
        grow_keeping(&mut l.nbr, new_total, 0);
        grow_keeping(&mut l.shear, new_total, [0.0; 3]);
        grow_keeping(&mut l.touch, new_total, 0);
        let mut work = Vec::with_capacity(parts.len());
        let (mut j, mut h, mut t) = (&mut l.nbr[..], &mut l.shear[..], &mut l.touch[..]);
        for (r, (head, tail)) in parts.into_iter().zip(saved) {
            let len = (new_off[r.end] - new_off[r.start]) as usize;
            let (j0, j1) = std::mem::take(&mut j).split_at_mut(len);
            let (h0, h1) = std::mem::take(&mut h).split_at_mut(len);
            let (t0, t1) = std::mem::take(&mut t).split_at_mut(len);
            (j, h, t) = (j1, h1, t1);
            let store = PartStore { base: new_off[r.start] as usize, nbr: j0, shear: h0, touch: t0 };
            let tail_start = new_off[r.end] as usize;
            work.push(Part { rows: r, store, head, tail, tail_start });
        }
        let code = &code[..];
        work.into_par_iter().for_each(|part| redraw_part(part, outer, code, &old_off, &new_off));
        l.nbr.truncate(new_total);
        l.shear.truncate(new_total);
        l.touch.truncate(new_total);
        l.offsets = new_off;
    }
}

/// Rows cut into parts of `part_rows`, merged where a part's head or tail copy would reach past
/// its own old entries (a shift larger than a part: one part then, done in order).
fn part_cuts(old_off: &[u32], new_off: &[u32], part_rows: usize) -> Vec<std::ops::Range<usize>> {
    let n = old_off.len() - 1;
    let mut cuts: Vec<usize> = (0..n.div_ceil(part_rows).max(1)).map(|k| k * part_rows).collect();
    cuts.push(n);
    let fits = |cuts: &[usize]| {
        cuts.windows(2).all(|w| {
            let (oa, na, ob, nb) = (old_off[w[0]], new_off[w[0]], old_off[w[1]], new_off[w[1]]);
            na <= ob && nb >= oa
        })
    };
    if !fits(&cuts) {
        cuts = vec![0, n];
    }
    cuts.windows(2).map(|w| w[0]..w[1]).collect()
}

/// The rows of one part moved to their new places (module comment).
fn redraw_part(mut part: Part, outer: &impl ListRows, code: &[u8], old_off: &[u32], new_off: &[u32]) {
    let r = part.rows.clone();
    let (oa, na) = (old_off[r.start] as usize, new_off[r.start] as usize);
    let own_end = old_off[r.end] as usize;
    // Old entries [O_a, saved) are in the queue, in order.
    let mut queue: VecDeque<Entry> = std::mem::take(&mut part.head).into();
    let mut saved = oa.max(na.min(own_end));
    let (mut old_row, mut new_row): (Vec<Entry>, Vec<Entry>) = (Vec::new(), Vec::new());
    for i in r {
        let (o_lo, o_hi) = (old_off[i] as usize, old_off[i + 1] as usize);
        old_row.clear();
        for p in o_lo..o_hi {
            let e = if p < saved {
                queue.pop_front().expect("queued old entry")
            } else if p >= part.tail_start {
                part.tail[p - part.tail_start]
            } else {
                part.store.get(p)
            };
            old_row.push(e);
        }
        // The new row, as `select_into`'s sweep 2 makes it from the old one.
        new_row.clear();
        let mut q = 0;
        let row = outer.offsets()[i] as usize..outer.offsets()[i + 1] as usize;
        for (k, &c) in row.clone().zip(&code[row]) {
            let j = outer.partner(i, k);
            let matched = q < old_row.len() && old_row[q].0 == j;
            if c != SKIP {
                let (sh, to) = if c == TAKE { ([0.0; 3], 0) } else { (old_row[q].1, old_row[q].2) };
                new_row.push((j, sh, to));
            }
            q += matched as usize;
        }
        let (w_lo, w_hi) = (new_off[i] as usize, new_off[i + 1] as usize);
        debug_assert_eq!(new_row.len(), w_hi - w_lo);
        // Queue the unread old entries of this part that the new row covers.
        let from = saved.max(o_hi);
        let upto = w_hi.min(own_end).min(part.tail_start);
        for p in from..upto {
            queue.push_back(part.store.get(p));
        }
        saved = from.max(upto);
        for (e, &entry) in (w_lo..w_hi).zip(&new_row) {
            part.store.set(e, entry);
        }
    }
    debug_assert!(queue.is_empty());
}

/// `v` resized to `len` keeping its contents; storage that must grow takes 1/16 more.
fn grow_keeping<T: Clone>(v: &mut Vec<T>, len: usize, fill: T) {
    if len > v.capacity() {
        v.reserve_exact(len + len / 16 - v.len());
    }
    v.resize(len.max(v.len()), fill);
}
