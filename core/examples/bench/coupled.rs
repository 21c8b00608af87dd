//! Coupled-step benchmark: the 44-mm bubbling bed as shipped (cases/bubbling-44mm.json), from a
//! fluidized state (0.3 s simulated, made once and cached under target/), 2,000 DEM steps each
//! of: the case's default coupling, the paper's every-step coupling (interval 1, the gas at its
//! own stable step as in both), and the same particles stepped by the DEM alone (gas off). The
//! three run interleaved in one process (rounds of 250 steps), so their ratio is not at the mercy
//! of the VM's speed swings. gas_coupling_share = 1 − DEM-alone step / coupled step. Other
//! settings run interleaved beside them as extra modes (`coupled_mode` lines): from the same
//! state, except the gas at half the sound speed, which needs a fluidized state of its own.

use fluidbed_core::case::Case;
use fluidbed_core::sim::{Simulation, StageTimers};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

pub const FLUIDIZED_AT_S: f64 = 0.3;
const STEPS: u64 = 2000;
const ROUND: u64 = 250;

fn cache_dir() -> PathBuf {
    let d =
        PathBuf::from(std::env::var("FLUIDBED_BENCH_CACHE").unwrap_or_else(|_| "target/fluidbed-bench-cache".into()));
    std::fs::create_dir_all(&d).expect("bench cache dir");
    d
}

pub fn shipped_case(name: &str) -> Case {
    let path = format!("{}/../cases/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    Case::parse_str(&text).unwrap_or_else(|r| panic!("{path}: {:?}", r.errors)).0
}

/// The checkpoint of `case` run to `t_end` from its poured bed, cached by the case's text and the
/// gas step the build plans for it; a cache the current build cannot read is made again.
pub fn state_at(case: &Case, t_end: f64, label: &str) -> Vec<u8> {
    let key = {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        serde_json::to_string(case).expect("case").hash(&mut h);
        t_end.to_bits().hash(&mut h);
        // the gas step this build plans (stored in the state, so a new estimate needs a new state)
        fluidbed_core::cfd::case_stable_time_step(case).map(f64::to_bits).hash(&mut h);
        h.finish()
    };
    let file = cache_dir().join(format!("{label}-{key:016x}.ckpt"));
    if let Ok(bytes) = std::fs::read(&file) {
        if Simulation::restore(&bytes).is_ok() {
            return bytes;
        }
        eprintln!("[{label}] cached state unreadable by this build; making it again");
    }
    let bed = PathBuf::from(std::env::var("FLUIDBED_BED_CACHE").unwrap_or_else(|_| "target/fluidbed-bed-cache".into()));
    let mut sim = Simulation::new(case.clone(), Some(&bed)).expect("case builds");
    let t0 = Instant::now();
    eprintln!("[{label}] running {} particles to t = {t_end} s (cached for later runs)", sim.dem().len());
    while sim.time() < t_end - 1e-12 {
        let left = ((t_end - sim.time()) / case.dem.time_step_s).round() as u64;
        if let Some(s) = sim.advance(left.max(1)).expect("run stays stable") {
            if s.index % 10 == 0 {
                eprintln!(
                    "[{label}] t = {:.3} s, ΔP = {:?} Pa, wall {:.0} s",
                    s.time_s,
                    s.pressure_drop_pa.map(|x| x.round()),
                    t0.elapsed().as_secs_f64()
                );
            }
        }
    }
    let bytes = sim.checkpoint();
    let tmp = file.with_extension("tmp");
    std::fs::write(&tmp, &bytes).expect("write cache");
    std::fs::rename(&tmp, &file).expect("cache in place");
    bytes
}

/// One mode's accumulated wall time and stage timers.
#[derive(Default)]
pub struct Tally {
    pub wall: f64,
    pub steps: u64,
    pub stages: StageTimers,
}

impl Tally {
    pub fn per_step(&self) -> f64 {
        self.wall / self.steps as f64
    }
    pub fn stages_json(&self) -> serde_json::Value {
        let n = self.steps as f64;
        let s = &self.stages;
        json!({"neighbours": s.neighbours / n, "contacts_integration": s.contacts_integration / n,
               "voidage": s.voidage / n, "exchange": s.exchange / n, "gas": s.gas / n, "output": s.output / n})
    }
}

/// `steps` coupled steps of `sim` (snapshots as they fall), added to `t`.
pub fn coupled_round(sim: &mut Simulation, steps: u64, t: &mut Tally) {
    if let Err(e) = try_coupled_round(sim, steps, t) {
        panic!("coupled run unstable (coupling {:?}, gas step {:?} s): {e}", sim.case().coupling, sim.plan().gas_dt_s);
    }
}

/// As `coupled_round`, the watchdog's stop returned instead of a panic.
pub fn try_coupled_round(sim: &mut Simulation, steps: u64, t: &mut Tally) -> Result<(), String> {
    sim.reset_timers();
    let t0 = Instant::now();
    let mut left = steps;
    while left > 0 {
        if sim.is_finished() {
            return Err(format!("the run is at its end time ({} s)", sim.end_time()));
        }
        let before = sim.steps();
        sim.advance(left).map_err(|e| e.to_string())?;
        left -= sim.steps() - before;
    }
    t.wall += t0.elapsed().as_secs_f64();
    t.steps += steps;
    add(&mut t.stages, sim.timers());
    Ok(())
}

/// `steps` steps of the particles alone (no drag, no gas), added to `t`.
pub fn dem_round(sim: &mut Simulation, steps: u64, t: &mut Tally) {
    let dem = sim.dem_mut();
    dem.external_forces_mut().fill([0.0; 3]);
    let n0 = dem.neighbour_seconds();
    let t0 = Instant::now();
    for _ in 0..steps {
        dem.step();
    }
    let wall = t0.elapsed().as_secs_f64();
    let nb = dem.neighbour_seconds() - n0;
    t.wall += wall;
    t.steps += steps;
    t.stages.neighbours += nb;
    t.stages.contacts_integration += wall - nb;
}

fn add(a: &mut StageTimers, b: &StageTimers) {
    a.neighbours += b.neighbours;
    a.contacts_integration += b.contacts_integration;
    a.voidage += b.voidage;
    a.exchange += b.exchange;
    a.gas += b.gas;
    a.output += b.output;
}

/// A mode of `run` beside the defaults: its name and what it changes on the restored state.
type Setting = (&'static str, fn(&mut Simulation));

pub fn run() {
    use fluidbed_core::case::{GasVoidage, PressureForce};
    // FLUIDBED_BENCH_CASE names another file of cases/ to time the same way.
    let name = std::env::var("FLUIDBED_BENCH_CASE").unwrap_or_else(|_| "bubbling-44mm.json".into());
    let case = shipped_case(&name);
    let state = state_at(&case, FLUIDIZED_AT_S, name.trim_end_matches(".json"));
    let restore = || Simulation::restore(&state).expect("cached state");
    let (mut alone, mut default, mut paper) = (restore(), restore(), restore());
    // The paper's coupling: every step, the pressure force of the moment.
    paper.set_coupling_interval(1);
    paper.set_pressure_force(PressureForce::Held);
    // Other settings, reported beside the defaults (not defaults; docs/BENCHMARKS.md and
    // docs/VALIDATION.md "The pressure force between couplings"); one the watchdog stops is named
    // with why.
    let settings: [Setting; 5] = [
        // The gas's voidage interpolated between couplings, at longer intervals.
        ("interpolated_interval_40", |s| {
            s.set_coupling_interval(40);
            s.set_gas_voidage(GasVoidage::Interpolated);
        }),
        ("interpolated_interval_80", |s| {
            s.set_coupling_interval(80);
            s.set_gas_voidage(GasVoidage::Interpolated);
        }),
        ("pressure_force_interval_mean_interval_10", |s| {
            s.set_coupling_interval(10);
            s.set_pressure_force(PressureForce::IntervalMean);
        }),
        // The gas stepped by the paper's AB3 (the default is forward–backward).
        ("gas_ab3", |s| s.set_gas_time_scheme(fluidbed_core::cfd::TimeScheme::Ab3)),
        // The defaults before 2026-12-06.
        ("held_interval_10", |s| {
            s.set_coupling_interval(10);
            s.set_pressure_force(PressureForce::Held);
        }),
    ];
    let mut extra: Vec<(&str, Simulation, Tally, Option<String>)> = settings
        .into_iter()
        .map(|(name, set)| {
            let mut sim = restore();
            set(&mut sim);
            (name, sim, Tally::default(), None)
        })
        .collect();
    // The gas's pressure waves at half the sound speed (`gas.acoustic_speed_factor`), the defaults
    // otherwise: its own fluidized state, since the equation of state differs.
    let mut half = case.clone();
    half.gas.as_mut().expect("gas").acoustic_speed_factor = 0.5;
    let half_state = state_at(&half, FLUIDIZED_AT_S, &format!("{}-acoustic-0.5", name.trim_end_matches(".json")));
    extra.push((
        "acoustic_speed_half",
        Simulation::restore(&half_state).expect("cached state"),
        Tally::default(),
        None,
    ));
    let (mut ta, mut td, mut tp) = (Tally::default(), Tally::default(), Tally::default());
    for _ in 0..STEPS / ROUND {
        dem_round(&mut alone, ROUND, &mut ta);
        coupled_round(&mut default, ROUND, &mut td);
        coupled_round(&mut paper, ROUND, &mut tp);
        for (_, sim, t, stop) in extra.iter_mut().filter(|e| e.3.is_none()) {
            *stop = try_coupled_round(sim, ROUND, t).err();
        }
    }
    let dt = case.dem.time_step_s;
    let plan = default.plan();
    let share = |t: &Tally| 1.0 - ta.per_step() / t.per_step();
    let main = [("dem_alone", &ta), ("default", &td), ("paper", &tp)].map(|(n, t)| (n, t, None));
    let modes = main.iter().map(|(n, t, s)| (*n, *t, s)).chain(extra.iter().map(|(n, _, t, s)| (*n, t, s)));
    for (name, t, stop) in modes {
        println!(
            "{}",
            json!({"bench": "coupled_mode", "mode": name, "s_per_step": t.per_step(), "share": share(t),
                "stages_s_per_step": t.stages_json(), "stopped": stop})
        );
    }
    println!(
        "{}",
        json!({"bench": "coupled", "particles": default.dem().len(), "cells": default.grid().num_cells(), "steps": STEPS,
            "threads": rayon::current_num_threads(), "coupling_interval": plan.coupling_interval, "gas_dt_s": plan.gas_dt_s,
            "dem_dt_s": dt, "dem_alone_s_per_step": ta.per_step(), "coupled_s_per_step": td.per_step(),
            "gas_coupling_share": share(&td), "wall_s_per_sim_s": td.per_step() / dt, "stages": td.stages_json(),
            "paper_coupling_interval": 1, "paper_dem_alone_s_per_step": ta.per_step(), "paper_coupled_s_per_step": tp.per_step(),
            "paper_gas_coupling_share": share(&tp), "paper_wall_s_per_sim_s": tp.per_step() / dt, "paper_stages": tp.stages_json()})
    );
}

/// The coupling's parts one by one on the fluidized state (`bench -- coupled-parts`): ms per call.
pub fn parts() {
    use fluidbed_core::coupling::{build_voidage, voidage_from_solid, DragCells, Exchange, ExchangeParams, GasAtCells};
    let case = shipped_case("bubbling-44mm.json");
    let sim = Simulation::restore(&state_at(&case, FLUIDIZED_AT_S, "bubbling-44mm")).expect("state");
    let (grid, dem, gas) = (sim.grid(), sim.dem(), sim.gas().expect("gas"));
    let n = grid.num_cells();
    let reps = 200;
    // Mean and median per call: on a shared machine the median is the steadier figure.
    let time = |label: &str, f: &mut dyn FnMut()| {
        f();
        let mut calls: Vec<f64> = (0..reps)
            .map(|_| {
                let t0 = Instant::now();
                f();
                t0.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        let ms = calls.iter().sum::<f64>() / reps as f64;
        calls.sort_by(f64::total_cmp);
        let median = calls[reps / 2];
        println!(
            "{}",
            json!({"bench": "coupled_part", "part": label, "ms_per_call": ms, "median_ms_per_call": median,
                   "ns_per_particle": ms * 1e6 / dem.len() as f64, "median_ns_per_particle": median * 1e6 / dem.len() as f64})
        );
    };
    let mut method = build_voidage(&case, grid);
    let (mut solid, mut eps) = (vec![0.0; n], vec![0.0; n]);
    time("voidage_solid_volume", &mut || method.solid_volume(dem.positions(), dem.radius(), &mut solid));
    time("voidage_from_solid", &mut || voidage_from_solid(grid, &solid, &mut eps));
    let (mut vel, mut rho, mut grad) = (vec![[0.0; 3]; n], vec![0.0; n], vec![[0.0; 3]; n]);
    let layers = fluidbed_core::coupling::layers_with_particles(grid, dem.positions());
    let mut gas_fields = gas.clone();
    time("gas_exchange_fields", &mut || gas_fields.exchange_fields(layers, &mut vel, &mut rho, &mut grad));
    let g = case.gas.as_ref().expect("gas");
    let par = ExchangeParams {
        law: case.coupling.drag_law,
        mu: g.viscosity_pa_s,
        eps_min: g.drag_voidage_min,
        d: 2.0 * dem.radius(),
    };
    let at = GasAtCells { velocity_cyl: &vel, density: &rho, grad_p_cyl: &grad, voidage: &eps, layers };
    let mut ex = Exchange::new(grid, dem.len());
    let (mut f, mut cf) = (vec![[0.0; 3]; dem.len()], vec![[0.0; 3]; n]);
    time("particle_gas_forces", &mut || {
        ex.particle_gas_forces(
            grid,
            DragCells::cells(grid, at.voidage),
            &at,
            par,
            (dem.positions(), dem.velocities()),
            &mut f,
            &mut cf,
        )
    });
    let mut gas2 = gas.clone();
    let dt = sim.plan().gas_dt_s.expect("gas dt");
    time("gas_step", &mut || gas2.step(dt));
    gas2.set_parallel(false);
    time("gas_step_one_thread", &mut || gas2.step(dt));
}

/// One gas step on the fluidized state three ways, interleaved in rounds of 20 steps (`bench --
/// gas-team`): as one team of threads, as four parallel loops, on one thread. Median ms per step.
pub fn gas_team() {
    let case = shipped_case("bubbling-44mm.json");
    let sim = Simulation::restore(&state_at(&case, FLUIDIZED_AT_S, "bubbling-44mm")).expect("state");
    let dt = sim.plan().gas_dt_s.expect("gas dt");
    let base = sim.gas().expect("gas").clone();
    let (mut team, mut loops, mut one) = (base.clone(), base.clone(), base);
    loops.set_team(false);
    one.set_parallel(false);
    let mut times: [Vec<f64>; 3] = Default::default();
    for _ in 0..60 {
        for (m, gas) in [&mut team, &mut loops, &mut one].into_iter().enumerate() {
            let t0 = Instant::now();
            for _ in 0..20 {
                gas.step(dt);
            }
            times[m].push(t0.elapsed().as_secs_f64() * 1e3 / 20.0);
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let [a, b, c] = times.each_mut().map(median);
    // The three were stepped alike: equal digests mean the same bits on every path.
    let digest = |g: &fluidbed_core::cfd::GasSolver| {
        let n = g.grid().num_cells();
        let bits: String =
            (0..n).map(|c| format!("{:x}{:x}", g.density(c).to_bits(), g.velocity_xyz(c)[2].to_bits())).collect();
        format!("{:016x}", fluidbed_core::dem::fnv1a(&bits))
    };
    eprintln!("gas_team state digests: team {}, loops {}, one thread {}", digest(&team), digest(&loops), digest(&one));
    println!(
        "{}",
        json!({"bench": "gas_team", "cells": sim.grid().num_cells(), "team_ms": a, "loops_ms": b, "one_thread_ms": c})
    );
}

/// Micro-timings of the particle pass's pieces (diagnostic).
pub fn micro() {
    use fluidbed_core::coupling::drag::{Beetstra, DragLaw};
    use fluidbed_core::coupling::fast_math::{fast_exp, fast_ln};
    let case = shipped_case("bubbling-44mm.json");
    let sim = Simulation::restore(&state_at(&case, FLUIDIZED_AT_S, "bubbling-44mm")).expect("state");
    let (grid, dem) = (sim.grid(), sim.dem());
    let pos = dem.positions();
    let n = pos.len();
    let hints: Vec<usize> = pos.iter().map(|p| grid.locate(p[0], p[1], p[2])).collect();
    let reps = 50;
    let mut acc = 0usize;
    let t0 = Instant::now();
    for _ in 0..reps {
        for (p, &h) in pos.iter().zip(&hints) {
            acc += grid.locate_near(p[0], p[1], p[2], h);
        }
    }
    println!("locate_near with hint: {:.1} ns ({acc})", t0.elapsed().as_secs_f64() * 1e9 / (reps * n) as f64);
    let t0 = Instant::now();
    for _ in 0..reps {
        for p in pos {
            acc += grid.locate(p[0], p[1], p[2]);
        }
    }
    println!("locate: {:.1} ns ({acc})", t0.elapsed().as_secs_f64() * 1e9 / (reps * n) as f64);
    let held = hints.iter().zip(pos).filter(|(&h, p)| grid.locate_near(p[0], p[1], p[2], h) == h).count();
    println!("hints that hold: {held} of {n}");
    let c = Beetstra.cell(0.55);
    let mut s = 0.0;
    let t0 = Instant::now();
    for k in 0..reps * n {
        s += Beetstra::f_cell(&c, 1.0 + (k % 1000) as f64 * 0.07);
    }
    println!("f_cell: {:.1} ns ({s})", t0.elapsed().as_secs_f64() * 1e9 / (reps * n) as f64);
    let t0 = Instant::now();
    for k in 0..reps * n {
        s += fast_exp(fast_ln(1.0 + (k % 1000) as f64 * 0.07));
    }
    println!("fast exp(ln): {:.1} ns ({s})", t0.elapsed().as_secs_f64() * 1e9 / (reps * n) as f64);
}

/// The gas alone from the fluidized state (force and voidage held), 80 ms at multiples of its
/// estimated stable step (stability.rs, cfl_factor 1): the step where it stops staying bounded.
pub fn gas_dt(scheme: fluidbed_core::cfd::TimeScheme) {
    let case = shipped_case("bubbling-44mm.json");
    let sim = Simulation::restore(&state_at(&case, FLUIDIZED_AT_S, "bubbling-44mm")).expect("state");
    let mut base = sim.gas().expect("gas").clone();
    base.set_time_scheme(scheme);
    let base = &base;
    let limit = base.stable_dt() / base.params().cfl_factor;
    let span = 0.08;
    for k in [0.9, 1.0, 1.03, 1.06, 1.1, 1.2] {
        let mut gas = base.clone();
        let dt = k * limit;
        let steps = (span / dt) as usize;
        let blew_up_at = (0..steps).find(|&s| {
            gas.step(dt);
            s % 100 == 0 && gas.check_finite().is_err()
        });
        let bounded = blew_up_at.is_none() && gas.check_finite().is_ok();
        println!(
            "{}",
            json!({"bench": "gas_dt", "step_over_limit": k, "dt_s": dt, "steps": steps, "bounded": bounded,
                   "blew_up_at_step": blew_up_at, "mass_ratio": if bounded { gas.total_mass() / base.total_mass() } else { f64::NAN }})
        );
    }
}

/// One gas step taken between DEM steps (the DEM evicts the gas's state from the caches) against
/// gas steps back to back, one thread and a team (`bench -- gas-context`, a diagnostic).
pub fn gas_context() {
    let case = shipped_case("bubbling-44mm.json");
    let state = state_at(&case, FLUIDIZED_AT_S, "bubbling-44mm");
    let mut sim = Simulation::restore(&state).expect("state");
    let dt = sim.plan().gas_dt_s.expect("gas dt");
    let base = sim.gas().expect("gas").clone();
    let (mut team, mut one) = (base.clone(), base);
    one.set_parallel(false);
    let mut t = [[0.0f64; 2]; 2];
    for _ in 0..10 {
        for (m, gas) in [&mut team, &mut one].into_iter().enumerate() {
            for _ in 0..20 {
                for _ in 0..3 {
                    sim.dem_mut().step();
                }
                let t0 = Instant::now();
                gas.step(dt);
                t[m][0] += t0.elapsed().as_secs_f64();
            }
            let t0 = Instant::now();
            for _ in 0..20 {
                gas.step(dt);
            }
            t[m][1] += t0.elapsed().as_secs_f64();
        }
    }
    println!("team: between DEM steps {:.3} ms, back to back {:.3} ms", t[0][0] / 200.0 * 1e3, t[0][1] / 200.0 * 1e3);
    println!(
        "one thread: between DEM steps {:.3} ms, back to back {:.3} ms",
        t[1][0] / 200.0 * 1e3,
        t[1][1] / 200.0 * 1e3
    );
}
