//! Pass 2 of a DEM step, per block of BLOCK particles: the chunk buffers of the pair pass summed
//! in chunk order after the external force, wall contacts for the wall list, gravity, and (fused)
//! the AB3 update on flat arrays (PHYSICS.md 7). Blocks are fixed, so results do not depend on
//! the thread count.

use super::ab_update::{ab_flat, ab_flat_moved};
use super::contact::{dist2, V3};
use super::forces::{narrow, widen, Acc, Past, PastV3, Stats};
use super::kernel::{Isa, Kernel};
use super::reference::RefV3;
use super::walls::{wall_forces, WallList};
use super::work_split::Sums;
use super::DemParams;
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Particles per block of the particle pass.
pub(crate) const BLOCK: usize = 256;

/// `out` with every row written (the block's stack rows need no clearing pass first, which
/// cost ~1% of a step).
#[inline(always)]
fn written<T: Copy>(out: &mut [MaybeUninit<T>], mut row: impl FnMut(usize) -> T) -> &mut [T] {
    for (l, o) in out.iter_mut().enumerate() {
        o.write(row(l));
    }
    // SAFETY: every element was written just above.
    unsafe { &mut *(out as *mut [MaybeUninit<T>] as *mut [T]) }
}

/// Force and n × F_t sums of the particles lo..lo + out.len() (`x`, `v`, `w`: their slices):
/// the external force (none when `ext` is empty), then the chunk buffers in chunk order, then
/// walls for the wall-list entries `widx`/`whist`; and the largest overlap and Coulomb excess.
#[inline(always)]
fn block_forces<'o, const FR: bool>(
    p: &DemParams,
    lo: usize,
    (x, v, w): (&[V3], &[V3], &[V3]),
    ext: &[V3],
    sc: Sums,
    (widx, whist): (&[u32], &mut [[V3; 3]]),
    out: &'o mut [MaybeUninit<Acc>],
) -> (&'o mut [Acc], Stats) {
    let mut st = Stats::ZERO;
    let hi = lo + out.len();
    // A scene without gas skips the stream of zeros (1–5% of a step, docs/BENCHMARKS.md).
    let out = if ext.is_empty() {
        written(out, |_| [0.0; 6])
    } else {
        let ext = &ext[lo..hi];
        written(out, |l| [ext[l][0], ext[l][1], ext[l][2], 0.0, 0.0, 0.0])
    };
    for (c, &[a, _, e]) in sc.bounds.iter().enumerate() {
        let (s, t) = (lo.max(a), hi.min(e));
        if s < t {
            let buf = sc.rows(c, s, t);
            for (o, q) in out[s - lo..t - lo].iter_mut().zip(buf) {
                for (ok, &qk) in o.iter_mut().zip(&q.0[..6]) {
                    *ok += qk as f64;
                }
            }
        }
    }
    for (&i, hist) in widx.iter().zip(whist.iter_mut()) {
        let l = i as usize - lo;
        let (ov, ex) = wall_forces::<FR>(p, x[l], v[l], w[l], hist, &mut out[l]);
        st.overlap = st.overlap.max(ov);
        st.coulomb_excess = st.coulomb_excess.max(ex);
    }
    (out, st)
}

/// a = F/m − g e_z − γ v of a particle with sums `o` and velocity `vi` (gravity and the pour's
/// extra damping γ).
#[inline(always)]
fn accel_of(p: &DemParams, o: &Acc, vi: V3) -> V3 {
    let (im, g, gz) = (1.0 / p.mass, p.extra_damping, p.gravity);
    [o[0] * im - g * vi[0], o[1] * im - g * vi[1], o[2] * im - gz - g * vi[2]]
}

/// α = R (Σ n × F_t)/I − γ ω of a particle with sums `o` and spin `wi` (zero without friction).
#[inline(always)]
fn alpha_of<const FR: bool>(p: &DemParams, o: &Acc, wi: V3) -> V3 {
    let (ii, g) = (p.radius / p.inertia, p.extra_damping);
    if FR {
        [o[3] * ii - g * wi[0], o[4] * ii - g * wi[1], o[5] * ii - g * wi[2]]
    } else {
        [0.0; 3]
    }
}

/// The wall-list entries (sorted by particle) of block b of n particles.
pub(super) fn block_walls(idx: &[u32], b: usize, n: usize) -> std::ops::Range<usize> {
    let at = |p: usize| idx.partition_point(|&i| (i as usize) < p.min(n));
    at(b * BLOCK)..at((b + 1) * BLOCK)
}

/// Wall-list entries split by block, for handing each block its own histories.
fn wall_blocks(walls: &mut WallList, n: usize) -> Vec<(&[u32], &mut [[V3; 3]])> {
    let (idx, mut hist) = (&walls.idx[..], &mut walls.hist[..]);
    let mut out = Vec::with_capacity(n.div_ceil(BLOCK));
    for b in 0..n.div_ceil(BLOCK) {
        let r = block_walls(idx, b, n);
        let (h0, h1) = std::mem::take(&mut hist).split_at_mut(r.len());
        out.push((&idx[r], h0));
        hist = h1;
    }
    out
}

/// Pass 2 for start-up: accelerations a and α of every particle into `a_out` and `alpha_out`, at
/// the past derivatives' precision (the start-up step keeps them as the history).
pub(crate) fn accel_pass<const FR: bool>(
    p: &DemParams,
    (x, v, w): (&[V3], &[V3], &[V3]),
    walls: &mut WallList,
    ext: &[V3],
    sc: Sums,
    (a_out, alpha_out): (&mut [PastV3], &mut [PastV3]),
) -> Stats {
    assert!(a_out.len() == x.len() && alpha_out.len() == x.len(), "one output row per particle");
    let wb = wall_blocks(walls, x.len());
    a_out
        .par_chunks_mut(BLOCK)
        .zip(alpha_out.par_chunks_mut(BLOCK))
        .zip(wb)
        .enumerate()
        .map(|(b, ((ab, alb), (widx, whist)))| {
            let r = b * BLOCK..b * BLOCK + ab.len();
            let (v, w) = (&v[r.clone()], &w[r.clone()]);
            let mut rows = [MaybeUninit::<Acc>::uninit(); BLOCK];
            let (sums, st) =
                block_forces::<FR>(p, r.start, (&x[r], v, w), ext, sc, (widx, whist), &mut rows[..ab.len()]);
            for (l, o) in sums.iter().enumerate() {
                ab[l] = narrow(accel_of(p, o, v[l]));
                alb[l] = narrow(alpha_of::<FR>(p, o, w[l]));
            }
            st
        })
        .reduce(|| Stats::ZERO, Stats::max)
}

/// The multistep update of a step: weights hb = h·b (PHYSICS.md 7), and the slot `ring` of the
/// past derivatives that holds the newer values (the current ones overwrite the other).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Weights {
    pub hb: [f64; 3],
    pub ring: usize,
}

/// Mutable per-particle state of the particle pass.
pub(crate) struct Motion<'a> {
    pub x: &'a mut [V3],
    pub v: &'a mut [V3],
    pub w: &'a mut [V3],
    pub past: &'a mut Past,
    /// Positions the largest displacement is measured from (the last near-list refresh);
    /// empty: not measured this step.
    pub x_ref: &'a [RefV3],
    pub walls: &'a mut WallList,
}

/// One block's share of `Motion`; `older` slots are overwritten with the current derivatives.
pub(super) struct BlockMotion<'a> {
    pub lo: usize,
    pub x: &'a mut [V3],
    pub v: &'a mut [V3],
    pub w: &'a mut [V3],
    pub newer: [&'a [PastV3]; 3],
    pub older: [&'a mut [PastV3]; 3],
    pub widx: &'a [u32],
    pub whist: &'a mut [[V3; 3]],
}

/// Pass 2, fused: accelerations and the multistep update (`step`) in one sweep, on the `kernel`
/// path.
pub(crate) fn update_pass<const FR: bool>(
    kernel: Kernel,
    p: &DemParams,
    step: Weights,
    m: Motion,
    ext: &[V3],
    sc: Sums,
) -> Stats {
    let n = m.x.len();
    let older = 1 - step.ring;
    let mut wb = wall_blocks(m.walls, n).into_iter();
    let [pv, pa, pw] = [&mut m.past.v, &mut m.past.a, &mut m.past.alpha].map(|s| {
        let (s0, s1) = s.split_at_mut(1);
        let (s0, s1) = (&mut s0[0][..], &mut s1[0][..]);
        if older == 0 {
            (s1.chunks(BLOCK), s0.chunks_mut(BLOCK))
        } else {
            (s0.chunks(BLOCK), s1.chunks_mut(BLOCK))
        }
    });
    let (mut nv, mut ov) = pv;
    let (mut na, mut oa) = pa;
    let (mut nw, mut ow) = pw;
    let mut work = Vec::with_capacity(n.div_ceil(BLOCK));
    for (b, ((x, v), w)) in m.x.chunks_mut(BLOCK).zip(m.v.chunks_mut(BLOCK)).zip(m.w.chunks_mut(BLOCK)).enumerate() {
        let (widx, whist) = wb.next().expect("wall block");
        let mut nx = || (nv.next().unwrap(), na.next().unwrap(), nw.next().unwrap());
        let (a0, a1, a2) = nx();
        let older = [ov.next().unwrap(), oa.next().unwrap(), ow.next().unwrap()];
        work.push(BlockMotion { lo: b * BLOCK, x, v, w, newer: [a0, a1, a2], older, widx, whist });
    }
    let x_ref = m.x_ref;
    work.into_par_iter()
        .map(|bm| update_block_on::<FR>(kernel, p, step, bm, x_ref, ext, sc))
        .reduce(|| Stats::ZERO, Stats::max)
}

/// One block of the fused particle pass on the `kernel` path (the portable one when the CPU
/// lacks it).
pub(crate) fn update_block_on<const FR: bool>(
    kernel: Kernel,
    p: &DemParams,
    step: Weights,
    bm: BlockMotion,
    x_ref: &[RefV3],
    ext: &[V3],
    sc: Sums,
) -> Stats {
    #[cfg(target_arch = "x86_64")]
    match kernel {
        Kernel::Avx512 => {
            if let Some(isa) = Isa::avx512() {
                // SAFETY: `isa` proves the features the function is compiled for.
                return unsafe { update_block_avx512::<FR>(isa, p, step, bm, (x_ref, ext), sc) };
            }
        }
        Kernel::Avx2 => {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has the feature the function is compiled for.
                return unsafe { update_block_avx2::<FR>(p, step, bm, (x_ref, ext), sc) };
            }
        }
        Kernel::Portable => {}
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = kernel;
    update_block::<FR, false>(Isa::PORTABLE, p, step, bm, (x_ref, ext), sc)
}

/// # Safety
/// The CPU has avx512f, avx512vl and bmi2 (which `isa` proves).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,bmi2")]
unsafe fn update_block_avx512<const FR: bool>(
    isa: Isa<true>,
    p: &DemParams,
    step: Weights,
    bm: BlockMotion,
    refs: (&[RefV3], &[V3]),
    sc: Sums,
) -> Stats {
    update_block::<FR, true>(isa, p, step, bm, refs, sc)
}

/// # Safety
/// The CPU has avx2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn update_block_avx2<const FR: bool>(
    p: &DemParams,
    step: Weights,
    bm: BlockMotion,
    refs: (&[RefV3], &[V3]),
    sc: Sums,
) -> Stats {
    update_block::<FR, false>(Isa::PORTABLE, p, step, bm, refs, sc)
}

/// Block `bm`: forces, accelerations, the multistep update, and (unless `x_ref` is empty) the
/// largest squared displacement since `x_ref`.
#[inline(always)]
fn update_block<const FR: bool, const V: bool>(
    isa: Isa<V>,
    p: &DemParams,
    Weights { hb, .. }: Weights,
    bm: BlockMotion,
    (x_ref, ext): (&[RefV3], &[V3]),
    sc: Sums,
) -> Stats {
    let BlockMotion { lo, x, v, w, newer, older, widx, whist } = bm;
    let len = x.len();
    assert!(len <= BLOCK && v.len() == len && w.len() == len, "block size");
    let mut rows = [MaybeUninit::<Acc>::uninit(); BLOCK];
    let (acc, mut st) = block_forces::<FR>(p, lo, (x, v, w), ext, sc, (widx, whist), &mut rows[..len]);
    // Accelerations straight into the flat arrays the update reads.
    let (mut a, mut al) = ([MaybeUninit::<V3>::uninit(); BLOCK], [MaybeUninit::<V3>::uninit(); BLOCK]);
    let a = written(&mut a[..len], |l| accel_of(p, &acc[l], v[l]));
    let al = written(&mut al[..len], |l| alpha_of::<FR>(p, &acc[l], w[l]));
    let [ov, oa, ow] = older;
    // x first: it uses the old velocities.
    let vel: &[f64] = v.as_flattened();
    (st.moved, st.extent) =
        ab_flat_moved(isa, hb, x.as_flattened_mut(), vel, newer[0].as_flattened(), ov.as_flattened_mut());
    ab_flat(hb, v.as_flattened_mut(), a.as_flattened(), newer[1].as_flattened(), oa.as_flattened_mut());
    if FR {
        ab_flat(hb, w.as_flattened_mut(), al.as_flattened(), newer[2].as_flattened(), ow.as_flattened_mut());
    }
    if x_ref.is_empty() {
        return st; // the system's bound on the displacement stands in for the check
    }
    // Largest squared displacement since `x_ref`, as eight partial maxima (a vector
    // max instead of a serial chain; max is exact, so the grouping does not matter).
    let mut part = [0.0f64; 8];
    for (l, (&xn, &xb)) in x.iter().zip(&x_ref[lo..lo + len]).enumerate() {
        let d2 = dist2(xn, widen(xb));
        part[l % 8] = if d2 > part[l % 8] { d2 } else { part[l % 8] };
    }
    st.disp2 = part.iter().fold(st.disp2, |a, &b| if b > a { b } else { a });
    st
}
