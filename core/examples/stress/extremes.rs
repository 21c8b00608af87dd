//! The `extremes` stress case: seeded random cases drawn inside and beyond the schema's ranges
//! (inlet up to 50 m/s, overlapping particles, cells barely larger than a particle, d of
//! 0.05–10 mm, ρ_p of 10–20,000 kg/m³, E of 1e5–1e11 Pa, near-empty and over-full columns, very
//! short and very long steps). Every case must be refused with a named field, finish, or be
//! stopped by the watchdog with a message naming a parameter: no panic, no hang (a wall-time bound
//! per case), no NaN or ∞ in any snapshot handed out. Each case is tiny (≤ 60 particles, a few
//! thousand DEM steps, a bounded number of gas steps). Shared by the example and its fast test.

use fluidbed_core::case::Case;
use fluidbed_core::sim::{SimError, Simulation, Snapshot};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::{Duration, Instant};

/// Parameters a stop message may name (one of them must appear: the user's next move).
const PARAMETERS: [&str; 5] = [
    "dem.time_step_s",
    "gas.time_step_s",
    "gas.superficial_velocity_m_s",
    "particles.youngs_modulus_pa",
    "gas.cfl_factor",
];

/// Most gas steps a generated case may need (its end time is cut to fit).
const MAX_GAS_STEPS: f64 = 3000.0;

/// Stop messages kept for the docs (every kind of stop seen, then others up to this many).
pub const STOP_EXAMPLES: usize = 5;

/// How one case ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Refused before the run: the first error's JSON pointer.
    Refused(String),
    /// The bed could not be built (the generator's own message).
    BuildFailed(String),
    Finished {
        warned: bool,
    },
    /// Stopped by the watchdog: its message.
    Stopped(String),
    Panicked(String),
    Hung,
}

impl Outcome {
    /// The row of the outcome table this case counts in.
    pub fn cause(&self) -> String {
        match self {
            Outcome::Refused(p) => {
                // one row for every particle of an explicit bed
                match p.rsplit_once('/') {
                    Some((head, last)) if !last.is_empty() && last.bytes().all(|b| b.is_ascii_digit()) => {
                        format!("refused {head}/<i>")
                    }
                    _ => format!("refused {p}"),
                }
            }
            Outcome::BuildFailed(m) => format!("bed not built: {m}"),
            Outcome::Finished { warned: false } => "finished".into(),
            Outcome::Finished { warned: true } => "finished (with warnings)".into(),
            Outcome::Stopped(m) => format!("stopped: {}", stop_kind(m)),
            Outcome::Panicked(_) => "PANIC".into(),
            Outcome::Hung => "HUNG".into(),
        }
    }
    /// Refusals name a field, stops a parameter; anything else is unexplained.
    pub fn explained(&self) -> bool {
        match self {
            Outcome::Refused(p) => p.starts_with('/'),
            Outcome::BuildFailed(m) => !m.is_empty(),
            Outcome::Finished { .. } => true,
            Outcome::Stopped(m) => PARAMETERS.iter().any(|p| m.contains(p)) && m.contains("DEM step"),
            Outcome::Panicked(_) | Outcome::Hung => false,
        }
    }
}

/// The kind of a watchdog stop, from its message.
fn stop_kind(m: &str) -> &'static str {
    const KINDS: [(&str, &str); 9] = [
        ("particle overlap", "overlap beyond 10% of d"),
        ("non-finite", "non-finite particle state"),
        ("left the column", "particle left through a wall"),
        ("moves at", "particle speed beyond the bound"),
        ("collapsed", "gas density collapsed"),
        ("acoustic/AB3", "gas step beyond the acoustic/AB3 limit"),
        ("would hold", "snapshot with NaN/Inf refused"),
        ("≤ 0", "gas density not positive"),
        ("gas ", "non-finite gas state"),
    ];
    KINDS.iter().find(|(k, _)| m.contains(k)).map_or("other", |(_, v)| v)
}

/// One case's result.
pub struct CaseResult {
    pub seed: u64,
    pub outcome: Outcome,
    /// Snapshots handed out that hold a NaN or ∞ (must be 0).
    pub nan_snapshots: usize,
    pub wall_s: f64,
}

/// All cases' results and the table.
#[derive(Default)]
pub struct Summary {
    pub cases: usize,
    pub panics: usize,
    pub hangs: usize,
    pub nan_snapshots: usize,
    pub unexplained: usize,
    pub by_cause: BTreeMap<String, usize>,
    /// The first stop message of each kind, then more up to `STOP_EXAMPLES` (for the docs).
    pub stop_examples: Vec<(u64, String)>,
}

impl Summary {
    pub fn add(&mut self, r: &CaseResult) {
        self.cases += 1;
        self.panics += matches!(r.outcome, Outcome::Panicked(_)) as usize;
        self.hangs += matches!(r.outcome, Outcome::Hung) as usize;
        self.nan_snapshots += r.nan_snapshots;
        self.unexplained += !r.outcome.explained() as usize;
        *self.by_cause.entry(r.outcome.cause()).or_default() += 1;
        if let Outcome::Stopped(m) = &r.outcome {
            let new_kind = !self.stop_examples.iter().any(|(_, e)| stop_kind(e) == stop_kind(m));
            if new_kind || self.stop_examples.len() < STOP_EXAMPLES {
                self.stop_examples.push((r.seed, m.clone()));
            }
        }
    }
    pub fn json(&self) -> Value {
        json!({ "stress": "extremes", "cases": self.cases, "panics": self.panics, "hangs": self.hangs,
                "nan_snapshots": self.nan_snapshots, "unexplained": self.unexplained })
    }
    /// The outcome table as Markdown.
    pub fn table(&self) -> String {
        let mut s = String::from("| outcome | cases |\n|---|---:|\n");
        for (k, n) in &self.by_cause {
            s += &format!("| {k} | {n} |\n");
        }
        s
    }
}

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    (rng.gen_range(lo.ln()..hi.ln())).exp()
}

/// A random case (as JSON, the way a user would submit it), from its seed.
pub fn random_case(seed: u64) -> Value {
    let rng = &mut ChaCha8Rng::seed_from_u64(seed);
    let beyond = rng.gen_bool(0.15); // draw some values beyond the schema's ranges
    let d = log_uniform(rng, 5e-5, 1e-2);
    let column_d = (d * log_uniform(rng, 3.0, 40.0)).min(0.2);
    let height = column_d * log_uniform(rng, 0.5, 6.0);
    let rho = if beyond && rng.gen_bool(0.3) { 2e5 } else { log_uniform(rng, 10.0, 20_000.0) };
    let e = if beyond && rng.gen_bool(0.3) { 1e2 } else { log_uniform(rng, 1e5, 1e11) };
    let nu = if beyond && rng.gen_bool(0.2) { 0.6 } else { rng.gen_range(0.0..0.49) };
    let mut case = json!({
        "name": format!("extremes {seed}"),
        "column": { "diameter_m": column_d, "height_m": height, "lid": rng.gen_bool(0.3) },
        "particles": {
            "diameter_m": d, "density_kg_m3": rho, "youngs_modulus_pa": e, "poisson_ratio": nu,
            "sliding_friction": if rng.gen_bool(0.3) { 0.0 } else { rng.gen_range(0.0..1.0) },
            "normal_damping": { "restitution": rng.gen_range(0.1..1.0) },
        },
    });
    // The DEM step as a multiple of the contact time at 1 m/s: 1e-4 (very short) to 0.1, and in
    // one case of six 0.1 to 3 (very long).
    let typed: Case = serde_json::from_value(json!({ "column": case["column"], "particles": case["particles"],
        "bed": { "generated": { "count": 1 } } }))
    .expect("a typed case");
    let tc = typed.hertz_contact_time_s(1.0);
    let mut dt = tc * if rng.gen_bool(1.0 / 6.0) { log_uniform(rng, 0.1, 3.0) } else { log_uniform(rng, 1e-4, 0.1) };
    if beyond && rng.gen_bool(0.2) {
        dt = [0.0, -1e-6, 0.05][rng.gen_range(0..3)];
    }
    let steps = rng.gen_range(100..3000) as f64;
    case["dem"] = json!({ "time_step_s": dt, "threads": 1 });
    case["end_time_s"] = json!(steps * dt.abs().max(1e-12));
    case["bed"] = random_bed(rng, d, column_d, height);
    if rng.gen_bool(0.7) {
        let u = if rng.gen_bool(0.3) { log_uniform(rng, 1.0, 50.0) } else { log_uniform(rng, 0.01, 1.0) };
        let radius = column_d / 2.0;
        // Cells barely larger than a particle, or a few annuli.
        let nr = if rng.gen_bool(0.4) { (radius / (1.05 * d)).floor().max(1.0) } else { rng.gen_range(1..6) as f64 };
        let nr = nr.min(8.0);
        let mut gas =
            json!({ "superficial_velocity_m_s": u, "ramp_time_s": rng.gen_range(0.0..2.0) * steps * dt.abs() });
        if rng.gen_bool(0.1) {
            gas["time_step_s"] = json!(dt.abs() * rng.gen_range(1..4) as f64);
        }
        case["gas"] = gas;
        let n0 = [3, 3, 4, 8][rng.gen_range(0..4)];
        case["grid"] = json!({ "dr_m": radius / nr, "n0": n0 });
        case["voidage"] =
            [json!({ "method": "direct" }), json!({ "method": "square_grid" }), json!({ "method": "grouping" })]
                [rng.gen_range(0..3)]
            .clone();
        case["coupling"] = json!({ "interval_steps": rng.gen_range(1..5) });
        cut_to_gas_budget(&mut case);
    }
    // One case in eight made soft (E of 1e5–1e6 Pa, a contact time ≥ 4× longer, so the step stays
    // valid): its thrown particles then collide beyond 10% overlap.
    if rng.gen_bool(0.125) {
        case["particles"]["youngs_modulus_pa"] = json!(log_uniform(rng, 1e5, 1e6));
    }
    let end = case["end_time_s"].as_f64().unwrap_or(0.0);
    case["outputs"] = json!({ "snapshot_interval_s": (end / 4.0).max(dt.abs()),
        "fields": ["voidage", "pressure", "gas_velocity", "particles"] });
    case
}

/// Explicit beds (some overlapping, some thrown fast, some over-full) or tiny generated ones.
fn random_bed(rng: &mut ChaCha8Rng, d: f64, column_d: f64, height: f64) -> Value {
    let radius = column_d / 2.0;
    if rng.gen_bool(0.25) {
        // Generated: a handful, or far more than fit (over-full: refused before the pour).
        let count = if rng.gen_bool(0.15) { 1_000_000_000 } else { rng.gen_range(1..40) };
        return json!({ "generated": { "count": count, "seed": rng.gen_range(0..1000) } });
    }
    let n = if rng.gen_bool(0.1) { rng.gen_range(100..300) } else { rng.gen_range(1..30) };
    let overlap = rng.gen_bool(0.2);
    let speed = if rng.gen_bool(0.4) { log_uniform(rng, 0.1, 50.0) } else { 0.0 };
    let mut pos: Vec<[f64; 3]> = Vec::new();
    for k in 0..n {
        let p = if overlap && k > 0 && rng.gen_bool(0.5) {
            let q: [f64; 3] = pos[rng.gen_range(0..pos.len())];
            let gap = d * rng.gen_range(0.3..1.0);
            [q[0] + gap, q[1], q[2]]
        } else {
            let r = (radius - d / 2.0).max(0.0) * rng.gen_range(0.0f64..1.0).sqrt();
            let th = rng.gen_range(0.0..std::f64::consts::TAU);
            [r * th.cos(), r * th.sin(), rng.gen_range(d / 2.0..(height.max(d)))]
        };
        pos.push(p);
    }
    let vel: Vec<[f64; 3]> =
        (0..n).map(|_| [0, 1, 2].map(|_| if speed > 0.0 { rng.gen_range(-speed..speed) } else { 0.0 })).collect();
    json!({ "explicit": { "positions_m": pos, "velocities_m_s": vel } })
}

/// Shorten the run so that the gas takes at most MAX_GAS_STEPS steps (and at least one DEM step).
fn cut_to_gas_budget(case: &mut Value) {
    let Ok(typed) = serde_json::from_value::<Case>(case.clone()) else { return };
    let Some(gas_dt) = fluidbed_core::cfd::case_stable_time_step(&typed) else { return };
    let dt = typed.dem.time_step_s.abs();
    if gas_dt > 0.0 && dt > 0.0 {
        let end = typed.end_time_s.min(MAX_GAS_STEPS * gas_dt);
        case["end_time_s"] = json!(((end / dt).floor().max(1.0)) * dt);
    }
}

/// Run one case as the server would: validate, build the bed (with a stop), step in chunks, and
/// check every snapshot handed out and checkpoint each one.
pub fn run_case(seed: u64, limit: Duration) -> CaseResult {
    let t0 = Instant::now();
    let case = random_case(seed);
    let mut nan = 0;
    let outcome = catch_unwind(AssertUnwindSafe(|| run(&case, t0, limit, &mut nan)))
        .unwrap_or_else(|p| Outcome::Panicked(panic_text(&*p)));
    CaseResult { seed, outcome, nan_snapshots: nan, wall_s: t0.elapsed().as_secs_f64() }
}

fn run(case: &Value, t0: Instant, limit: Duration, nan: &mut usize) -> Outcome {
    let (typed, report) = match Case::parse_value(case) {
        Ok(ok) => ok,
        Err(rep) => return Outcome::Refused(rep.errors.first().map_or(String::new(), |p| p.path.clone())),
    };
    let warned = !report.warnings.is_empty();
    let stop = || t0.elapsed() > limit;
    let cache = std::env::temp_dir().join(format!("fluidbed-extremes-{}", std::process::id()));
    if let Err(m) = fluidbed_core::dem::build_bed_until(&typed, Some(&cache), &stop) {
        return if stop() { Outcome::Hung } else { Outcome::BuildFailed(m) };
    }
    let mut sim = match Simulation::new(typed, Some(&cache)) {
        Ok(s) => s,
        Err(e) => return Outcome::BuildFailed(e.to_string()),
    };
    while !sim.is_finished() {
        if stop() {
            return Outcome::Hung;
        }
        match sim.advance(10) {
            Ok(Some(s)) => {
                *nan += holds_non_finite(&s) as usize;
                let _ = sim.checkpoint();
            }
            Ok(None) => {}
            Err(SimError::Unstable(m)) => return Outcome::Stopped(m),
            Err(e) => return Outcome::BuildFailed(e.to_string()),
        }
    }
    Outcome::Finished { warned }
}

/// An independent scan of every number a snapshot carries.
fn holds_non_finite(s: &Snapshot) -> bool {
    let bad = |x: &f64| !x.is_finite();
    let bad3 = |v: &[f64; 3]| v.iter().any(bad);
    s.voidage.iter().flatten().any(bad)
        || s.pressure_pa.iter().flatten().any(bad)
        || s.gas_velocity_m_s.iter().flatten().any(bad3)
        || s.pressure_drop_pa.iter().any(bad)
        || s.layer_pressure_drop_pa.iter().flatten().any(bad)
        || s.particles.iter().any(|p| p.positions_m.iter().any(bad3) || p.velocities_m_s.iter().any(bad3))
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_default()
}

/// Run `n` cases from `seed`, printing a line per case when `verbose`.
pub fn run_all(n: u64, seed: u64, limit: Duration, verbose: bool) -> Summary {
    let mut sum = Summary::default();
    for i in 0..n {
        let r = run_case(seed + i, limit);
        if verbose {
            println!("case {:4} ({:6.2} s): {}", r.seed, r.wall_s, r.outcome.cause());
        }
        if !r.outcome.explained() || r.nan_snapshots > 0 {
            eprintln!("case {}: {:?} (nan snapshots {})\n{}", r.seed, r.outcome, r.nan_snapshots, random_case(r.seed));
        }
        sum.add(&r);
    }
    sum
}
