//! Slug rise velocity (issue: science, paper section 3.4 and Fig. 8): a tall bed of the paper's
//! particles — the bubbling case's 44-mm column and grid (dr 4.4 mm, layers dr/2, its voidage),
//! 160 mm settled as the paper's slugging bed (≈ 165k particles), 0.321 m tall — at four velocities
//! between 1.2 and 2 U_mf. (The 22-mm column, D/d = 18, made flat wall-spanning plugs, for which
//! the formula is not meant, and a 90-mm bed in the 44-mm column had only growing bubbles at its
//! probes: docs/VALIDATION.md; 44 mm is D/d = 37, near the paper's 50-mm tube.) Each run's
//! analysis (accumulated while it runs, from `FROM_S` to `END_S`) gives the rise velocity by
//! cross-correlating the cross-section voidage at 120 and 160 mm above the distributor (the paper:
//! slugs fully formed from ≈ 120 mm, measured at 140 mm; Müller et al. 2007a's method), against
//! Stewart & Davidson (1967):
//! u_s = (U − U_mf) + 0.35 √(g D), with U_mf = 0.30 m/s (the paper's measured value).
//! Figure: the worst relative error of the four; beside it the slope of u_s against U − U_mf
//! (the paper's point that U − U_mf belongs in the formula: near 1).
//!
//! Each velocity is a long run (≈ 2.6 simulated s): it keeps a checkpoint in target/validate-cache
//! every 0.05 s and resumes there; a finished run keeps its last checkpoint there and is not run
//! again (its analysis is read from that checkpoint by the current build). Voidage slices
//! of the last snapshots go to docs/img/slug_rise_44mm_160mm_U*.png, to tell round-nosed slugs from
//! wall-spanning plugs.

use crate::common::*;
use fluidbed_core::case::{Bed, Case, Field};
use fluidbed_core::sim::{AnalysisReport, Simulation};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// Superficial velocities (m/s): 1.8, 2, 1.4 and 1.2 U_mf, the paper's slugging set, run in this
/// order: the clearest slugs first, and the two that `pressure-oscillation` reads.
const VELOCITIES: [f64; 4] = [0.54, 0.60, 0.425, 0.37];
/// U_mf of the formula (the paper's measured value; `validate -- umf` for the model's).
const UMF: f64 = 0.30;
/// Start of the analysis window (after the 0.24-s ramp and the first slugs through the probes) and
/// the end: 2 s of slugging.
const FROM_S: f64 = 0.8;
const END_S: f64 = 2.8;
const SETTLED_M: f64 = 0.16;
const COLUMN_M: f64 = 0.3212; // 146 layers of 2.2 mm
/// The two cross-sections of the rise velocity (m above the distributor), about the paper's 140 mm.
const PROBES_M: [f64; 2] = [0.12, 0.16];

/// What a finished run keeps beside its last checkpoint.
#[derive(Serialize, Deserialize)]
struct Kept {
    particles: usize,
    wall_s: f64,
}

/// A finished run: what it kept and the analysis of its last checkpoint.
pub struct Finished {
    particles: usize,
    wall_s: f64,
    pub analysis: AnalysisReport,
}

/// The slugging bed at superficial velocity `u`.
fn case(u: f64) -> Case {
    let mut c = load_case("bubbling-44mm.json");
    c.name = format!("slug rise: 44 mm, {} mm settled, U = {u} m/s", SETTLED_M * 1e3);
    c.column.height_m = COLUMN_M;
    if let Bed::Generated(g) = &mut c.bed {
        g.settled_height_m = Some(SETTLED_M);
    }
    let gas = c.gas.as_mut().expect("the quickstart has gas");
    gas.superficial_velocity_m_s = u;
    gas.ramp_time_s = 0.24;
    c.end_time_s = END_S;
    c.outputs.snapshot_interval_s = 0.01;
    c.outputs.fields = vec![Field::Voidage];
    c.analysis.from_s = FROM_S;
    c.analysis.rise_heights_m = Some(PROBES_M);
    let report = c.validate();
    assert!(report.is_ok(), "slug-rise case invalid: {:?}", report.errors);
    c
}

/// Stewart & Davidson's slug rise velocity in a tube of diameter `d` (m/s).
pub fn stewart_davidson(u: f64, umf: f64, d: f64) -> f64 {
    (u - umf) + 0.35 * (9.81 * d).sqrt()
}

/// Where the run at `u` is kept (`.ckpt`: its checkpoint, the last one once it has finished).
fn cache_path(u: f64) -> String {
    let key = fluidbed_core::dem::fnv1a(&serde_json::to_string(&case(u)).expect("case to JSON"));
    format!("target/validate-cache/slug-rise-U{u}-{key:016x}.bin")
}

/// The finished run at `u`, if it has finished (never starts it).
pub fn finished_at(u: f64) -> Option<Finished> {
    let cache = cache_path(u);
    let kept = bincode::deserialize::<Kept>(&std::fs::read(&cache).ok()?).ok()?;
    let bytes = std::fs::read(format!("{cache}.ckpt")).ok()?;
    let (_, _, analysis) = Simulation::analysis_of_checkpoint(&bytes, None).ok()?;
    Some(Finished { particles: kept.particles, wall_s: kept.wall_s, analysis })
}

/// The run at `u`, from the cache, resumed from its checkpoint or run now.
fn run_at(u: f64) -> Finished {
    let case = case(u);
    let cache = cache_path(u);
    let ckpt = format!("{cache}.ckpt");
    if let Some(done) = finished_at(u) {
        eprintln!("[slug-rise U={u}] using the run kept in {cache} and {ckpt} (delete them to run again)");
        return done;
    }
    // The wall time so far rides in the checkpoint's file name's sibling.
    let wall_file = format!("{cache}.wall");
    let resumed = std::fs::read(&ckpt).ok().and_then(|b| Simulation::restore(&b).ok());
    let wall_before: f64 = std::fs::read_to_string(&wall_file).ok().and_then(|s| s.trim().parse().ok()).unwrap_or(0.0);
    let mut sim = match resumed {
        Some(sim) => {
            eprintln!("[slug-rise U={u}] resuming at t = {:.3} s from {ckpt}", sim.time());
            sim
        }
        None => {
            eprintln!("[slug-rise U={u}] running to {END_S} s; kept in {cache}");
            Simulation::new(case, Some(&bed_cache())).unwrap_or_else(|e| panic!("slug-rise: {e}"))
        }
    };
    let t0 = std::time::Instant::now();
    std::fs::create_dir_all("target/validate-cache").expect("cache dir");
    while !sim.is_finished() {
        let Some(s) = sim.advance(u64::MAX).unwrap_or_else(|e| panic!("slug-rise U={u}: {e}")) else { continue };
        let ms = (s.time_s * 1000.0).round() as i64;
        if ms > (END_S * 1000.0) as i64 - 60 && ms % 20 == 0 {
            let eps = s.voidage.as_ref().expect("voidage field");
            crate::plots::voidage_slice(&s, eps, &format!("docs/img/slug_rise_44mm_160mm_U{u}_{ms:04}ms.png"));
        }
        if s.index % 5 == 0 {
            let wall = wall_before + t0.elapsed().as_secs_f64();
            eprintln!(
                "[slug-rise U={u}] t = {:.3} s, ΔP = {:.0} Pa, wall {wall:.0} s",
                s.time_s,
                s.pressure_drop_pa.unwrap_or(0.0)
            );
            write_atomically(&ckpt, &sim.checkpoint());
            write_atomically(&wall_file, wall.to_string().as_bytes());
        }
    }
    let kept = Kept { particles: sim.dem().len(), wall_s: wall_before + t0.elapsed().as_secs_f64() };
    // The last checkpoint stays: the finished run's analysis is read from it.
    write_atomically(&ckpt, &sim.checkpoint());
    write_atomically(&cache, &bincode::serialize(&kept).expect("kept run"));
    let _ = std::fs::remove_file(&wall_file);
    Finished { particles: kept.particles, wall_s: kept.wall_s, analysis: sim.analysis_report() }
}

/// Least-squares slope of y on x.
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

pub fn run() -> serde_json::Value {
    let d = case(VELOCITIES[0]).column.diameter_m;
    let (mut excess, mut measured, mut points) = (Vec::new(), Vec::new(), Vec::new());
    let mut worst: Option<(f64, f64, f64)> = None;
    for u in VELOCITIES {
        let k = run_at(u);
        let rise = k.analysis.rise_velocity.as_ref();
        let r = rise.and_then(|r| r.voidage.as_ref());
        let want = stewart_davidson(u, UMF, d);
        let got = r.map_or(f64::NAN, |r| r.velocity_m_s);
        let err = got / want - 1.0;
        println!(
            "{}",
            json!({"slug_rise_point": u, "particles": k.particles, "u_minus_umf": u - UMF, "rise_m_s": got,
                "stewart_davidson_m_s": want, "rel_err": err, "peak": r.map(|r| r.peak), "delay_s": r.map(|r| r.delay_s),
                "heights_m": rise.map(|r| [r.lower_m, r.upper_m]), "bed_height_m": k.analysis.bed_height_m,
                "dp_dominant_hz": k.analysis.pressure_drop.as_ref().and_then(|p| p.dominant_frequency_hz),
                "eruptions_per_s": k.analysis.eruptions.as_ref().map(|e| e.fronts.count.per_second),
                "dp_cycles_per_eruption": k.analysis.eruptions.as_ref().and_then(|e| e.dp_frequency_per_eruption),
                "window_s": [k.analysis.from_s, k.analysis.to_s], "wall_s": k.wall_s})
        );
        if got.is_finite() {
            excess.push(u - UMF);
            measured.push(got);
        }
        points.push((u - UMF, got));
        // A point without a figure (NaN) is the worst.
        if worst.is_none_or(|w| err.is_nan() || err.abs() > w.2.abs()) {
            worst = Some((got, want, err));
        }
    }
    let (figure, reference, rel_err) = worst.expect("four velocities");
    let s = if excess.len() >= 2 { slope(&excess, &measured) } else { f64::NAN };
    json!({"name": "slug-rise", "figure": figure, "reference": reference, "rel_err": rel_err,
        "slope_vs_u_minus_umf": s, "points": points, "column_diameter_m": d, "umf_m_s": UMF,
        "note": "worst of four velocities; rise velocity by cross-correlation of the cross-section voidage at 120 and 160 mm above the distributor"})
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_formula_gives_the_published_values() {
        // 0.35 √(g D) for D = 50 mm is 0.245 m/s (the paper's tube).
        let v = super::stewart_davidson(0.3, 0.3, 0.05);
        assert!((v - 0.2451).abs() < 1e-3, "{v}");
    }
}
