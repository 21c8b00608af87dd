//! One multistep DEM step as a single rayon broadcast: every thread of the pool takes pair-pass
//! chunks (its own share first, then what is left of the others', `steal_ranges`), then
//! particle-pass blocks the same way. There is no barrier between the passes: a block waits
//! (spinning) only for the chunks whose particle windows cover it — they read its particles and
//! write its force sums — so a thread whose pair pass ran long hands blocks to the others
//! instead of making them wait. As two parallel loops (`forces::pair_pass`, then
//! `particle_pass::update_pass`) the pool's threads fall asleep between the passes and must be
//! woken (tens of µs a pass on a VM). The work is that of the two passes (the same chunks,
//! buffers and blocks, whichever thread takes them), so every bit of the result is the same.

use super::contact::V3;
use super::forces::{chunk_pairs_on, ChunkArgs, Past, PastV3, Scratch, Stats};
use super::kernel::Kernel;
use super::neighbors::{Hist, NeighborList};
use super::pair_scatter::PairSum;
use super::particle_pass::{block_walls, update_block_on, BlockMotion, Weights, BLOCK};
use super::reference::RefV3;
use super::steal_ranges::StealRanges;
use super::walls::WallList;
use super::work_split::Sums;
use super::DemParams;
#[cfg(test)]
use crate::team::has_own_team;
use crate::team::{spin_until, Raw};
use std::sync::atomic::{AtomicBool, Ordering};

/// Spins (then yields) until every chunk c with `need(c)` is done; false if a chunk failed
/// (its thread panicked), so that nobody waits for it for ever.
fn wait_for_chunks(done: &[AtomicBool], failed: &AtomicBool, need: impl Fn(usize) -> bool) -> bool {
    (0..done.len()).filter(|&c| need(c)).all(|c| spin_until(|| done[c].load(Ordering::Acquire), failed))
}

/// Tests only: chunk c panics while this holds c + 1, on pools without their own team lock (the
/// test that sets it holds the process-wide lock, so no other such team runs meanwhile).
#[cfg(test)]
pub(crate) static PANIC_IN_CHUNK: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// The state the steps change.
pub(crate) struct StepState<'a> {
    pub x: &'a mut [V3],
    pub v: &'a mut [V3],
    pub w: &'a mut [V3],
    pub past: &'a mut Past,
    pub walls: &'a mut WallList,
    pub nl: &'a mut NeighborList,
    pub sc: &'a mut Scratch,
}

/// The pair pass and the fused particle pass of one step (`step`: the multistep weights and
/// slot), displacements measured from `x_ref` (unless it is empty), on the `kernel` path. The
/// caller holds the pool's `TeamLock`. Panics unless the state has one row per particle and `sc`
/// was planned for `s.nl` (chunks in order, their list entries and buffers disjoint).
pub(crate) fn team_step<const FR: bool>(
    kernel: Kernel,
    p: &DemParams,
    step: Weights,
    s: StepState,
    x_ref: &[RefV3],
    ext: &[V3],
) -> Stats {
    let StepState { x, v, w, past, walls, nl, sc } = s;
    let n = x.len();
    assert!(
        v.len() == n && w.len() == n && (x_ref.is_empty() || x_ref.len() == n) && (ext.is_empty() || ext.len() == n)
    );
    assert!(past.v.iter().chain(&past.a).chain(&past.alpha).all(|s| s.len() == n), "past derivatives");
    let (offsets, nbr) = (&nl.offsets[..], &nl.nbr[..]);
    let (bounds, start, owner) = (&sc.bounds[..], &sc.start[..], &sc.owner[..]);
    assert!(start.len() > bounds.len() && bounds.iter().all(|&[a, b, e]| a <= b && b <= e && e <= n), "chunks");
    // What the threads write must be disjoint: chunk c writes list entries offsets[a]..offsets[b]
    // and buffer rows start[c]..start[c] + e − a, so the chunks must follow each other. The
    // offsets are checked at the chunk cuts only: a pass over all of them here, on one thread,
    // would idle the others long enough to sleep; `Scratch::replan` checks them all, and the list
    // changes only with a new plan.
    assert!(offsets.len() == n + 1 && bounds.iter().all(|&[a, b, _]| offsets[a] <= offsets[b]), "list offsets");
    assert!(bounds.windows(2).all(|c| c[0][1] == c[1][0]), "chunks in order");
    assert!(bounds.iter().enumerate().all(|(c, &[a, _, e])| start[c] + e - a <= start[c + 1]), "chunk buffers");
    let (nc, nb) = (bounds.len(), n.div_ceil(BLOCK));
    let widx = &walls.idx[..];
    let raw = Shared {
        x: Raw::new(x),
        v: Raw::new(v),
        w: Raw::new(w),
        past: [&mut past.v, &mut past.a, &mut past.alpha].map(|[s0, s1]| [Raw::new(s0), Raw::new(s1)]),
        whist: Raw::new(&mut walls.hist),
        shear: Raw::new(&mut nl.shear),
        touch: Raw::new(&mut nl.touch),
        acc: Raw::new(&mut sc.acc),
    };
    let team = rayon::current_num_threads();
    // Chunks: each thread starts at the end of its share, next to the following thread's,
    // whose first blocks wait for it (a chunk's window reaches into the particles after it).
    let (chunk_queue, block_queue) = (StealRanges::new(nc, team, true), StealRanges::new(nb, team, false));
    let done: Vec<AtomicBool> = (0..nc).map(|_| AtomicBool::new(false)).collect();
    let failed = AtomicBool::new(false);
    let per_thread = rayon::broadcast(|ctx| {
        let (t, nt) = (ctx.index(), ctx.num_threads());
        assert!(nt == team, "broadcast on the pool that was counted");
        let mut st = Stats::ZERO;
        // A panic in a chunk marks the team failed (no block waits for that chunk for ever).
        let pairs = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            while let Some(c) = chunk_queue.take(t) {
                let [a, b, e] = bounds[c];
                // SAFETY: chunk c reads x, v, w only in its window a..e, which no block
                // writes before c is done; its histories, flags and buffer (disjoint from the
                // other chunks') are written only by the thread that took c (taken once).
                let (x, v, w) = unsafe { (raw.x.view(a, e), raw.v.view(a, e), raw.w.view(a, e)) };
                let (k0, k1) = if FR { (offsets[a] as usize, offsets[b] as usize) } else { (0, 0) };
                let (sh, to) = unsafe { (raw.shear.part(k0, k1), raw.touch.part(k0, k1)) };
                let buf = unsafe { raw.acc.part(start[c], start[c] + e - a) };
                let args = ChunkArgs::new(p, a, b, offsets, owner, nbr, (x, v, w));
                #[cfg(test)]
                assert!(
                    PANIC_IN_CHUNK.load(Ordering::Relaxed) != c + 1 || has_own_team(),
                    "injected panic in chunk {c}"
                );
                st = st.max(chunk_pairs_on::<FR>(kernel, &args, sh, to, buf));
                done[c].store(true, Ordering::Release);
            }
        }));
        if let Err(e) = pairs {
            failed.store(true, Ordering::Release);
            std::panic::resume_unwind(e);
        }
        // SAFETY: rows are read through `sums` only for a block whose chunks are done (below);
        // the other chunks' buffer rows are not read.
        let sums = unsafe { Sums::from_raw(bounds, start, raw.acc.ptr, raw.acc.len) };
        let (ring, older) = (step.ring, 1 - step.ring);
        while let Some(b) = block_queue.take(t) {
            let (lo, hi, wr) = (b * BLOCK, ((b + 1) * BLOCK).min(n), block_walls(widx, b, n));
            // Block b's particles lie in the windows of the chunks that overlap it.
            if !wait_for_chunks(&done, &failed, |c| bounds[c][0] < hi && bounds[c][2] > lo) {
                break; // another thread's chunk panicked; its panic reaches the caller
            }
            // SAFETY: every chunk that reads block b's particles or writes their buffer rows
            // is done; b's particles and wall entries are touched only by the thread that took b.
            let slot = |q: usize, s: usize| unsafe { raw.past[q][s].part(lo, hi) };
            let bm = BlockMotion {
                lo,
                x: unsafe { raw.x.part(lo, hi) },
                v: unsafe { raw.v.part(lo, hi) },
                w: unsafe { raw.w.part(lo, hi) },
                newer: [0, 1, 2].map(|q| &*slot(q, ring)),
                older: [0, 1, 2].map(|q| slot(q, older)),
                whist: unsafe { raw.whist.part(wr.start, wr.end) },
                widx: &widx[wr],
            };
            st = st.max(update_block_on::<FR>(kernel, p, step, bm, x_ref, ext, sums));
        }
        st
    });
    per_thread.into_iter().fold(Stats::ZERO, Stats::max)
}

/// Raw views of everything the threads write.
#[derive(Clone, Copy)]
struct Shared {
    x: Raw<V3>,
    v: Raw<V3>,
    w: Raw<V3>,
    past: [[Raw<PastV3>; 2]; 3],
    whist: Raw<[V3; 3]>,
    shear: Raw<Hist>,
    touch: Raw<u8>,
    acc: Raw<PairSum>,
}
