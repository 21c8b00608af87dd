//! Slug rise velocity (issue: science, paper section 3.4 and Fig. 8): the paper's slugging bed —
//! its particles, 160 mm settled in its 50-mm tube (≈ 210k particles) on the bubbling case's cells
//! (dr = D/10, layers dr/2) and voidage, 0.32 m tall — at four velocities between 1.2 and 2 U_mf.
//! `FLUIDBED_SLUG_COLUMN_MM=44` runs (or reads) the same bed in the bubbling case's own 44-mm
//! column (≈ 165k particles, 0.321 m), where the runs at 0.54 and 0.60 m/s made flat plugs over
//! wall slugs (docs/VALIDATION.md), which is why the check moved to the paper's tube. (The 22-
//! and 30-mm columns plugged too, and a 90-mm bed in the 44-mm column had only growing bubbles
//! at its probes.) Each run's
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
//! of the last snapshots go to docs/img/slug_rise_<D>mm_160mm_U*.png, to tell round-nosed slugs
//! from wall-spanning plugs.

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

/// The tube: its diameter in mm, its height (whole layers) and cell width.
#[derive(Clone, Copy)]
pub struct Tube {
    pub mm: u32,
    height_m: f64,
    dr_m: f64,
}

/// The paper's 50-mm tube (128 layers of 2.5 mm) and the bubbling case's 44-mm one (146 of 2.2 mm).
pub const PAPER_TUBE: Tube = Tube { mm: 50, height_m: 0.32, dr_m: 0.005 };
pub const BUBBLING_TUBE: Tube = Tube { mm: 44, height_m: 0.3212, dr_m: 0.0044 };

/// The tube of this run: the paper's, or the 44-mm one with `FLUIDBED_SLUG_COLUMN_MM=44`.
fn tube() -> Tube {
    match std::env::var("FLUIDBED_SLUG_COLUMN_MM").ok().as_deref() {
        None | Some("50") => PAPER_TUBE,
        Some("44") => BUBBLING_TUBE,
        Some(other) => panic!("FLUIDBED_SLUG_COLUMN_MM={other}: choose 50 (the paper's tube) or 44"),
    }
}

/// The slugging bed at superficial velocity `u` in `tube`.
fn case(u: f64, tube: Tube) -> Case {
    let mut c = load_case("bubbling-44mm.json");
    c.name = format!("slug rise: {} mm, {} mm settled, U = {u} m/s", tube.mm, SETTLED_M * 1e3);
    c.column.height_m = tube.height_m;
    // For the 44-mm tube these are the bubbling case's own values (the same doubles, so the same
    // case JSON and cache key as before the tubes were chosen).
    c.column.diameter_m = tube.mm as f64 * 1e-3;
    c.grid.dr_m = tube.dr_m;
    c.grid.dz_m = Some(tube.dr_m / 2.0);
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
    // The coupling these runs started with (the defaults until 2026-12-06): one set, one coupling.
    c.coupling.interval_steps = 10;
    c.coupling.pressure_force = fluidbed_core::case::PressureForce::Held;
    c.coupling.gas_voidage = fluidbed_core::case::GasVoidage::Held;
    c.coupling.gas_drag = fluidbed_core::case::GasDrag::Held;
    let report = c.validate();
    assert!(report.is_ok(), "slug-rise case invalid: {:?}", report.errors);
    c
}

/// Stewart & Davidson's slug rise velocity in a tube of diameter `d` (m/s).
pub fn stewart_davidson(u: f64, umf: f64, d: f64) -> f64 {
    (u - umf) + 0.35 * (9.81 * d).sqrt()
}

/// Where the run at `u` is kept (`.ckpt`: its checkpoint, the last one once it has finished).
fn cache_path(u: f64, tube: Tube) -> String {
    format!("target/validate-cache/slug-rise-U{u}-{:016x}.bin", cache_key(&case(u, tube)))
}

/// The finished run at `u` in `tube`, if it has finished (never starts it).
pub fn finished_at(u: f64, tube: Tube) -> Option<Finished> {
    let cache = cache_path(u, tube);
    let kept = bincode::deserialize::<Kept>(&std::fs::read(&cache).ok()?).ok()?;
    let bytes = std::fs::read(format!("{cache}.ckpt")).ok()?;
    let (_, _, analysis) = Simulation::analysis_of_checkpoint(&bytes, None).ok()?;
    Some(Finished { particles: kept.particles, wall_s: kept.wall_s, analysis })
}

/// The run at `u`, from the cache, resumed from its checkpoint or run now.
fn run_at(u: f64, tube: Tube) -> Finished {
    let case = case(u, tube);
    let cache = cache_path(u, tube);
    let ckpt = format!("{cache}.ckpt");
    if let Some(done) = finished_at(u, tube) {
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
            crate::plots::voidage_slice(&s, eps, &format!("docs/img/slug_rise_{}mm_160mm_U{u}_{ms:04}ms.png", tube.mm));
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
    let tube = tube();
    let d = case(VELOCITIES[0], tube).column.diameter_m;
    let (mut excess, mut measured, mut points) = (Vec::new(), Vec::new(), Vec::new());
    let mut worst: Option<(f64, f64, f64)> = None;
    for u in VELOCITIES {
        let k = run_at(u, tube);
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
    use super::*;

    #[test]
    fn the_formula_gives_the_published_values() {
        // 0.35 √(g D) for D = 50 mm is 0.245 m/s (the paper's tube).
        let v = super::stewart_davidson(0.3, 0.3, 0.05);
        assert!((v - 0.2451).abs() < 1e-3, "{v}");
    }

    #[test]
    fn the_runs_made_before_keep_their_cache_keys() {
        // The 50-mm run at 0.54 m/s and the finished 44-mm runs that pressure-oscillation reads.
        for (u, tube, key) in [
            (0.54, PAPER_TUBE, "ff69819feec9ea01"),
            (0.54, BUBBLING_TUBE, "bb25fcd642c143a0"),
            (0.6, BUBBLING_TUBE, "a43e74c38422ada0"),
        ] {
            let path = cache_path(u, tube);
            assert!(path.ends_with(&format!("{key}.bin")), "U = {u}, {} mm: {path}", tube.mm);
        }
    }
}
