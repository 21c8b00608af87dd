//! `stress -- bubbling-1m`: cases/bubbling-44mm.json (30k particles, U = 0.6 m/s) for 1,000,000
//! DEM steps (1.25 s) at its defaults, with no watchdog stop allowed:
//! - the gas mass budget of the flux-updated cells (cfd/mass_budget.rs), in − out − change over
//!   the mass held, at every snapshot (5 ms) and its largest magnitude;
//! - the particles' vertical momentum budget: P(t) − P(0) against ∫ (gas + plate + tube − weight) dt,
//!   the forces summed every `FORCE_EVERY` steps (the gas force is held over a coupling interval of
//!   the same length), relative to the weight's impulse over the run;
//! - a drift figure: docs/img/bubbling_1m_mass_budget.png.
//!
//! Progress (checkpoint and what was gathered) is kept in target/validate-cache every 0.05 s, so a
//! stopped run resumes there. Last line `{"stress":"bubbling-1m",…}`.

use fluidbed_core::case::Case;
use fluidbed_core::output::plot::{trace, TraceLabels};
use fluidbed_core::sim::Simulation;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::f64::consts::PI;
use std::time::Instant;

const DEM_STEPS: u64 = 1_000_000;
/// DEM steps between the force samples of the momentum budget (the default coupling interval).
const FORCE_EVERY: u64 = 10;

/// What the run has gathered (kept beside its checkpoint).
#[derive(Default, Serialize, Deserialize)]
struct Progress {
    /// (time, (in − out − change)/held) per snapshot.
    mass: Vec<(f64, f64)>,
    /// ∫ (gas + plate + tube − weight) dt so far (N s) and the momentum at the start (kg m/s).
    impulse: f64,
    p0: Option<f64>,
    wall_s: f64,
}

fn case() -> Case {
    let path = format!("{}/../cases/bubbling-44mm.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut c = Case::parse_str(&text).unwrap_or_else(|r| panic!("{path}: {:?}", r.errors)).0;
    c.end_time_s = DEM_STEPS as f64 * c.dem.time_step_s;
    c.outputs.snapshot_interval_s = 0.005;
    c.outputs.fields = vec![];
    c
}

fn write_atomically(path: &str, bytes: &[u8]) {
    let tmp = format!("{path}.tmp");
    std::fs::write(&tmp, bytes).unwrap_or_else(|e| panic!("{tmp}: {e}"));
    std::fs::rename(&tmp, path).unwrap_or_else(|e| panic!("{path}: {e}"));
}

pub fn run() {
    let case = case();
    let key = fluidbed_core::dem::fnv1a(&serde_json::to_string(&case).expect("case to JSON"));
    std::fs::create_dir_all("target/validate-cache").expect("cache dir");
    let (ckpt, partial) = (
        format!("target/validate-cache/stress-bubbling-1m-{key:016x}.ckpt"),
        format!("target/validate-cache/stress-bubbling-1m-{key:016x}.partial"),
    );
    let resumed = std::fs::read(&ckpt).ok().and_then(|b| Simulation::restore(&b).ok()).and_then(|sim| {
        let p: Progress = bincode::deserialize(&std::fs::read(&partial).ok()?).ok()?;
        Some((sim, p))
    });
    let (mut sim, mut p) = match resumed {
        Some((sim, p)) => {
            eprintln!("[bubbling-1m] resuming at DEM step {} from {ckpt}", sim.steps());
            (sim, p)
        }
        None => {
            let bed = std::path::PathBuf::from(
                std::env::var("FLUIDBED_BED_CACHE").unwrap_or_else(|_| "target/fluidbed-bed-cache".into()),
            );
            (Simulation::new(case.clone(), Some(&bed)).expect("the bubbling case builds"), Progress::default())
        }
    };
    let (dt, n) = (case.dem.time_step_s, sim.dem().len());
    let d = case.particles.diameter_m;
    let weight = n as f64 * case.particles.density_kg_m3 * PI * d * d * d / 6.0 * case.gravity_m_s2;
    p.p0.get_or_insert(sim.dem().momentum()[2]);
    let (t0, wall_before) = (Instant::now(), p.wall_s);
    while !sim.is_finished() {
        let left = FORCE_EVERY - sim.steps() % FORCE_EVERY;
        let before = sim.steps();
        // A watchdog stop ends the stress run as a failure, with its message.
        let snap = sim.advance(left).unwrap_or_else(|e| panic!("bubbling-1m: {e}"));
        if sim.steps() > before && sim.steps().is_multiple_of(FORCE_EVERY) {
            let dem = sim.dem();
            let [plate, tube, _] = dem.wall_loads();
            p.impulse += (dem.external_force_total()[2] + plate + tube - weight) * FORCE_EVERY as f64 * dt;
        }
        if let Some(s) = snap {
            let b = sim.gas().expect("gas").mass_balance();
            p.mass.push((s.time_s, b.relative_error()));
            if s.index % 10 == 0 {
                p.wall_s = wall_before + t0.elapsed().as_secs_f64();
                eprintln!(
                    "[bubbling-1m] t = {:.3} s, ΔP = {:.0} Pa, mass budget {:+.2e}, wall {:.0} s",
                    s.time_s,
                    s.pressure_drop_pa.unwrap_or(0.0),
                    b.relative_error(),
                    p.wall_s
                );
                write_atomically(&ckpt, &sim.checkpoint());
                write_atomically(&partial, &bincode::serialize(&p).expect("progress"));
            }
        }
    }
    let wall = wall_before + t0.elapsed().as_secs_f64();
    let b = sim.gas().expect("gas").mass_balance();
    let worst = p.mass.iter().map(|m| m.1.abs()).fold(0.0, f64::max);
    let momentum_change = sim.dem().momentum()[2] - p.p0.expect("start momentum");
    let momentum_rel = (momentum_change - p.impulse) / (weight * sim.time());
    let (t, e): (Vec<f64>, Vec<f64>) = p.mass.iter().copied().unzip();
    let labels = TraceLabels {
        title: "44-mm bubbling bed, 1,000,000 DEM steps: gas mass budget",
        x: "time t [s]",
        y: "(in − out − change) / mass held [-]",
    };
    let img = trace(&t, &e, &labels).expect("figure");
    std::fs::create_dir_all("docs/img").expect("docs/img");
    std::fs::write("docs/img/bubbling_1m_mass_budget.png", img.encode()).expect("write png");
    println!(
        "{}",
        json!({"stress": "bubbling-1m", "particles": n, "dem_steps": sim.steps(), "simulated_s": sim.time(),
            "gas_steps": sim.gas().expect("gas").steps(), "mass_held_kg": b.held, "net_inflow_kg": b.net_inflow,
            "mass_change_kg": b.change, "mass_budget_rel_final": b.relative_error(), "mass_budget_rel_max": worst,
            "momentum_change_n_s": momentum_change, "force_impulse_n_s": p.impulse,
            "momentum_budget_rel": momentum_rel, "watchdog_stops": 0, "wall_s": wall,
            "png": "docs/img/bubbling_1m_mass_budget.png"})
    );
    let _ = (std::fs::remove_file(&ckpt), std::fs::remove_file(&partial));
}
