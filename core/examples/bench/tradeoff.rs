//! Run time against error (`bench -- tradeoff`). Two parts:
//! 1. Coupled runs on a 22-mm bed of the paper's particles (4.9k, E = 120 MPa, DEM step 1.25 µs,
//!    dz = dr/2), fluidized at 0.6 m/s: from a state at 0.2 s (made once and cached) each knob's
//!    setting runs 0.3 s with snapshots every 2 ms. Cost = wall seconds per simulated second; the
//!    errors, against the paper's every-step coupling, in the ΔP mean, standard deviation and
//!    dominant frequency and the time-averaged voidage (layer means; annulus means over the bed),
//!    beside the noise floor: the same reference from a second poured bed (seed 2). An error below
//!    the floor is inside the noise.
//!    The costs are measured again interleaved in one process (`tradeoff_cost` lines), the figures
//!    to compare. `-- tradeoff errors|cost|voidage` runs one part (the voidage part always runs); `layer`
//!    the reference and the fluid layer height point alone, `sound` the reference and the acoustic
//!    speed points (the gas's pressure waves at f = ½ and ¼ of the sound speed, each from its own
//!    spin-up) alone, `gas-voidage` the reference and the gas's voidage extrapolated,
//!    interpolated and held between couplings at intervals 10, 20, 50 alone, `scheme` the gas's
//!    time schemes, `pressure` the particles' pressure force held or at the interval's mean at
//!    intervals 10 and 20, `interval` the interval's mean at intervals 20, 30, 40 and 50, `long` intervals of 40 to
//!    160 with the gas's voidage and the drag on the gas held or not, `probe` the settings of
//!    `FLUIDBED_PROBE` without a reference. The bed spins up at the coupling of the fronts in
//!    docs/BENCHMARKS.md (interval 20, the gas's voidage and drag held); each point sets its own.
//! 2. Voidage methods on random packings in that grid (L1 against the converged exact split),
//!    cost per particle per call and per DEM step at the case's coupling interval.
//!
//! Last line: {"bench":"tradeoff","default_voidage","default_l1","default_ns_per_particle",
//! "paper_sg3_l1","paper_sg3_ns_per_particle"} (per DEM step: the default at its interval, the
//! paper's square grid configuration 3 at every step).

use crate::coupled::{coupled_round, shipped_case, state_at, Tally};
use crate::voidage::packing;
use fluidbed_core::case::{BoxSplit, Case, GasDrag, GasVoidage, PressureForce, Voidage};
use fluidbed_core::cfd::TimeScheme;
use fluidbed_core::coupling::build_voidage;
use fluidbed_core::coupling::voidage::{voidage_from_solid, ExactCylindrical, SquareGrid, VoidageMethod};
use fluidbed_core::grid::CylGrid;
use fluidbed_core::sim::{fluid_grid, Simulation, Snapshot};
use serde_json::json;
use std::f64::consts::PI;
use std::time::Instant;

pub(crate) const SPIN_UP_S: f64 = 0.2;
const WINDOW_S: f64 = 0.3;

/// The window of each point: `WINDOW_S`, or `FLUIDBED_TRADEOFF_WINDOW_S` seconds.
fn window_s() -> f64 {
    std::env::var("FLUIDBED_TRADEOFF_WINDOW_S").ok().and_then(|s| s.parse().ok()).unwrap_or(WINDOW_S)
}

/// The trade-off bed: the quickstart's 22-mm column with the paper's particles and DEM step.
pub(crate) fn bed(seed: u64) -> Case {
    let mut c = shipped_case("quickstart.json");
    c.particles.youngs_modulus_pa = 1.2e8;
    c.dem.time_step_s = 1.25e-6;
    c.grid.dz_m = Some(c.grid.dr_m / 2.0);
    c.column.height_m = (c.column.height_m / (c.grid.dr_m / 2.0)).round() * c.grid.dr_m / 2.0;
    c.outputs.snapshot_interval_s = 0.002;
    c.outputs.fields = vec![fluidbed_core::case::Field::Voidage, fluidbed_core::case::Field::Pressure];
    c.end_time_s = SPIN_UP_S + WINDOW_S;
    // The coupling the fronts spin up with and their points change (the defaults until 2026-12-06).
    c.coupling.interval_steps = 20;
    c.coupling.gas_voidage = GasVoidage::Held;
    c.coupling.gas_drag = GasDrag::Held;
    c.coupling.pressure_force = PressureForce::IntervalMean;
    if let fluidbed_core::case::Bed::Generated(g) = &mut c.bed {
        g.seed = seed;
    }
    c
}

/// The trade-off bed with fluid layers as high as the cells are wide (dz = dr; the column height
/// is a whole number of dr, so each layer is two of the reference's).
fn layers_of_dr(c: &Case) -> Case {
    let mut c = c.clone();
    c.grid.dz_m = Some(c.grid.dr_m);
    assert!(((c.column.height_m / c.grid.dr_m).round() * c.grid.dr_m - c.column.height_m).abs() < 1e-12);
    c
}

/// Acoustic speed factors of the trade-off (`gas.acoustic_speed_factor`).
const ACOUSTIC_FACTORS: [f64; 2] = [0.5, 0.25];

/// The trade-off bed with the gas's pressure waves at `f` times the sound speed.
fn with_acoustic_factor(c: &Case, f: f64) -> Case {
    let mut c = c.clone();
    c.gas.as_mut().expect("the bed has gas").acoustic_speed_factor = f;
    c
}

/// What a window of snapshots says about the bed.
struct Stats {
    dp_mean: f64,
    dp_std: f64,
    dp_freq: f64,
    axial: Vec<f64>,
    radial: Vec<f64>,
}

fn stats(snaps: &[Snapshot], grid: &CylGrid) -> Stats {
    let dp: Vec<f64> = snaps.iter().filter_map(|s| s.pressure_drop_pa).collect();
    let n = dp.len() as f64;
    let mean = dp.iter().sum::<f64>() / n;
    let std = (dp.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n).sqrt();
    // Dominant frequency: the largest periodogram bin above zero (resolution 1/window).
    let dt = snaps[1].time_s - snaps[0].time_s;
    let (mut best, mut freq) = (0.0, 0.0);
    for k in 1..dp.len() / 2 {
        let (mut re, mut im) = (0.0, 0.0);
        for (m, x) in dp.iter().enumerate() {
            let a = 2.0 * PI * (k * m) as f64 / n;
            re += (x - mean) * a.cos();
            im += (x - mean) * a.sin();
        }
        if re * re + im * im > best {
            best = re * re + im * im;
            freq = k as f64 / (n * dt);
        }
    }
    let per = grid.cells_per_layer();
    let mut axial = vec![0.0; grid.nz];
    let mut radial = vec![0.0; grid.nr];
    let bed_layers = (0.04 / grid.dz) as usize;
    for s in snaps {
        let e = s.voidage.as_ref().expect("voidage field");
        for k in 0..grid.nz {
            axial[k] += e[k * per..(k + 1) * per].iter().sum::<f64>() / per as f64 / snaps.len() as f64;
        }
        for k in 0..bed_layers.min(grid.nz) {
            let mut c = k * per;
            for (i, r) in radial.iter_mut().enumerate() {
                let m = grid.cells_in_annulus(i);
                *r += e[c..c + m].iter().sum::<f64>() / (m * bed_layers * snaps.len()) as f64;
                c += m;
            }
        }
    }
    Stats { dp_mean: mean, dp_std: std, dp_freq: freq, axial, radial }
}

fn l1(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() / a.len() as f64
}

/// The errors of `s` against `r`, relative for the ΔP figures.
fn errors(s: &Stats, r: &Stats) -> serde_json::Value {
    json!({"dp_mean": (s.dp_mean / r.dp_mean - 1.0).abs(), "dp_std": (s.dp_std / r.dp_std - 1.0).abs(),
           "dp_freq_hz": (s.dp_freq - r.dp_freq).abs(), "voidage_axial_l1": l1(&s.axial, &r.axial),
           "voidage_radial_l1": l1(&s.radial, &r.radial)})
}

/// Run `case` over the window from its cached spin-up state with `interval`: snapshots, cost.
fn window(case: &Case, label: &str, interval: u32) -> (Vec<Snapshot>, f64) {
    window_as(case, label, interval, GasVoidage::Held)
}

/// `window` with the gas's voidage moved as `how` from the spin-up state on.
fn window_as(case: &Case, label: &str, interval: u32, how: GasVoidage) -> (Vec<Snapshot>, f64) {
    let state = state_at(case, SPIN_UP_S, label);
    let mut sim = Simulation::restore(&state).expect("state");
    sim.set_coupling_interval(interval);
    sim.set_gas_voidage(how);
    if interval == 1 {
        // The reference is the paper's coupling: every step, the pressure force of the moment.
        sim.set_pressure_force(PressureForce::Held);
    }
    let (snaps, cost, stopped) = run_window(&mut sim);
    assert!(stopped.is_none(), "stable run: {stopped:?}");
    (snaps, cost)
}

/// Run `sim` from its spin-up state over the window: its snapshots, the wall seconds per
/// simulated second, and why the watchdog stopped it, if it did.
fn run_window(sim: &mut Simulation) -> (Vec<Snapshot>, f64, Option<String>) {
    let window = window_s();
    sim.set_end_time(SPIN_UP_S + window);
    let (mut snaps, t0) = (Vec::new(), Instant::now());
    while !sim.is_finished() {
        match sim.advance(u64::MAX) {
            Ok(Some(s)) => snaps.push(s),
            Ok(None) => {}
            Err(e) => return (snaps, t0.elapsed().as_secs_f64() / window, Some(e.to_string())),
        }
    }
    (snaps, t0.elapsed().as_secs_f64() / window, None)
}

fn coupled_front() -> f64 {
    let reference = bed(1);
    let (ref_snaps, ref_cost) = window(&reference, "tradeoff-seed1", 1);
    let grid = fluid_grid(&reference);
    let r = stats(&ref_snaps, &grid);
    let (floor_snaps, _) = window(&bed(2), "tradeoff-seed2", 1);
    let floor = errors(&stats(&floor_snaps, &grid), &r);
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "noise_floor", "setting": "seed 2, interval 1", "errors": floor})
    );
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "coupling_interval", "setting": 1, "wall_s_per_sim_s": ref_cost,
        "dp_mean_pa": r.dp_mean, "dp_std_pa": r.dp_std, "dp_freq_hz": r.dp_freq})
    );
    let mut default_cost = ref_cost;
    for interval in [2u32, 5, 10, 20] {
        let (snaps, cost) = window(&reference, "tradeoff-seed1", interval);
        let s = stats(&snaps, &grid);
        if interval == reference.coupling.interval_steps {
            default_cost = cost;
        }
        println!(
            "{}",
            json!({"bench": "tradeoff_point", "knob": "coupling_interval", "setting": interval,
            "wall_s_per_sim_s": cost, "errors": errors(&s, &r), "dp_mean_pa": s.dp_mean, "dp_std_pa": s.dp_std, "dp_freq_hz": s.dp_freq})
        );
    }
    let mut exact = reference.clone();
    exact.voidage = Voidage::ExactCylindrical;
    let (snaps, cost) = window(&exact, "tradeoff-exact", exact.coupling.interval_steps);
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "voidage", "setting": "exact_cylindrical at the default interval",
        "wall_s_per_sim_s": cost, "errors": errors(&stats(&snaps, &grid), &r)})
    );
    for f in ACOUSTIC_FACTORS {
        acoustic_point(&reference, &r, f);
    }
    layer_height_point(&reference, r);
    default_cost
}

/// The acoustic speed at `f` times the sound speed at the default interval, against the reference.
fn acoustic_point(reference: &Case, r: &Stats, f: f64) {
    let case = with_acoustic_factor(reference, f);
    let (snaps, cost) = window(&case, &format!("tradeoff-acoustic-{f}"), case.coupling.interval_steps);
    let s = stats(&snaps, &fluid_grid(&case));
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "acoustic_speed_factor", "setting": format!("{f} at the default interval"),
        "wall_s_per_sim_s": cost, "errors": errors(&s, r), "dp_mean_pa": s.dp_mean, "dp_std_pa": s.dp_std, "dp_freq_hz": s.dp_freq})
    );
}

/// The every-step reference's statistics, after printing the noise floor (the same reference from
/// a second poured bed) against them.
fn reference_beside_floor(reference: &Case, floor_case: &Case) -> Stats {
    let (ref_snaps, _) = window(reference, "tradeoff-seed1", 1);
    let r = stats(&ref_snaps, &fluid_grid(reference));
    let (floor_snaps, _) = window(floor_case, "tradeoff-seed2", 1);
    let floor = stats(&floor_snaps, &fluid_grid(floor_case));
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "noise_floor", "setting": "seed 2, interval 1",
        "errors": errors(&floor, &r), "dp_mean_pa": r.dp_mean, "dp_std_pa": r.dp_std, "dp_freq_hz": r.dp_freq})
    );
    r
}

/// One window from the reference's spin-up state with `set` applied, printed as a point of `knob`
/// against the reference's statistics `r`.
fn point_from_spin_up(reference: &Case, r: &Stats, knob: &str, setting: String, set: impl FnOnce(&mut Simulation)) {
    let mut sim = Simulation::restore(&state_at(reference, SPIN_UP_S, "tradeoff-seed1")).expect("state");
    set(&mut sim);
    let (snaps, cost, stopped) = run_window(&mut sim);
    assert!(stopped.is_none(), "stable run: {stopped:?}");
    let s = stats(&snaps, &fluid_grid(reference));
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": knob, "setting": setting, "wall_s_per_sim_s": cost,
        "errors": errors(&s, r), "dp_mean_pa": s.dp_mean, "dp_std_pa": s.dp_std, "dp_freq_hz": s.dp_freq})
    );
}

/// `-- tradeoff scheme`: the gas's time scheme (cfd/forward_backward.rs) at the default interval,
/// each from the reference's spin-up state, against the reference and beside the noise floor.
fn scheme_front() {
    let reference = bed(1);
    let r = reference_beside_floor(&reference, &bed(2));
    let interval = reference.coupling.interval_steps;
    for scheme in [TimeScheme::Ab3, TimeScheme::ForwardBackward] {
        point_from_spin_up(&reference, &r, "gas_time_scheme", format!("{scheme:?} at interval {interval}"), |sim| {
            sim.set_coupling_interval(interval);
            sim.set_gas_time_scheme(scheme);
        });
    }
}

/// `-- tradeoff pressure`: the particles' pressure force between couplings held (the paper's) or at
/// the interval's mean (`coupling.pressure_force`), at intervals 10 and 20, each from the
/// reference's spin-up state, against the reference and beside the noise floor.
fn pressure_front() {
    pressure_force_points("pressure_force", &[10, 20], &[PressureForce::Held, PressureForce::IntervalMean]);
}

/// `-- tradeoff interval`: the pressure force at the interval's mean (the default) at coupling
/// intervals 20, 30, 40 and 50, against the reference beside its floor.
fn interval_front() {
    pressure_force_points("coupling_interval", &[20, 30, 40, 50], &[PressureForce::IntervalMean]);
}

/// Each pressure force of `hows` at each coupling interval of `intervals`, one window each from
/// the reference's spin-up, printed as points of `knob` beside the reference's floor.
fn pressure_force_points(knob: &str, intervals: &[u32], hows: &[PressureForce]) {
    let reference = bed(1);
    let r = reference_beside_floor(&reference, &bed(2));
    for &interval in intervals {
        for &how in hows {
            point_from_spin_up(&reference, &r, knob, format!("{how:?} at interval {interval}"), |sim| {
                sim.set_coupling_interval(interval);
                sim.set_pressure_force(how);
            });
        }
    }
}

/// `-- tradeoff long`: intervals of 40 to 160 with the gas's voidage held or interpolated and
/// the drag on the gas held or implicit (`coupling.gas_voidage`, `coupling.gas_drag`), the
/// pressure force at the interval's mean, against the reference beside its floor.
fn long_interval_front() {
    let reference = bed(1);
    let r = reference_beside_floor(&reference, &bed(2));
    let (held, interpolated) = (GasVoidage::Held, GasVoidage::Interpolated);
    for (voidage, drag, interval) in [
        (held, GasDrag::Held, 40u32),
        (held, GasDrag::Implicit, 40),
        (interpolated, GasDrag::Held, 40),
        (interpolated, GasDrag::Implicit, 40),
        (interpolated, GasDrag::Held, 80),
        (interpolated, GasDrag::Implicit, 80),
        (interpolated, GasDrag::Implicit, 160),
    ] {
        let setting = format!("{voidage:?} gas voidage, {drag:?} gas drag at interval {interval}");
        point_from_spin_up(&reference, &r, "long_interval", setting, |sim| {
            sim.set_coupling_interval(interval);
            sim.set_pressure_force(PressureForce::IntervalMean);
            sim.set_gas_voidage(voidage);
            sim.set_gas_drag(drag);
        });
    }
}

/// `-- tradeoff probe`: windows from the reference's spin-up at the settings of
/// `FLUIDBED_PROBE` ("interval:gas_voidage:pressure_force:gas_drag" separated by ";", the names as
/// in the case), each printed with its ΔP statistics and voidage profiles (no reference run).
fn probe() {
    let reference = bed(1);
    let spec = std::env::var("FLUIDBED_PROBE").expect("FLUIDBED_PROBE");
    for item in spec.split(';').filter(|s| !s.is_empty()) {
        let f: Vec<&str> = item.split(':').collect();
        let interval: u32 = f[0].parse().expect("interval");
        fn parse<T: serde::de::DeserializeOwned>(s: &str) -> T {
            serde_json::from_value(serde_json::Value::String(s.into())).expect(s)
        }
        let (gv, pf, gd): (GasVoidage, PressureForce, GasDrag) = (parse(f[1]), parse(f[2]), parse(f[3]));
        let mut sim = Simulation::restore(&state_at(&reference, SPIN_UP_S, "tradeoff-seed1")).expect("state");
        sim.set_coupling_interval(interval);
        sim.set_gas_voidage(gv);
        sim.set_pressure_force(pf);
        sim.set_gas_drag(gd);
        let (snaps, cost, stopped) = run_window(&mut sim);
        let s = stats(&snaps, &fluid_grid(&reference));
        println!(
            "{}",
            json!({"bench": "tradeoff_probe", "setting": item, "wall_s_per_sim_s": cost, "stopped": stopped,
            "dp_mean_pa": s.dp_mean, "dp_std_pa": s.dp_std, "dp_freq_hz": s.dp_freq})
        );
    }
}

/// `-- tradeoff sound`: the reference window and the acoustic speed points alone.
fn acoustic_front() {
    let reference = bed(1);
    let (ref_snaps, _) = window(&reference, "tradeoff-seed1", 1);
    let r = stats(&ref_snaps, &fluid_grid(&reference));
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "coupling_interval", "setting": 1, "dp_mean_pa": r.dp_mean,
        "dp_std_pa": r.dp_std, "dp_freq_hz": r.dp_freq})
    );
    for f in ACOUSTIC_FACTORS {
        acoustic_point(&reference, &r, f);
    }
}

/// Fluid layer height dr instead of dr/2 at the default interval, against the reference's
/// statistics `r` with its layers merged in pairs.
fn layer_height_point(reference: &Case, r: Stats) {
    let coarse = layers_of_dr(reference);
    let (snaps, cost) = window(&coarse, "tradeoff-dz-dr", coarse.coupling.interval_steps);
    let s = stats(&snaps, &fluid_grid(&coarse));
    let pairs = |v: &[f64]| v.chunks(2).map(|p| p.iter().sum::<f64>() / p.len() as f64).collect::<Vec<_>>();
    let r2 = Stats { axial: pairs(&r.axial), ..r };
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "layer_height", "setting": "dz = dr at the default interval",
        "wall_s_per_sim_s": cost, "errors": errors(&s, &r2), "dp_mean_pa": s.dp_mean, "dp_std_pa": s.dp_std, "dp_freq_hz": s.dp_freq})
    );
}

/// The gas's voidage extrapolated or interpolated between couplings (`coupling.gas_voidage`) at
/// long intervals, beside the held voidage, against the paper's every-step reference and its
/// noise floor (the extrapolated points first).
fn gas_voidage_front() {
    let reference = bed(1);
    let (ref_snaps, ref_cost) = window(&reference, "tradeoff-seed1", 1);
    let grid = fluid_grid(&reference);
    let r = stats(&ref_snaps, &grid);
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "coupling_interval", "setting": 1, "wall_s_per_sim_s": ref_cost,
        "dp_mean_pa": r.dp_mean, "dp_std_pa": r.dp_std, "dp_freq_hz": r.dp_freq})
    );
    let (floor_snaps, _) = window(&bed(2), "tradeoff-seed2", 1);
    println!(
        "{}",
        json!({"bench": "tradeoff_point", "knob": "noise_floor", "setting": "seed 2, interval 1",
        "errors": errors(&stats(&floor_snaps, &grid), &r)})
    );
    let (held, interpolated, extrapolated) = (GasVoidage::Held, GasVoidage::Interpolated, GasVoidage::Extrapolated);
    for (how, interval) in [
        (extrapolated, 20u32),
        (extrapolated, 10),
        (interpolated, 20),
        (held, 10),
        (interpolated, 10),
        (held, 20),
        (extrapolated, 50),
        (interpolated, 50),
        (held, 50),
    ] {
        let (snaps, cost) = window_as(&reference, "tradeoff-seed1", interval, how);
        let s = stats(&snaps, &grid);
        println!(
            "{}",
            json!({"bench": "tradeoff_point", "knob": "gas_voidage", "setting": format!("{how:?}, interval {interval}"),
            "wall_s_per_sim_s": cost, "errors": errors(&s, &r), "dp_mean_pa": s.dp_mean, "dp_std_pa": s.dp_std, "dp_freq_hz": s.dp_freq})
        );
    }
}

/// `-- tradeoff layer`: the reference window and the layer-height point alone.
fn layer_front() {
    let reference = bed(1);
    let (ref_snaps, _) = window(&reference, "tradeoff-seed1", 1);
    let r = stats(&ref_snaps, &fluid_grid(&reference));
    layer_height_point(&reference, r);
}

/// Mean L1 over three packings and ns per particle per call of `make`'s method.
fn voidage_point(g: &CylGrid, a: f64, make: &dyn Fn() -> Box<dyn VoidageMethod>) -> (f64, f64) {
    let (mut l1_sum, mut ns_sum) = (0.0, 0.0);
    let n = g.num_cells();
    let (mut solid, mut e, mut e_ref) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for (k, eps) in [0.4, 0.6, 0.9].into_iter().enumerate() {
        let pos = packing(g, eps, a, 200 + k as u64);
        ExactCylindrical::with_nodes(g, 48).solid_volume(&pos, a, &mut solid);
        voidage_from_solid(g, &solid, &mut e_ref);
        let mut m = make();
        m.solid_volume(&pos, a, &mut solid);
        voidage_from_solid(g, &solid, &mut e);
        l1_sum += l1(&e, &e_ref);
        let (t0, mut reps) = (Instant::now(), 0);
        while reps < 3 || t0.elapsed().as_secs_f64() < 0.2 {
            m.solid_volume(&pos, a, &mut solid);
            reps += 1;
        }
        ns_sum += t0.elapsed().as_secs_f64() * 1e9 / (reps * pos.len()) as f64;
    }
    (l1_sum / 3.0, ns_sum / 3.0)
}

/// Cost of each setting on the reference bed, interleaved in one process (rounds of 1,000 steps
/// from the same state), so that the VM's speed swings fall on all settings alike: wall seconds
/// per simulated second.
fn interleaved_costs() {
    let reference = bed(1);
    let state = state_at(&reference, SPIN_UP_S, "tradeoff-seed1");
    let mut exact = reference.clone();
    exact.voidage = Voidage::ExactCylindrical;
    let exact_state = state_at(&exact, SPIN_UP_S, "tradeoff-exact");
    let mut runs: Vec<(String, Simulation, Tally)> = Vec::new();
    for interval in [1u32, 2, 5, 10, 20] {
        let mut sim = Simulation::restore(&state).expect("state");
        sim.set_coupling_interval(interval);
        runs.push((format!("coupling_interval {interval}"), sim, Tally::default()));
    }
    let sim = Simulation::restore(&exact_state).expect("state");
    runs.push(("exact_cylindrical at the default interval".into(), sim, Tally::default()));
    let coarse_state = state_at(&layers_of_dr(&reference), SPIN_UP_S, "tradeoff-dz-dr");
    let sim = Simulation::restore(&coarse_state).expect("state");
    runs.push(("dz = dr at the default interval".into(), sim, Tally::default()));
    for f in ACOUSTIC_FACTORS {
        let state = state_at(&with_acoustic_factor(&reference, f), SPIN_UP_S, &format!("tradeoff-acoustic-{f}"));
        let sim = Simulation::restore(&state).expect("state");
        runs.push((format!("acoustic_speed_factor {f} at the default interval"), sim, Tally::default()));
    }
    for _ in 0..6 {
        for (_, sim, t) in runs.iter_mut() {
            coupled_round(sim, 1000, t);
        }
    }
    let dt = reference.dem.time_step_s;
    for (label, _, t) in &runs {
        println!(
            "{}",
            json!({"bench": "tradeoff_cost", "setting": label, "wall_s_per_sim_s": t.per_step() / dt,
            "stages_s_per_step": t.stages_json()})
        );
    }
}

pub fn run() {
    let part = std::env::args().nth(2).unwrap_or_default();
    if part.is_empty() || part == "errors" {
        coupled_front();
    }
    let alone: Option<fn()> = match part.as_str() {
        "gas-voidage" => Some(gas_voidage_front),
        "scheme" => Some(scheme_front),
        "pressure" => Some(pressure_front),
        "interval" => Some(interval_front),
        "probe" => Some(probe),
        "long" => Some(long_interval_front),
        _ => None,
    };
    if let Some(front) = alone {
        return front();
    }
    if part == "layer" {
        layer_front();
    }
    if part == "sound" {
        acoustic_front();
    }
    if part.is_empty() || part == "cost" {
        interleaved_costs();
    }
    let case = shipped_case("bubbling-44mm.json");
    let mut g = fluid_grid(&case);
    g = CylGrid::new(g.radius, 20.0 * g.dz, g.dr, g.dz, g.n0);
    let a = case.particles.diameter_m / 2.0;
    let interval = case.coupling.interval_steps as f64;
    let sg3 = || -> Box<dyn VoidageMethod> { Box::new(SquareGrid::new(&g, 1.375e-3, BoxSplit::Cuboid, 1.0)) };
    let (sg3_l1, sg3_ns) = voidage_point(&g, a, &sg3);
    println!(
        "{}",
        json!({"bench": "tradeoff_voidage", "method": "square_grid cuboid config 3", "l1": sg3_l1, "ns_per_particle_call": sg3_ns})
    );
    // The square grid with boxes below d and the cube side just under the box (every cube still
    // in at most 2 × 2 × 2 boxes), the front the shipped cases' choice comes from.
    for (side, f) in [(1.1e-3, 0.806), (0.9e-3, 0.75), (0.8e-3, 0.66), (0.6875e-3, 0.57)] {
        let (l, ns) = voidage_point(&g, a, &|| Box::new(SquareGrid::new(&g, side, BoxSplit::Cuboid, f)));
        println!(
            "{}",
            json!({"bench": "tradeoff_voidage", "method": format!("square_grid cuboid, {:.4} mm boxes, cube side {f} d", side * 1e3),
            "l1": l, "ns_per_particle_call": ns, "ns_per_particle_step_at_default_interval": ns / interval})
        );
    }
    for nodes in [2usize, 3, 4] {
        let (l, ns) = voidage_point(&g, a, &|| Box::new(ExactCylindrical::with_nodes(&g, nodes)));
        println!(
            "{}",
            json!({"bench": "tradeoff_voidage", "method": format!("exact_cylindrical {nodes} nodes"), "l1": l,
            "ns_per_particle_call": ns, "ns_per_particle_step_at_default_interval": ns / interval})
        );
    }
    // The shipped case's own method, built as a run builds it.
    let (default_l1, default_ns) = voidage_point(&g, a, &|| build_voidage(&case, &g));
    let default_name = match &case.voidage {
        Voidage::SquareGrid { box_side_m, split, cube_side_factor } => format!(
            "square_grid {split:?}, {} boxes, cube side {cube_side_factor} d",
            box_side_m.map_or("default".into(), |b| format!("{:.4} mm", b * 1e3))
        ),
        other => format!("{other:?}"),
    };
    println!(
        "{}",
        json!({"bench": "tradeoff", "default_voidage": format!("{default_name}, coupling every {interval} DEM steps"),
            "default_l1": default_l1, "default_ns_per_particle": default_ns / interval,
            "paper_sg3_l1": sg3_l1, "paper_sg3_ns_per_particle": sg3_ns})
    );
}
