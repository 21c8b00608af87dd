//! Scaling (`bench -- scaling`): DEM-alone and coupled cost per particle-step, and peak resident
//! memory of the coupled run per particle, against bed size.
//!
//! Beds: the shipped bubbling case (cases/bubbling-44mm.json: d = 1.2 mm, E = 120 MPa, DEM step
//! 1.25 µs, square-grid voidage, its default coupling interval, U = 0.6 m/s) with the settled
//! height kept at 30 mm and the column widened to R = 2, 5, 11, 13 annuli of the fixed dr = 4.4 mm
//! (dz = 2.2 mm, column height 123.2 mm): 4,732, 30,148, 146,948 and 205,410 particles, and the
//! cells grow with the particles (672 to 28,392, 0.14 per particle). Each bed is the DEM's full
//! pour (`build_bed`, cached under target/fluidbed-bed-cache; the parent process pours a missing
//! bed and prints how long it took: 12 s, 82 s, 11 min, 19 min on the loaded 2-core VM).
//!
//! State measured: the settled bed with the inlet at the case's full velocity from t = 0 (no ramp),
//! i.e. a bed starting to fluidize, after a warm-up of WARMUP coupled steps. Then ROUNDS rounds of
//! ROUND DEM-alone steps (the same particles, gas off: `coupled::dem_round`) and ROUND coupled
//! steps (`coupled::coupled_round`), interleaved on one Simulation (rounds are whole coupling
//! intervals, so each coupled round starts by recomputing the drag that the DEM round cleared; the
//! gas does not advance in DEM rounds). Each size runs in its own child
//! process (`scaling one <annuli>`), which reports VmHWM from /proc/self/status after its run: the
//! peak resident memory of a process that loaded the cached bed and ran it coupled (the bed file
//! and its decoded copy count, as in any run). The sizes are visited PASSES times in turn; each
//! size's cost is the least of its passes (the VM's speed drifts over minutes, and a slow pass is
//! the other jobs'), its memory the largest. Beside the wall-clock figures each child reports the
//! CPU time of all its threads per particle-step (`cpu_ns`), which says how much of a slow figure
//! was waiting for a core rather than work.
//!
//! Last line: {"bench":"scaling","sizes","dem_ns_per_particle_step","coupled_ns_per_particle_step",
//! "bytes_per_particle",…}.

use crate::coupled::{coupled_round, dem_round, shipped_case, Tally};
use fluidbed_core::case::Case;
use fluidbed_core::sim::Simulation;
use serde_json::{json, Value};
use std::path::PathBuf;
use std::time::Instant;

/// Column radius in annuli of the case's dr.
const ANNULI: [usize; 4] = [2, 5, 11, 13];
const WARMUP: u64 = 400;
const ROUND: u64 = 200;
const ROUNDS: u64 = 4;
const PASSES: usize = 3;

fn bed_cache() -> PathBuf {
    PathBuf::from(std::env::var("FLUIDBED_BED_CACHE").unwrap_or_else(|_| "target/fluidbed-bed-cache".into()))
}

/// The shipped bubbling case in a column of `annuli` annuli, inlet at full velocity from t = 0.
fn case_for(annuli: usize) -> Case {
    let mut c = shipped_case("bubbling-44mm.json");
    c.column.diameter_m = 2.0 * annuli as f64 * c.grid.dr_m;
    c.gas.as_mut().expect("the case has gas").ramp_time_s = 0.0;
    let report = c.validate();
    assert!(report.is_ok(), "scaled case invalid: {:?}", report.errors);
    c
}

/// The poured bed of `case` in the cache: seconds it took and whether it was poured now.
fn ensure_bed(case: &Case) -> (f64, bool) {
    let dir = bed_cache();
    let files = || std::fs::read_dir(&dir).map(|d| d.count()).unwrap_or(0);
    let before = files();
    let t0 = Instant::now();
    fluidbed_core::dem::build_bed(case, Some(&dir)).expect("bed pours");
    (t0.elapsed().as_secs_f64(), files() > before)
}

/// A `/proc/self/status` figure in bytes: `VmHWM` (peak resident set) or `VmRSS` (now).
fn status_bytes(key: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let line = status.lines().find(|l| l.starts_with(key)).unwrap_or_else(|| panic!("no {key} line"));
    let kb: u64 = line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).expect("a value in kB");
    kb * 1024
}

/// CPU time of all this process's threads so far (ns; first field of each task's schedstat).
/// Beside the wall time: on a VM loaded by other jobs it says how much of a slow step was waiting.
fn cpu_ns() -> u64 {
    let tasks = std::fs::read_dir("/proc/self/task").expect("/proc/self/task");
    let run = |e: std::fs::DirEntry| std::fs::read_to_string(e.path().join("schedstat")).ok();
    tasks.filter_map(|e| run(e.ok()?)?.split_whitespace().next()?.parse::<u64>().ok()).sum()
}

/// One size in this process (`scaling one <annuli>`): prints one JSON line.
fn one(annuli: usize) {
    let case = case_for(annuli);
    let start = status_bytes("VmHWM:");
    let mut sim = Simulation::new(case, Some(&bed_cache())).expect("case builds");
    let n = sim.dem().len();
    // Diagnostics beside the headline figure: the peak of the construction (bed file read and
    // decoded, lists built), then the peak of the run alone ("5" to clear_refs resets VmHWM to
    // the current resident set; unavailable on some kernels, then null).
    let (built_peak, built_rss) = (status_bytes("VmHWM:"), status_bytes("VmRSS:"));
    let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let mut warm = Tally::default();
    coupled_round(&mut sim, WARMUP, &mut warm);
    let (mut dem, mut cpl) = (Tally::default(), Tally::default());
    let (mut dem_cpu, mut cpl_cpu) = (0u64, 0u64);
    for _ in 0..ROUNDS {
        let c0 = cpu_ns();
        dem_round(&mut sim, ROUND, &mut dem);
        let c1 = cpu_ns();
        coupled_round(&mut sim, ROUND, &mut cpl);
        (dem_cpu, cpl_cpu) = (dem_cpu + c1 - c0, cpl_cpu + cpu_ns() - c1);
    }
    let per = |t: &Tally| t.per_step() * 1e9 / n as f64;
    let cpu_per = |ns: u64| ns as f64 / (ROUND * ROUNDS * n as u64) as f64;
    let run_peak = status_bytes("VmHWM:");
    let peak = run_peak.max(built_peak);
    let (outer, near) = sim.dem().list_sizes();
    println!(
        "{}",
        json!({"bench": "scaling_one", "annuli": annuli, "diameter_m": sim.case().column.diameter_m, "particles": n,
            "cells": sim.grid().num_cells(), "threads": rayon::current_num_threads(), "warmup_steps": WARMUP,
            "steps_per_mode": ROUND * ROUNDS, "time_s": sim.time(),
            "dem_ns_per_particle_step": per(&dem), "coupled_ns_per_particle_step": per(&cpl),
            "dem_cpu_ns_per_particle_step": cpu_per(dem_cpu), "coupled_cpu_ns_per_particle_step": cpu_per(cpl_cpu),
            "peak_rss_bytes": peak, "bytes_per_particle": peak as f64 / n as f64, "start_peak_rss_bytes": start,
            "built_peak_rss_bytes": built_peak, "built_rss_bytes": built_rss,
            "run_peak_rss_bytes": reset.then_some(run_peak), "verlet_entries": outer, "near_entries": near,
            "coupled_stages_s_per_step": cpl.stages_json(), "dem_stages_s_per_step": dem.stages_json()})
    );
}

/// Run `scaling one <annuli>` as a child and return its JSON line.
fn child(annuli: usize) -> Value {
    let exe = std::env::current_exe().expect("own executable");
    let out = std::process::Command::new(exe)
        .args(["scaling", "one", &annuli.to_string()])
        .stderr(std::process::Stdio::inherit())
        .output()
        .expect("child runs");
    assert!(out.status.success(), "scaling one {annuli} failed: {}", out.status);
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().rev().find(|l| l.starts_with('{')).expect("child printed JSON");
    println!("{line}");
    serde_json::from_str(line).expect("child JSON")
}

/// `scaling`: every size in its own child; `scaling one <annuli>`: that child.
pub fn run() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(2).map(String::as_str) == Some("one") {
        return one(args.get(3).and_then(|a| a.parse().ok()).expect("scaling one <annuli>"));
    }
    let mut pour = Vec::new();
    for &a in &ANNULI {
        let case = case_for(a);
        eprintln!("[scaling] bed of {a} annuli (D = {:.1} mm): from the cache or poured", case.column.diameter_m * 1e3);
        let (s, poured) = ensure_bed(&case);
        println!("{}", json!({"bench": "scaling_bed", "annuli": a, "seconds": s, "poured": poured}));
        pour.push(json!({"annuli": a, "seconds": s, "poured": poured}));
    }
    let mut runs: Vec<Vec<Value>> = vec![Vec::new(); ANNULI.len()];
    for _ in 0..PASSES {
        for (k, &a) in ANNULI.iter().enumerate() {
            runs[k].push(child(a));
        }
    }
    let f = |v: &Value, key: &str| v[key].as_f64().expect(key);
    let least = |k: usize, key: &str| runs[k].iter().map(|v| f(v, key)).fold(f64::INFINITY, f64::min);
    let most = |k: usize, key: &str| runs[k].iter().map(|v| f(v, key)).fold(0.0, f64::max);
    let ks = 0..ANNULI.len();
    let sizes: Vec<u64> = ks.clone().map(|k| runs[k][0]["particles"].as_u64().expect("particles")).collect();
    let cells: Vec<u64> = ks.clone().map(|k| runs[k][0]["cells"].as_u64().expect("cells")).collect();
    let dem: Vec<f64> = ks.clone().map(|k| least(k, "dem_ns_per_particle_step")).collect();
    let cpl: Vec<f64> = ks.clone().map(|k| least(k, "coupled_ns_per_particle_step")).collect();
    let bytes: Vec<f64> = ks.clone().map(|k| most(k, "bytes_per_particle")).collect();
    let dem_cpu: Vec<f64> = ks.clone().map(|k| least(k, "dem_cpu_ns_per_particle_step")).collect();
    let cpl_cpu: Vec<f64> = ks.clone().map(|k| least(k, "coupled_cpu_ns_per_particle_step")).collect();
    println!(
        "{}",
        json!({"bench": "scaling", "sizes": sizes, "cells": cells, "annuli": ANNULI, "passes": PASSES,
            "dem_ns_per_particle_step": dem, "coupled_ns_per_particle_step": cpl, "bytes_per_particle": bytes,
            "dem_cpu_ns_per_particle_step": dem_cpu, "coupled_cpu_ns_per_particle_step": cpl_cpu,
            "bed_generation": pour})
    );
}
