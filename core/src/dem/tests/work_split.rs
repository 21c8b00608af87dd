//! The pair pass's work split: chunks of at most `MAX_CHUNK_ROWS` rows, each entry's row stored
//! less its chunk's first row (16 bits), on a list past four such chunks.

use crate::dem::neighbors::NeighborList;
use crate::dem::work_split::{Scratch, MAX_CHUNK_ROWS};

/// A half list of `n` rows: partner i + 1, and i + 2 on every seventh row.
fn chain_list(n: usize) -> NeighborList {
    let mut nl = NeighborList { offsets: vec![0], ..Default::default() };
    for i in 0..n {
        for j in [i + 1, if i % 7 == 0 { i + 2 } else { n }] {
            if j < n {
                nl.nbr.push(j as u32);
            }
        }
        nl.offsets.push(nl.nbr.len() as u32);
    }
    nl.shear = vec![[0.0; 3]; nl.nbr.len()];
    nl.touch = vec![0; nl.nbr.len()];
    nl
}

#[test]
fn chunks_past_the_row_limit_are_cut_and_every_entry_keeps_its_row() {
    let n = 4 * MAX_CHUNK_ROWS + 123;
    let nl = chain_list(n);
    for chunks in [1, 2, 5] {
        let sc = Scratch::plan(&nl, n, chunks);
        assert!(sc.bounds.len() >= 5, "{chunks} chunks asked: {} planned", sc.bounds.len());
        assert_eq!((sc.bounds[0][0], sc.bounds.last().unwrap()[1]), (0, n));
        for (c, &[a, b, e]) in sc.bounds.iter().enumerate() {
            assert!(b - a <= MAX_CHUNK_ROWS, "chunk {c}: {} rows", b - a);
            assert!(c == 0 || sc.bounds[c - 1][1] == a, "chunk {c} starts where the one before ends");
            assert!(e <= n && e >= b);
            for i in a..b {
                for k in nl.offsets[i] as usize..nl.offsets[i + 1] as usize {
                    assert_eq!(a + sc.owner[k] as usize, i, "entry {k}");
                }
            }
        }
    }
}
