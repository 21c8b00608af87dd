//! `bench -- halo`: what an axial slab split of the settled 44-mm bed (the DEM bench's anchor,
//! 25,000 particles) would cost one bed spread over several machines (docs/DEPLOY.md). For 2, 4
//! and 8 slabs of equal particle count, each slab's ghosts are the particles of its neighbours
//! within one contact cutoff plus the Verlet skin, d (1 + skin), of its faces. Measured on one
//! thread, interleaved in blocks in one process: the DEM step of every slab with its ghosts
//! against the slab alone (the extra contact, list and integration work a rank would do), and
//! the ghost state a rank sends per step (position, velocity, spin and id: 80 bytes a particle),
//! and the work of all ranks with their ghosts over the whole bed's on one thread.
//! Last line `{"bench":"halo","slabs":[…],"ghost_fraction":[…],"extra_cost":[…],
//! "bytes_per_rank_step":[…],"work_over_whole_bed":[…]}`.

use crate::dem::{bench_case, load_anchor};
use fluidbed_core::case::{Bed, ExplicitBed};
use fluidbed_core::dem::DemSystem;
use std::time::Instant;

const BYTES_PER_GHOST: usize = 80;

/// A DEM system of these particles, at rest, under the anchor's settings.
fn system(positions: Vec<[f64; 3]>) -> DemSystem {
    let mut case = bench_case();
    case.bed = Bed::Explicit(ExplicitBed { positions_m: positions.clone(), velocities_m_s: None });
    let n = positions.len();
    DemSystem::new(&case, positions, vec![[0.0; 3]; n])
}

pub fn run() {
    let Some(mut positions) = load_anchor() else {
        eprintln!("../shared/anchors/settled_25000.data.gz not found");
        std::process::exit(1);
    };
    positions.sort_by(|a, b| a[2].total_cmp(&b[2]));
    let case = bench_case();
    let width = case.particles.diameter_m * (1.0 + case.dem.skin_fraction);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let time = |s: &mut DemSystem, steps: usize| {
        let t0 = Instant::now();
        for _ in 0..steps {
            s.step();
        }
        t0.elapsed().as_secs_f64()
    };
    // The whole bed on one thread, the same 1,000 steps after the same warm-up.
    let t_whole = pool.install(|| {
        let mut s = system(positions.clone());
        time(&mut s, 100);
        time(&mut s, 1000)
    });
    eprintln!("halo: the whole bed, 1,000 DEM steps on one thread: {t_whole:.3} s");
    let (mut slabs_out, mut fractions, mut costs, mut bytes, mut work) = (vec![], vec![], vec![], vec![], vec![]);
    for slabs in [2usize, 4, 8] {
        let n = positions.len();
        let bounds: Vec<usize> = (0..=slabs).map(|k| k * n / slabs).collect();
        let (mut alone, mut haloed, mut ghosts, mut most_ghosts) = (Vec::new(), Vec::new(), 0usize, 0usize);
        for k in 0..slabs {
            let own = &positions[bounds[k]..bounds[k + 1]];
            let (lo, hi) = (own[0][2], own[own.len() - 1][2]);
            let halo: Vec<[f64; 3]> = positions[..bounds[k]]
                .iter()
                .chain(&positions[bounds[k + 1]..])
                .filter(|p| p[2] > lo - width && p[2] < hi + width)
                .copied()
                .collect();
            ghosts += halo.len();
            most_ghosts = most_ghosts.max(halo.len());
            alone.push(own.to_vec());
            haloed.push(own.iter().chain(&halo).copied().collect::<Vec<_>>());
        }
        let (t_alone, t_haloed) = pool.install(|| {
            let mut a: Vec<DemSystem> = alone.into_iter().map(system).collect();
            let mut h: Vec<DemSystem> = haloed.into_iter().map(system).collect();
            for s in a.iter_mut().chain(h.iter_mut()) {
                time(s, 100);
            }
            let (mut ta, mut th) = (0.0, 0.0);
            for _ in 0..10 {
                for (sa, sh) in a.iter_mut().zip(h.iter_mut()) {
                    ta += time(sa, 100);
                    th += time(sh, 100);
                }
            }
            (ta, th)
        });
        let fraction = ghosts as f64 / n as f64;
        let cost = t_haloed / t_alone - 1.0;
        let total_work = t_haloed / t_whole;
        eprintln!(
            "halo: {slabs} slabs of {} particles, {ghosts} ghosts in all ({:.1}% of the bed; at most {most_ghosts} on one rank), 1,000 DEM steps {:.3} s alone vs {:.3} s with ghosts: +{:.1}%; all ranks together do {:.2}× the whole bed's work",
            n / slabs,
            100.0 * fraction,
            t_alone,
            t_haloed,
            100.0 * cost,
            total_work
        );
        work.push(format!("{total_work:.3}"));
        slabs_out.push(slabs);
        fractions.push(format!("{fraction:.4}"));
        costs.push(format!("{cost:.4}"));
        bytes.push(most_ghosts * BYTES_PER_GHOST);
    }
    let list = |v: &[String]| v.join(",");
    println!(
        "{{\"bench\":\"halo\",\"particles\":{},\"halo_width_m\":{width:.6},\"slabs\":{slabs_out:?},\"ghost_fraction\":[{}],\"extra_cost\":[{}],\"bytes_per_rank_step\":{bytes:?},\"work_over_whole_bed\":[{}]}}",
        positions.len(),
        list(&fractions),
        list(&costs),
        list(&work)
    );
}
