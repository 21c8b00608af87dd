//! The live contact histories of a near list keyed by particle-id pair, to be carried across a
//! re-sort into the near list drawn from the new Verlet list (`NearList::select_into` with
//! `Histories::Carried`). Only live (touching) pairs are kept: about half the near list's
//! entries, 16 bytes each, instead of a history for every entry of the new Verlet list.

use super::neighbors::{Hist, NeighborList};

/// Histories by id pair: a CSR over the smaller id of (larger id, ξ oriented smaller → larger).
#[derive(Debug, Default)]
pub struct IdHistories {
    start: Vec<u32>,
    map: Vec<(u32, Hist)>,
}

impl IdHistories {
    /// The live histories of `old`, whose row i is the particle with id `old_ids[i]`. Empty
    /// when `old` is not a list of these particles (none yet).
    pub fn of(old: &NeighborList, old_ids: &[u32]) -> IdHistories {
        let n = old_ids.len();
        if old.offsets.len() != n + 1 {
            return IdHistories::default();
        }
        let mut start = vec![0u32; n + 2];
        let mut entries = Vec::new();
        for i in 0..n {
            for k in old.offsets[i] as usize..old.offsets[i + 1] as usize {
                if old.touch[k] == 0 {
                    continue;
                }
                let (a, b, s) = (old_ids[i], old_ids[old.nbr[k] as usize], old.shear[k]);
                let (lo, hi, s) = if a < b { (a, b, s) } else { (b, a, s.map(|c| -c)) };
                start[lo as usize + 2] += 1;
                entries.push((lo, hi, s));
            }
        }
        if entries.is_empty() {
            return IdHistories::default();
        }
        for i in 0..n {
            start[i + 2] += start[i + 1];
        }
        // start[lo + 1] is the next free place of row lo while filling; start[lo] its start after.
        let mut map = vec![(0u32, [0.0f32; 3]); entries.len()];
        for (lo, hi, s) in entries {
            let slot = &mut start[lo as usize + 1];
            map[*slot as usize] = (hi, s);
            *slot += 1;
        }
        start.pop();
        IdHistories { start, map }
    }

    /// The history of the pair of ids (a, b), oriented a → b, if it was live.
    #[inline]
    pub fn get(&self, a: u32, b: u32) -> Option<Hist> {
        if self.map.is_empty() {
            return None;
        }
        let (lo, hi, sign) = if a < b { (a, b, 1.0f32) } else { (b, a, -1.0) };
        let row = &self.map[self.start[lo as usize] as usize..self.start[lo as usize + 1] as usize];
        row.iter().find(|e| e.0 == hi).map(|e| e.1.map(|c| sign * c))
    }
}
