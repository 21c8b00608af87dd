//! The near list (`near_list`): it holds every touching pair at every step of a fast,
//! colliding run (checked by brute force over all pairs), a pair pass over it gives the whole
//! Verlet list's forces, flags and histories bit for bit, and a refresh keeps every live history.

use super::energy::random_gas;
use super::{test_case, with_damping};
use crate::dem::forces::{pair_pass, Scratch};
use crate::dem::near_list::{Histories, NearList};
use crate::dem::neighbors::NeighborList;
use crate::dem::pair_scatter::PairSum;
use crate::dem::DemSystem;
use std::collections::{HashMap, HashSet};

/// The Verlet-list entry of each near-list entry: its row's entry with the same partner.
fn sources(outer: &NeighborList, near: &NeighborList) -> Vec<u32> {
    let mut out = Vec::with_capacity(near.nbr.len());
    for i in 0..near.offsets.len() - 1 {
        let row = outer.offsets[i] as usize..outer.offsets[i + 1] as usize;
        for &j in &near.nbr[near.offsets[i] as usize..near.offsets[i + 1] as usize] {
            let k = row.clone().find(|&k| outer.nbr[k] == j).expect("a near entry is in its Verlet row");
            out.push(k as u32);
        }
    }
    out
}

/// Pairs (i < j) listed in the near list now.
fn near_pairs(s: &DemSystem) -> HashSet<(u32, u32)> {
    let nl = &s.near.list;
    let mut set = HashSet::new();
    for i in 0..s.len() {
        for &j in &nl.nbr[nl.offsets[i] as usize..nl.offsets[i + 1] as usize] {
            set.insert((i as u32, j));
        }
    }
    set
}

/// 400 particles at up to 1.5 m/s under gravity in a closed column, and their diameter: they
/// cross the near gap (0.045 d) in about 30 steps, so a run refreshes and rebuilds many times.
fn colliding_gas() -> (DemSystem, f64) {
    let case = with_damping(test_case(0.01, 0.02, true, 9.81, 1e-6), 0.05, 0.05, 0.3);
    let d = case.particles.diameter_m;
    let (x, v) = random_gas(400, 0.005, 0.02, d / 2.0, 1.5, 5);
    (DemSystem::new(&case, x, v), d)
}

#[test]
fn near_list_holds_every_touching_pair() {
    let (mut s, d) = colliding_gas();
    let mut touching_seen = 0;
    for _ in 0..2000 {
        s.step();
        // The running bound that stands in for the exact displacement check never falls below
        // the largest displacement since the refresh.
        let (bound, largest) = s.moved_bound_and_largest();
        assert!(bound >= largest, "bound {bound:e} below the displacement {largest:e} at step {}", s.steps());
        let listed = near_pairs(&s);
        let x = s.positions();
        for i in 0..x.len() {
            for j in i + 1..x.len() {
                let r2: f64 = (0..3).map(|a| (x[j][a] - x[i][a]).powi(2)).sum();
                if r2 < d * d {
                    touching_seen += 1;
                    assert!(
                        listed.contains(&(i as u32, j as u32)),
                        "touching pair ({i}, {j}) missing at step {}",
                        s.steps()
                    );
                }
            }
        }
    }
    let (builds, refreshes) = s.list_builds();
    eprintln!("{builds} builds, {refreshes} refreshes, {touching_seen} touching pair-steps");
    assert!(builds >= 5 && refreshes >= 20, "{builds} Verlet builds, {refreshes} refreshes");
    assert!(touching_seen > 20_000, "only {touching_seen} touching pair-steps");
}

#[test]
fn near_list_pair_pass_equals_the_whole_lists() {
    // Jittered lattice at contact: pairs touching, pairs within the near gap, pairs beyond it.
    let case = with_damping(test_case(0.02, 0.03, false, 9.81, 1e-6), 0.1, 0.05, 0.3);
    let d = case.particles.diameter_m;
    let mut x = Vec::new();
    let mut k = 0u64;
    let mut jitter = || {
        k = k.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        0.06 * d * ((k >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    };
    for iz in 0..10 {
        for iy in -6..=6 {
            for ix in -6..=6 {
                let p = [ix as f64 * d, iy as f64 * d, d + iz as f64 * d];
                if (p[0] * p[0] + p[1] * p[1]).sqrt() < 0.0095 - d {
                    x.push([p[0] + jitter(), p[1] + jitter(), p[2] + jitter()]);
                }
            }
        }
    }
    let v: Vec<[f64; 3]> = (0..x.len()).map(|i| [0.05 * (i % 7) as f64, -0.03 * (i % 5) as f64, 0.0]).collect();
    let mut s = DemSystem::new(&case, x, v);
    for w in s.w.iter_mut() {
        *w = [200.0, -100.0, 50.0];
    }
    for _ in 0..5 {
        s.step(); // live histories
    }
    // The whole list with the near list's histories; every other entry not live.
    let src = sources(&s.outer.to_list(), &s.near.list);
    let mut outer = s.outer.to_list();
    (outer.touch, outer.shear) = (vec![0; outer.nbr.len()], vec![[1.0; 3]; outer.nbr.len()]);
    for (e, &k) in src.iter().enumerate() {
        outer.shear[k as usize] = s.near.list.shear[e];
        outer.touch[k as usize] = s.near.list.touch[e];
    }
    let n = s.len();
    let run = |nl: &mut crate::dem::neighbors::NeighborList| {
        let mut sc = Scratch::plan(nl, n, 1);
        pair_pass::<true>(&s.p, (&s.x, &s.v, &s.w), nl, &mut sc, s.kernel());
        let mut acc = sc.acc;
        acc.resize(n, Default::default());
        acc
    };
    let mut near = s.near.list.clone();
    let (on_near, on_outer) = (run(&mut near), run(&mut outer));
    let touching = near.touch.iter().filter(|&&t| t == 1).count();
    assert!(touching > 500 && touching < near.nbr.len(), "{touching} of {} near entries touch", near.nbr.len());
    assert!(near.nbr.len() < outer.nbr.len(), "the near list is the whole list");
    let bits = |a: &[PairSum]| a.iter().flat_map(|r| r.0).map(f32::to_bits).collect::<Vec<_>>();
    assert!(bits(&on_near) == bits(&on_outer), "forces and torques differ");
    // Every entry left out of the near list does not touch; the kept ones agree exactly.
    let kept: HashSet<u32> = src.iter().copied().collect();
    for k in 0..outer.nbr.len() {
        assert!(kept.contains(&(k as u32)) || outer.touch[k] == 0, "entry {k} touches but was left out");
    }
    for (e, &k) in src.iter().enumerate() {
        assert_eq!(near.touch[e], outer.touch[k as usize]);
        assert!(near.shear[e].map(f32::to_bits) == outer.shear[k as usize].map(f32::to_bits), "history of entry {k}");
    }
    // A refresh (with a gap of zero, so only touching or live entries stay) carries every live
    // history of the old near list to the same pair, bit for bit.
    let again = NearList::select(&s.outer, &s.x, d, 0.0, Histories::Near(&s.near));
    assert!(again.list.nbr.len() < s.near.list.nbr.len(), "nothing left out");
    let old: HashMap<u32, usize> = src.iter().enumerate().map(|(e, &k)| (k, e)).collect();
    let mut live = 0;
    for (e, &k) in sources(&s.outer.to_list(), &again.list).iter().enumerate() {
        let o = old[&k];
        assert_eq!(again.list.nbr[e], s.near.list.nbr[o]);
        assert_eq!(again.list.touch[e], s.near.list.touch[o]);
        assert!(
            again.list.shear[e].map(f32::to_bits) == s.near.list.shear[o].map(f32::to_bits),
            "history of entry {k}"
        );
        live += again.list.touch[e] as usize;
    }
    assert_eq!(live, s.near.list.touch.iter().filter(|&&t| t == 1).count(), "a live history was dropped");
}

/// The near list's arrays as bits, to compare two lists exactly.
fn list_bits(nl: &NeighborList) -> (Vec<u32>, Vec<u32>, Vec<u8>, Vec<u32>) {
    let shear = nl.shear.iter().flatten().map(|v| v.to_bits()).collect();
    (nl.offsets.clone(), nl.nbr.clone(), nl.touch.clone(), shear)
}

#[test]
fn a_refresh_in_place_equals_a_fresh_selection() {
    // Live histories, lists that grow and shrink from refresh to refresh.
    let (mut s, d) = colliding_gas();
    let base_gap = s.p.near_gap();
    let (mut compared, mut moved_rows, mut live) = (0, 0, 0);
    for round in 0..40 {
        for _ in 0..7 {
            s.step();
        }
        // Gaps that keep the list, shrink it to the live entries, or take the whole Verlet list
        // (shifts larger than a part), each from the list the previous gap left.
        let mut near = s.near.clone();
        for gap in [base_gap, 0.0, 10.0 * d, 0.5 * base_gap, base_gap] {
            let want = NearList::select(&s.outer, &s.x, d, gap, Histories::Near(&near));
            // The Verlet list as kept (16-bit partner steps) selects what the plain list does.
            assert!(s.outer.is_compact(), "the Verlet list keeps its partners in 16 bits");
            let plain = NearList::select(&s.outer.to_list(), &s.x, d, gap, Histories::Near(&near));
            assert!(list_bits(&plain.list) == list_bits(&want.list), "round {round}: the two forms select differently");
            for part_rows in [1, 7, 64, 1 << 14] {
                let mut got = near.clone();
                got.refresh_in_parts(&s.outer, &s.x, d, gap, part_rows);
                assert!(
                    list_bits(&got.list) == list_bits(&want.list),
                    "round {round}, gap {gap:e}, parts of {part_rows}: the lists differ"
                );
                compared += 1;
            }
            let changed = near.list.offsets.iter().zip(&want.list.offsets).filter(|(a, b)| a != b).count();
            moved_rows += changed;
            live += want.list.touch.iter().filter(|&&t| t != 0).count();
            near = want;
        }
    }
    assert!(compared == 800 && moved_rows > 10_000 && live > 1_000, "{moved_rows} rows moved, {live} live entries");
}

/// Live histories by particle-id pair (i < j by id, ξ oriented from the smaller id).
fn live_by_id(s: &DemSystem) -> HashMap<(u32, u32), [u32; 3]> {
    let (nl, ids) = (&s.near.list, s.ids());
    let mut out = HashMap::new();
    for i in 0..s.len() {
        for k in nl.offsets[i] as usize..nl.offsets[i + 1] as usize {
            if nl.touch[k] != 0 {
                let (a, b) = (ids[i], ids[nl.nbr[k] as usize]);
                let h = if a < b { nl.shear[k] } else { nl.shear[k].map(|c| -c) };
                out.insert((a.min(b), a.max(b)), h.map(f32::to_bits));
            }
        }
    }
    out
}

#[test]
fn a_rebuild_carries_every_live_history_by_particle_id() {
    let (mut s, _) = colliding_gas();
    let mut carried = 0;
    for _ in 0..40 {
        for _ in 0..13 {
            s.step();
        }
        let before = live_by_id(&s);
        // Reverse the order, so that the re-sort moves every particle and flips orientations.
        s.x.reverse();
        s.v.reverse();
        s.w.reverse();
        s.ids.reverse();
        for slot in s.past.v.iter_mut().chain(&mut s.past.a).chain(&mut s.past.alpha) {
            slot.reverse();
        }
        let n = s.len() as u32;
        let nl = &mut s.near.list;
        let mut rows: Vec<Vec<(u32, [f32; 3], u8)>> = (0..n as usize).map(|_| Vec::new()).collect();
        for i in 0..n as usize {
            for k in nl.offsets[i] as usize..nl.offsets[i + 1] as usize {
                let (a, b) = (n - 1 - i as u32, n - 1 - nl.nbr[k]);
                let (lo, hi, h) = if a < b { (a, b, nl.shear[k]) } else { (b, a, nl.shear[k].map(|c| -c)) };
                rows[lo as usize].push((hi, h, nl.touch[k]));
            }
        }
        *nl = crate::dem::neighbors::NeighborList::default();
        nl.offsets.push(0);
        for r in rows {
            for (j, h, t) in r {
                nl.nbr.push(j);
                nl.shear.push(h);
                nl.touch.push(t);
            }
            nl.offsets.push(nl.nbr.len() as u32);
        }
        assert_eq!(live_by_id(&s), before, "the reversed list holds the same histories");
        s.rebuild();
        assert_eq!(live_by_id(&s), before, "a history was lost or changed by the rebuild");
        carried += before.len();
    }
    assert!(carried > 500, "only {carried} live histories carried");
}

#[test]
fn a_pass_keeping_the_histories_gives_the_same_forces_and_keeps_them() {
    let (mut s, _) = colliding_gas();
    for _ in 0..60 {
        s.step(); // live histories
    }
    let n = s.len();
    for (chunks, rows) in [(1, 1), (1, 4096), (3, 7), (3, 100_000), (8, 33)] {
        let mut sc = Scratch::plan(&s.near.list, n, chunks);
        let (before, mut kept) = (list_bits(&s.near.list), s.near.list.clone());
        let keep = Some(rows);
        crate::dem::forces::pair_pass_with::<true>(&s.p, (&s.x, &s.v, &s.w), &mut kept, &mut sc, s.kernel(), keep);
        assert!(list_bits(&kept) == before, "{chunks} chunks, pieces of {rows}: the histories or flags changed");
        let on_kept = sc.acc.clone();
        let mut written = s.near.list.clone();
        pair_pass::<true>(&s.p, (&s.x, &s.v, &s.w), &mut written, &mut sc, s.kernel());
        assert!(list_bits(&written) != before, "the plain pass writes nothing either: no test");
        let bits = |a: &[PairSum]| a.iter().flat_map(|r| r.0).map(f32::to_bits).collect::<Vec<_>>();
        assert!(bits(&on_kept) == bits(&sc.acc), "{chunks} chunks, pieces of {rows}: the forces differ");
    }
}
