//! Bubbling (issue: coupling): the 44-mm bed at U = 0.6 m/s runs (two simulated seconds, so that
//! `fluidized` has a long time mean; the issue asks for one) with no watchdog stop; voidage maps
//! every 50 ms from 0.7 to 1 s show the bubbles (cf. paper Fig. 9). The run's ΔP series and the
//! particles' momentum budget are kept in target/validate-cache for `fluidized` too, beside the
//! run's last checkpoint (its analysis is read from there); a stopped run resumes from the
//! checkpoint it keeps there every 0.05 s.

use crate::common::*;
use fluidbed_core::case::Field;
use serde::{Deserialize, Serialize};
use serde_json::json;

#[derive(Serialize, Deserialize)]
pub struct RunSummary {
    pub particles: usize,
    pub end_s: f64,
    /// (time, ΔP) per snapshot.
    pub dp: Vec<(f64, f64)>,
    /// Largest share of nearly empty cells (ε > 0.8) below 30 mm after t = 0.4 s.
    pub bubble_fraction_max: f64,
    pub wall_s: f64,
    /// Momentum budget of the particles per snapshot: (time, plate, tube, gas force, momentum),
    /// vertical components in N and kg m/s (empty in runs kept by earlier builds).
    #[serde(default)]
    pub budget: Vec<[f64; 5]>,
    /// The run's analysis from `ANALYSIS_FROM_S` to the end, read by this build from the run's
    /// last checkpoint (kept beside the cache), so a report that gained figures needs no rerun.
    #[serde(skip)]
    pub analysis: Option<fluidbed_core::sim::AnalysisReport>,
}

/// Start of the run's analysis window: after the 240-ms ramp and the first eruptions, as `fluidized`.
pub const ANALYSIS_FROM_S: f64 = 0.4;

/// Simulated seconds of the run both validations read (`FLUIDBED_BUBBLING_END_S` overrides).
pub fn end_s() -> f64 {
    std::env::var("FLUIDBED_BUBBLING_END_S").ok().and_then(|s| s.parse().ok()).unwrap_or(2.0)
}

/// The bubbling case: cases/bubbling-44mm.json, or the file `FLUIDBED_BUBBLING_CASE` names.
pub fn case() -> fluidbed_core::case::Case {
    match std::env::var("FLUIDBED_BUBBLING_CASE") {
        Ok(path) => load_case_path(&path),
        Err(_) => load_case("bubbling-44mm.json"),
    }
}

/// The bubbling case as the run to `end_s` runs it, and where that run is kept (named after the
/// case it ran, so an edited case runs anew). Bincode, not JSON: the analysis holds NaN where a
/// figure has no value, which JSON would write as null and then not read back.
fn run_case(end_s: f64) -> (fluidbed_core::case::Case, String) {
    let mut case = case();
    case.end_time_s = end_s;
    case.outputs.snapshot_interval_s = 0.005;
    case.outputs.fields = vec![Field::Voidage, Field::Pressure];
    case.analysis.from_s = ANALYSIS_FROM_S;
    let key = cache_key(&case);
    (case, format!("target/validate-cache/bubbling-44mm-{end_s}s-{key:016x}.bin"))
}

/// The last checkpoint of the finished run to `end_s`, if it has finished.
pub fn kept_checkpoint(end_s: f64) -> Option<Vec<u8>> {
    let (_, cache) = run_case(end_s);
    std::fs::metadata(&cache).ok()?;
    std::fs::read(format!("{cache}.ckpt")).ok()
}

/// The run of the bubbling case to `end_s`, from the cache or run now.
pub fn run_to(end_s: f64) -> RunSummary {
    let (case, cache) = run_case(end_s);
    let cache = cache.as_str();
    let (ckpt, partial) = (format!("{cache}.ckpt"), format!("{cache}.partial"));
    if let Ok(bytes) = std::fs::read(cache) {
        match bincode::deserialize::<RunSummary>(&bytes) {
            Ok(mut r) => {
                eprintln!("using the run kept in {cache} (delete it to run again)");
                r.analysis = std::fs::read(&ckpt)
                    .ok()
                    .and_then(|b| fluidbed_core::sim::Simulation::analysis_of_checkpoint(&b, None).ok())
                    .map(|(_, _, a)| a);
                return r;
            }
            Err(e) => eprintln!("the run kept in {cache} does not read ({e}); running it again"),
        }
    }
    let t0 = std::time::Instant::now();
    // Progress is kept every 0.05 s beside the cache (`.ckpt`: the simulation, `.partial`: what
    // was gathered so far), so a stopped run resumes from there.
    let resumed =
        std::fs::read(&ckpt).ok().and_then(|b| fluidbed_core::sim::Simulation::restore(&b).ok()).and_then(|sim| {
            let p: Progress = bincode::deserialize(&std::fs::read(&partial).ok()?).ok()?;
            Some((sim, p))
        });
    let (mut sim, mut p) = match resumed {
        Some((sim, p)) => {
            eprintln!("resuming the bubbling case at t = {:.3} s from {ckpt}", sim.time());
            (sim, p)
        }
        None => {
            eprintln!("running the bubbling case to {end_s} s; it will be kept in {cache}");
            (fluidbed_core::sim::Simulation::new(case, Some(&bed_cache())).expect("build"), Progress::default())
        }
    };
    let wall_before = p.wall_s;
    while !sim.is_finished() {
        if let Some(s) = sim.advance(u64::MAX).unwrap_or_else(|e| panic!("bubbling: {e}")) {
            let dem = sim.dem();
            let [plate, tube, _] = dem.wall_loads();
            p.budget.push([s.time_s, plate, tube, dem.external_force_total()[2], dem.momentum()[2]]);
            if let Some(dp) = s.pressure_drop_pa {
                p.dp.push((s.time_s, dp));
            }
            let eps = s.voidage.as_ref().expect("voidage field");
            if s.time_s >= 0.4 - 1e-9 {
                let g = s.grid.grid();
                let bed = &eps[..(0.03 / g.dz).floor() as usize * g.cells_per_layer()];
                let f = bed.iter().filter(|&&e| e > 0.8).count() as f64 / bed.len() as f64;
                p.bubble_fraction_max = p.bubble_fraction_max.max(f);
            }
            let ms = (s.time_s * 1000.0).round() as i64;
            if (700..=1000).contains(&ms) && ms % 50 == 0 {
                crate::plots::voidage_slice(&s, eps, &format!("docs/img/bubbling_voidage_{ms:04}ms.png"));
            }
            if s.index % 10 == 0 {
                p.wall_s = wall_before + t0.elapsed().as_secs_f64();
                eprintln!(
                    "[bubbling] t = {:.3} s, ΔP = {:.0} Pa, wall {:.0} s",
                    s.time_s,
                    s.pressure_drop_pa.unwrap_or(0.0),
                    p.wall_s
                );
                std::fs::create_dir_all("target/validate-cache").expect("cache dir");
                write_atomically(&ckpt, &sim.checkpoint());
                write_atomically(&partial, &bincode::serialize(&p).expect("progress"));
            }
        }
    }
    crate::plots::pressure_trace(&p.dp, "docs/img/bubbling_dp.png");
    let r = RunSummary {
        particles: sim.dem().len(),
        end_s: sim.time(),
        dp: p.dp,
        bubble_fraction_max: p.bubble_fraction_max,
        wall_s: wall_before + t0.elapsed().as_secs_f64(),
        budget: p.budget,
        analysis: Some(sim.analysis_report()),
    };
    std::fs::create_dir_all("target/validate-cache").expect("cache dir");
    // The last checkpoint stays beside the summary: the analysis is read from it.
    write_atomically(&ckpt, &sim.checkpoint());
    write_atomically(cache, &bincode::serialize(&r).expect("run summary"));
    let _ = std::fs::remove_file(&partial);
    r
}

/// What a run has gathered so far (kept beside its checkpoint).
#[derive(Default, Serialize, Deserialize)]
struct Progress {
    dp: Vec<(f64, f64)>,
    budget: Vec<[f64; 5]>,
    bubble_fraction_max: f64,
    wall_s: f64,
}

pub fn run() -> serde_json::Value {
    let r = run_to(end_s());
    let case = case();
    let (weight, head) = expected_dp(&case, r.particles);
    let want = weight + head;
    let tail: Vec<f64> = r.dp.iter().filter(|(t, _)| *t >= 0.4).map(|x| x.1).collect();
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    eprintln!(
        "ran {:.3} s simulated in {:.0} s wall; largest bubble share of the bed cells {:.3}",
        r.end_s, r.wall_s, r.bubble_fraction_max
    );
    json!({"name": "bubbling", "figure": r.bubble_fraction_max, "reference": want, "mean_dp_pa": mean, "rel_err": mean / want - 1.0,
           "simulated_s": r.end_s, "wall_s": r.wall_s, "watchdog_stops": 0,
           "note": "figure: largest share of bed cells with ε > 0.8 (bubbles); rel_err: mean ΔP vs bed weight less buoyancy plus the gas head"})
}
