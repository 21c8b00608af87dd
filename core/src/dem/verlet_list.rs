//! The Verlet list as the DEM keeps it between builds: the rows of `build_rows` (partners j > i,
//! CSR) with each partner stored as j − i in 16 bits when every row's partners lie within 65,535
//! rows of it, else as the plain u32. The cell order puts a particle's partners within about two
//! layers of linked cells (about 13,000 rows in a 205k-particle bed), so 2 B per entry instead of
//! 4: the list is read only when the near list is drawn from it (`ListRows`), never by the pair
//! pass. A checkpoint holds the plain list's shape (`NeighborList`), so checkpoints of either
//! form resume.

use super::neighbors::{build_rows, Hist, NeighborList, BLOCK};
use rayon::prelude::*;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// CSR rows of partners, as the near list's selection reads them.
pub trait ListRows: Sync {
    /// Row i is entries offsets[i]..offsets[i + 1].
    fn offsets(&self) -> &[u32];
    /// The partner of entry k, in row i.
    fn partner(&self, i: usize, k: usize) -> u32;
    fn entries(&self) -> usize;
}

impl ListRows for NeighborList {
    fn offsets(&self) -> &[u32] {
        &self.offsets
    }
    #[inline(always)]
    fn partner(&self, _i: usize, k: usize) -> u32 {
        self.nbr[k]
    }
    fn entries(&self) -> usize {
        self.nbr.len()
    }
}

/// The Verlet list: one of `step` (j − i) and `wide` (j) holds the partners.
#[derive(Clone, Debug, Default)]
pub struct VerletList {
    offsets: Vec<u32>,
    step: Vec<u16>,
    wide: Vec<u32>,
}

impl ListRows for VerletList {
    fn offsets(&self) -> &[u32] {
        &self.offsets
    }
    #[inline(always)]
    fn partner(&self, i: usize, k: usize) -> u32 {
        if self.wide.is_empty() {
            i as u32 + u32::from(self.step[k])
        } else {
            self.wide[k]
        }
    }
    fn entries(&self) -> usize {
        self.step.len().max(self.wide.len())
    }
}

impl From<NeighborList> for VerletList {
    /// The rows of `nl` (its histories and flags are not kept), in `build_rows`' blocks.
    fn from(nl: NeighborList) -> VerletList {
        let NeighborList { offsets, nbr, .. } = nl;
        let n = offsets.len().saturating_sub(1);
        let rows = (0..n.div_ceil(BLOCK))
            .map(|b| {
                let (a, e) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
                let counts = offsets[a..=e].windows(2).map(|o| o[1] - o[0]).collect();
                (counts, nbr[offsets[a] as usize..offsets[e] as usize].to_vec())
            })
            .collect();
        Self::assemble(rows, u16::MAX as usize)
    }
}

impl VerletList {
    /// The list of `build_rows` (particles in cell order, pairs closer than `cutoff`), its blocks
    /// assembled in parallel.
    pub fn build(x: &[[f64; 3]], tube_radius: f64, cutoff: f64, diameter: f64) -> VerletList {
        Self::assemble(build_rows(x, tube_radius, cutoff, diameter), u16::MAX as usize)
    }

    /// The list of `rows` (`build_rows`), as steps if none exceeds `max_step` (≤ u16::MAX).
    fn assemble(rows: Vec<(Vec<u32>, Vec<u32>)>, max_step: usize) -> VerletList {
        let n: usize = rows.iter().map(|r| r.0.len()).sum();
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0u32);
        for c in rows.iter().flat_map(|r| &r.0) {
            offsets.push(offsets.last().unwrap() + c);
        }
        // Block b holds rows b·BLOCK.. and entries offsets[b·BLOCK]..
        let fits = rows.par_iter().enumerate().all(|(b, (counts, list))| {
            let owners = (b * BLOCK..).zip(counts).flat_map(|(i, &c)| std::iter::repeat_n(i, c as usize));
            owners.zip(list).all(|(i, &j)| (j as usize).checked_sub(i).is_some_and(|s| s <= max_step))
        });
        let total = *offsets.last().unwrap() as usize;
        if !fits || total == 0 {
            let mut wide = Vec::with_capacity(total);
            rows.iter().for_each(|r| wide.extend_from_slice(&r.1));
            return VerletList { offsets, step: Vec::new(), wide };
        }
        let mut step = vec![0u16; total];
        let mut parts = Vec::with_capacity(rows.len());
        let mut rest = &mut step[..];
        for r in &rows {
            let (part, more) = std::mem::take(&mut rest).split_at_mut(r.1.len());
            parts.push(part);
            rest = more;
        }
        parts.into_par_iter().zip(rows.par_iter()).enumerate().for_each(|(b, (out, (counts, list)))| {
            let owners = (b * BLOCK..).zip(counts).flat_map(|(i, &c)| std::iter::repeat_n(i, c as usize));
            for ((o, i), &j) in out.iter_mut().zip(owners).zip(list) {
                *o = (j as usize - i) as u16;
            }
        });
        VerletList { offsets, step, wide: Vec::new() }
    }

    /// The plain list (partners as u32, no histories).
    #[cfg(test)]
    pub fn to_list(&self) -> NeighborList {
        NeighborList {
            offsets: self.offsets.clone(),
            nbr: self.partners().collect(),
            shear: Vec::new(),
            touch: Vec::new(),
        }
    }
    /// Whether the partners are stored as 16-bit steps.
    #[cfg(test)]
    pub fn is_compact(&self) -> bool {
        self.wide.is_empty() && !self.step.is_empty()
    }
    /// Every entry's partner, in entry order.
    fn partners(&self) -> impl Iterator<Item = u32> + '_ {
        let n = self.offsets.len().saturating_sub(1);
        (0..n).flat_map(move |i| {
            (self.offsets[i] as usize..self.offsets[i + 1] as usize).map(move |k| self.partner(i, k))
        })
    }
}

/// The partners as a sequence of u32 (a checkpoint's `nbr`).
struct Partners<'a>(&'a VerletList);

impl Serialize for Partners<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeSeq;
        let mut seq = s.serialize_seq(Some(self.0.entries()))?;
        for j in self.0.partners() {
            seq.serialize_element(&j)?;
        }
        seq.end()
    }
}

impl Serialize for VerletList {
    /// As `NeighborList` (offsets, partners, empty histories and flags).
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("NeighborList", 4)?;
        st.serialize_field("offsets", &self.offsets)?;
        st.serialize_field("nbr", &Partners(self))?;
        st.serialize_field("shear", &[] as &[Hist])?;
        st.serialize_field("touch", &[] as &[u8])?;
        st.end()
    }
}

impl<'de> Deserialize<'de> for VerletList {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<VerletList, D::Error> {
        NeighborList::deserialize(d).map(VerletList::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn list(rows: &[&[u32]]) -> NeighborList {
        let mut nl = NeighborList { offsets: vec![0], ..Default::default() };
        for r in rows {
            nl.nbr.extend_from_slice(r);
            nl.offsets.push(nl.nbr.len() as u32);
        }
        nl
    }

    #[test]
    fn partners_within_a_step_of_16_bits_are_stored_as_steps_and_read_back() {
        let nl = list(&[&[1, 2, 65_535], &[], &[3, 65_537], &[4]]);
        let v = VerletList::from(nl.clone());
        assert!(v.is_compact());
        assert_eq!(v.entries(), 6);
        let back = v.to_list();
        assert_eq!((back.offsets, back.nbr), (nl.offsets.clone(), nl.nbr.clone()));
        assert_eq!(v.partner(2, 4), 65_537);
    }

    #[test]
    fn a_built_list_is_the_plain_list_in_either_form() {
        // A random bed in cell order, as the DEM builds it.
        let mut seed = 7u64;
        let mut u = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (r, d) = (0.01, 0.001);
        let raw: Vec<[f64; 3]> = (0..6000)
            .map(|_| {
                let (a, s) = (std::f64::consts::TAU * u(), (r - d / 2.0) * u().sqrt());
                [s * a.cos(), s * a.sin(), 0.02 * u()]
            })
            .collect();
        let order = crate::dem::neighbors::cell_order(&raw, r, 1.4 * d);
        let x: Vec<[f64; 3]> = order.iter().map(|&o| raw[o as usize]).collect();
        let plain = crate::dem::neighbors::build_list(&x, r, 1.4 * d, d);
        assert!(plain.nbr.len() > 10_000, "{} pairs", plain.nbr.len());
        let compact = VerletList::build(&x, r, 1.4 * d, d);
        let wide = VerletList::assemble(build_rows(&x, r, 1.4 * d, d), 3);
        assert!(compact.is_compact() && !wide.is_compact());
        for v in [compact, wide] {
            let back = v.to_list();
            assert!(back.offsets == plain.offsets && back.nbr == plain.nbr);
            assert_eq!(v.entries(), plain.nbr.len());
        }
    }

    #[test]
    fn a_partner_farther_than_16_bits_keeps_the_plain_list() {
        let nl = list(&[&[1, 65_536], &[2]]);
        let v = VerletList::from(nl.clone());
        assert!(!v.is_compact());
        assert_eq!(v.partner(0, 1), 65_536);
        assert_eq!(v.to_list().nbr, nl.nbr);
    }

    #[test]
    fn a_checkpoint_holds_the_plain_list_and_reads_back_either_form() {
        let nl = list(&[&[1, 9, 300], &[2, 70_000], &[]]);
        for src in [nl.clone(), list(&[&[1, 9, 300], &[2, 7], &[]])] {
            let v = VerletList::from(src.clone());
            let bytes = bincode::serialize(&v).unwrap();
            assert_eq!(
                bytes,
                bincode::serialize(&NeighborList { shear: vec![], touch: vec![], ..src.clone() }).unwrap()
            );
            let back: VerletList = bincode::deserialize(&bytes).unwrap();
            assert_eq!(back.to_list().nbr, src.nbr);
        }
    }
}
