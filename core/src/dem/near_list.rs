//! The near list: the entries of the Verlet list whose gap (centre distance − d) was below a
//! small `gap` at its last refresh, or whose contact history is live, kept in the Verlet list's
//! order. The pair pass walks it instead of the whole list (5.3 entries per particle in the
//! settled bed, 3.1 within 0.03 d), and its contact histories are stored with it.
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

impl NearList {
    /// Copy the histories and touch flags back into `outer` (the list this one was drawn from).
    /// Entries of `outer` that were left out keep flag 0: they were not touching when left out
    /// and cannot have touched since.
    pub fn write_back(&self, outer: &mut NeighborList) {
        for (e, &k) in self.src.iter().enumerate() {
            outer.shear[k as usize] = self.list.shear[e];
            outer.touch[k as usize] = self.list.touch[e];
        }
    }

    /// The entries of `outer` with gap < `gap` at positions `x`, or with a live history (whose
    /// history and flag come along), in `outer`'s order.
    pub fn select(outer: &NeighborList, x: &[V3], diameter: f64, gap: f64) -> NearList {
        let n = outer.offsets.len().saturating_sub(1);
        assert!(x.len() == n, "one position per list row");
        let reach2 = (diameter + gap) * (diameter + gap);
        let blocks: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let (a, e) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
                let mut counts = Vec::with_capacity(e - a);
                let mut src = Vec::new();
                for i in a..e {
                    let before = src.len();
                    let xi = x[i];
                    for k in outer.offsets[i] as usize..outer.offsets[i + 1] as usize {
                        let xj = x[outer.nbr[k] as usize];
                        let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                        if r2 < reach2 || outer.touch[k] != 0 {
                            src.push(k as u32);
                        }
                    }
                    counts.push((src.len() - before) as u32);
                }
                (counts, src)
            })
            .collect();
        let total: usize = blocks.iter().map(|b| b.1.len()).sum();
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0u32);
        let mut src = Vec::with_capacity(total);
        for (counts, s) in blocks {
            for c in counts {
                offsets.push(offsets.last().unwrap() + c);
            }
            src.extend_from_slice(&s);
        }
        let pick = |k: &u32| *k as usize;
        let list = NeighborList {
            offsets,
            nbr: src.iter().map(|k| outer.nbr[pick(k)]).collect(),
            shear: src.iter().map(|k| outer.shear[pick(k)]).collect(),
            touch: src.iter().map(|k| outer.touch[pick(k)]).collect(),
        };
        NearList { list, src }
    }
}
