//! DEM throughput on the settled 44-mm bed (~25,000 particles, LIGGGHTS anchor settings):
//! 1,000 warm-up steps, then 2,000 timed steps, once on 1 thread and once on all cores.
//! Prints `{"bench":"dem","kernel":…,"particles":…,"steps":…,"threads":…,"particle_steps_per_s":…}`
//! per run, the kernel being the code path that ran (`FLUIDBED_KERNEL`, else the best the CPU has).
//! `bench -- dem shaken`: the same with random initial velocities (lists refreshed often).
//! `bench -- dem reproducible`: the cost of `dem.reproducible` (see `reproducible_cost`).
//! `bench -- dem pour`: instead, time `build_bed` for the default particles poured to a settled
//! height (7k bed: 30-mm column, 15 mm; 30k bed: 44-mm column, 30 mm), one JSON line each.

use fluidbed_core::case::{Bed, Case, Damping, ExplicitBed, GeneratedBed};
use fluidbed_core::dem::{build_bed, DemSystem};
use std::time::Instant;

const ANCHOR: &str = "../shared/anchors/settled_25000.data.gz";

/// The anchor scene: paper Table 1 particles with e = 0.9 for normal and tangential damping.
pub fn bench_case() -> Case {
    let mut c: Case = serde_json::from_str(
        r#"{"column":{"diameter_m":0.044,"height_m":0.06},"particles":{},"bed":{"generated":{"count":25000,"seed":1}}}"#,
    )
    .expect("bench case");
    c.particles.diameter_m = 0.0012;
    c.particles.density_kg_m3 = 1000.0;
    c.particles.youngs_modulus_pa = 1.2e8;
    c.particles.poisson_ratio = 0.33;
    c.particles.sliding_friction = 0.1;
    c.particles.normal_damping = Damping::Restitution(0.9);
    c.particles.tangential_damping = Damping::Restitution(0.9);
    c.dem.time_step_s = 1.25e-6;
    c.dem.skin_fraction = 0.3;
    c.gravity_m_s2 = 9.81;
    c
}

/// Positions from the LAMMPS data file (columns id type diameter density x y z), in id order.
pub fn load_anchor() -> Option<Vec<[f64; 3]>> {
    let candidates =
        [ANCHOR.to_string(), format!("{}/../../shared/anchors/settled_25000.data.gz", env!("CARGO_MANIFEST_DIR"))];
    let path = candidates.iter().find(|p| std::path::Path::new(p).exists())?;
    let out = std::process::Command::new("zcat").arg(path).output().ok()?;
    let text = String::from_utf8(out.stdout).ok()?;
    let mut rows: Vec<(u64, [f64; 3])> = Vec::new();
    let mut in_atoms = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with("Atoms") {
            in_atoms = true;
            continue;
        }
        if !in_atoms || t.is_empty() {
            continue;
        }
        let f: Vec<&str> = t.split_whitespace().collect();
        if f.len() < 7 {
            if !rows.is_empty() {
                break;
            }
            continue;
        }
        let num = |k: usize| f[k].parse::<f64>().ok();
        rows.push((f[0].parse().ok()?, [num(4)?, num(5)?, num(6)?]));
    }
    rows.sort_by_key(|r| r.0);
    Some(rows.into_iter().map(|r| r.1).collect())
}

/// Time pouring the default particles to a settled height in a column (no cache).
fn pour(column_mm: f64, height_mm: f64) {
    let mut c: Case = serde_json::from_str(
        r#"{"column":{"diameter_m":0.044,"height_m":0.12},"particles":{},"bed":{"generated":{"settled_height_m":0.03,"seed":1}}}"#,
    )
    .expect("pour case");
    c.column.diameter_m = column_mm / 1000.0;
    c.bed = Bed::Generated(GeneratedBed { settled_height_m: Some(height_mm / 1000.0), count: None, seed: 1 });
    let t0 = Instant::now();
    let (x, _) = build_bed(&c, None).expect("bed");
    let secs = t0.elapsed().as_secs_f64();
    let top = x.iter().map(|p| p[2]).fold(0.0, f64::max) + c.particles.diameter_m / 2.0;
    println!(
        "{{\"bench\":\"dem_pour\",\"column_mm\":{column_mm},\"height_mm\":{height_mm},\"particles\":{},\"threads\":{},\"seconds\":{secs:.1},\"bed_top_mm\":{:.2}}}",
        x.len(),
        rayon::current_num_threads(),
        top * 1000.0
    );
}

pub fn run() {
    if std::env::args().nth(2).as_deref() == Some("pour") {
        pour(30.0, 15.0);
        pour(44.0, 30.0);
        return;
    }
    if std::env::args().nth(2).as_deref() == Some("reproducible") {
        return reproducible_cost();
    }
    // `bench -- dem shaken`: the same bed with every particle thrown at up to 0.5 m/s (seeded),
    // so the lists are refreshed and rebuilt often, as in a bubbling bed.
    let shaken = std::env::args().nth(2).as_deref() == Some("shaken");
    let mut case = bench_case();
    let positions = match load_anchor() {
        Some(p) => p,
        None => {
            eprintln!("{ANCHOR} not found: pouring the bed with build_bed (slow)");
            case.bed = Bed::Generated(GeneratedBed { settled_height_m: None, count: Some(25000), seed: 1 });
            build_bed(&case, Some(std::path::Path::new("target/bed-cache"))).expect("bed").0
        }
    };
    case.bed = Bed::Explicit(ExplicitBed { positions_m: positions.clone(), velocities_m_s: None });
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let mut counts = vec![1];
    if cores > 1 {
        counts.push(cores);
    }
    // Profiling overrides, e.g. FLUIDBED_DEM_BENCH="0,200,1" for callgrind: warm-up, timed, threads.
    let (mut warm, mut timed) = (1000u64, 2000u64);
    if let Ok(spec) = std::env::var("FLUIDBED_DEM_BENCH") {
        let f: Vec<u64> = spec.split(',').filter_map(|s| s.trim().parse().ok()).collect();
        if f.len() == 3 {
            (warm, timed, counts) = (f[0], f[1], vec![f[2] as usize]);
        }
    }
    for threads in counts {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        pool.install(|| {
            let mut seed = 0x9e37_79b9_7f4a_7c15u64;
            let mut uniform = || {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            };
            let speed = if shaken { 0.5 / 3f64.sqrt() } else { 0.0 };
            let v0 = positions.iter().map(|_| [0; 3].map(|_| speed * uniform())).collect();
            let mut sys = DemSystem::new(&case, positions.clone(), v0);
            for _ in 0..warm {
                sys.step();
            }
            let t0 = Instant::now();
            for _ in 0..timed {
                sys.step();
            }
            let secs = t0.elapsed().as_secs_f64();
            let rate = sys.len() as f64 * timed as f64 / secs;
            let (builds, refreshes) = sys.list_builds();
            let (outer, near) = sys.list_sizes();
            let per = |e: usize| e as f64 / sys.len() as f64;
            eprintln!(
                "dem: {threads} thread(s), {:.3} s, state {:016x}, KE {:.3e} J, max overlap {:.2e} d, {builds} Verlet builds, {refreshes} near-list refreshes, {:.2} / {:.2} entries per particle, {} touching",
                secs,
                state_digest(&sys),
                sys.kinetic_energy(),
                sys.max_overlap_fraction(),
                per(outer),
                per(near),
                sys.touching_pairs().map_or("n/a (no friction)".into(), |t| format!("{:.2}", per(t)))
            );
            println!(
                "{{\"bench\":\"{}\",\"kernel\":\"{}\",\"particles\":{},\"steps\":{},\"threads\":{},\"particle_steps_per_s\":{:.0}}}",
                if shaken { "dem_shaken" } else { "dem" },
                sys.kernel(),
                sys.len(),
                timed,
                threads,
                rate
            );
        });
    }
}

/// `bench -- dem reproducible`: the settled bed stepped with the default work split and with
/// `dem.reproducible` (fixed chunks) on all cores, interleaved in blocks of 200 steps in one
/// process (so that the VM's drifts hit both alike); one JSON line with both rates.
fn reproducible_cost() {
    let Some(positions) = load_anchor() else {
        eprintln!("{ANCHOR} not found");
        std::process::exit(1);
    };
    let mut case = bench_case();
    case.bed = Bed::Explicit(ExplicitBed { positions_m: positions.clone(), velocities_m_s: None });
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        let mut systems: Vec<DemSystem> = [false, true]
            .map(|on| {
                let mut c = case.clone();
                c.dem.reproducible = on;
                DemSystem::new(&c, positions.clone(), vec![[0.0; 3]; positions.len()])
            })
            .into();
        for s in systems.iter_mut() {
            for _ in 0..1000 {
                s.step();
            }
        }
        let (rounds, block) = (10, 200);
        let mut secs = [0.0f64; 2];
        for _ in 0..rounds {
            for (k, s) in systems.iter_mut().enumerate() {
                let t0 = Instant::now();
                for _ in 0..block {
                    s.step();
                }
                secs[k] += t0.elapsed().as_secs_f64();
            }
        }
        let rate = |k: usize| (positions.len() * rounds * block) as f64 / secs[k];
        println!(
            "{{\"bench\":\"dem_reproducible\",\"kernel\":\"{}\",\"threads\":{threads},\"default_particle_steps_per_s\":{:.0},\"reproducible_particle_steps_per_s\":{:.0},\"cost\":{:.3}}}",
            systems[0].kernel(),
            rate(0),
            rate(1),
            rate(0) / rate(1) - 1.0
        );
    });
}

/// FNV-1a over the bits of every position, velocity and spin: equal digests mean a code change
/// left the trajectory bit for bit the same (for one thread count).
fn state_digest(sys: &DemSystem) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for arr in [sys.positions(), sys.velocities(), sys.angular_velocities()] {
        for c in arr.iter().flatten() {
            h = (h ^ c.to_bits()).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}
