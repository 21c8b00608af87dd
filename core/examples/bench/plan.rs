//! `bench -- plan`: each skip of the scene plan (core/src/sim/plan.rs) measured against the same
//! scene made to do the work it skips, the two interleaved in rounds in one process so that
//! their ratio survives the VM's speed swings. The scene is the quickstart bed (4,850 poured
//! particles in the 22-mm column), except for the frozen bed, which is the shipped frozen case.
//! The skips are:
//! - frozen_packed_bed: `cases/packed-bed.json` (the paper's Fig. 3 packed bed: 30,135 particles in
//!   the 44-mm column, `dem.frozen`, U = 0.2 m/s, below U_mf) against the same bed stepped;
//! - frozen_small_bed: the same skip on the quickstart bed (a coarser, cheaper DEM step and a bed
//!   a sixth the size, so the gas, which the skip keeps, is a larger part of the step);
//! - no_gas: a case without gas against the same bed under still gas (U = 0);
//! - frictionless: μ = 0 (no tangential history, no spin) against μ = 1e-300 (the friction path,
//!   the same forces to round-off);
//! - gas_subcycling: the gas at its own stable step against the gas at every DEM step (the
//!   paper's particles, DEM step 1.25 µs, U = 0.6 m/s);
//! - fields_not_requested: a DEM-only run snapshotting every 20 steps with no fields against the
//!   same with the voidage and particle fields.
//!
//! The answers are compared in core/src/sim/plan_tests.rs. One JSON line per skip, then
//! `{"bench":"plan","frozen_packed_bed_speedup":…, one key per skip}`.

use crate::coupled::{coupled_round, shipped_case, Tally};
use fluidbed_core::case::{Case, Field};
use fluidbed_core::sim::Simulation;
use serde_json::json;
use std::path::PathBuf;

/// The quickstart bed, long enough never to end here, snapshots out of the way.
fn scene() -> Case {
    let mut c = shipped_case("quickstart.json");
    c.end_time_s = 100.0;
    c.outputs.snapshot_interval_s = 10.0;
    c
}

fn gas_at(c: &mut Case, u: f64) {
    let g = c.gas.as_mut().expect("the quickstart has gas");
    g.superficial_velocity_m_s = u;
    g.ramp_time_s = 0.002;
}

/// Step both scenes `steps` DEM steps in all, interleaved in four rounds; (skipping, working)
/// seconds per step.
fn race(skipping: Case, working: Case, steps: u64) -> (f64, f64, [Simulation; 2]) {
    let bed = PathBuf::from(std::env::var("FLUIDBED_BED_CACHE").unwrap_or_else(|_| "target/fluidbed-bed-cache".into()));
    let mut sims = [skipping, working].map(|c| Simulation::new(c, Some(&bed)).expect("scene builds"));
    let mut t = [Tally::default(), Tally::default()];
    // A warm-up round each (lists built, caches filled), not timed.
    for s in sims.iter_mut() {
        coupled_round(s, steps / 8, &mut Tally::default());
    }
    for _ in 0..4 {
        for (s, t) in sims.iter_mut().zip(t.iter_mut()) {
            coupled_round(s, steps / 4, t);
        }
    }
    (t[0].per_step(), t[1].per_step(), sims)
}

pub fn run() {
    let mut speedups = serde_json::Map::new();
    let mut report = |key: &str, skipping: Case, working: Case, steps: u64| {
        let (ts, tw, sims) = race(skipping, working, steps);
        let plans = [sims[0].plan(), sims[1].plan()];
        println!(
            "{}",
            json!({"bench": "plan_skip", "skip": key, "particles": sims[0].dem().len(), "steps": steps,
                "s_per_step_skipping": ts, "s_per_step_working": tw, "speedup": tw / ts,
                "plan_skipping": plans[0], "plan_working": plans[1]})
        );
        eprintln!("plan: {key}: {:.3} ms per step skipping, {:.3} ms working: {:.2}×", ts * 1e3, tw * 1e3, tw / ts);
        speedups.insert(format!("{key}_speedup"), json!((tw / ts * 1000.0).round() / 1000.0));
    };

    let packed = || {
        let mut c = shipped_case("packed-bed.json");
        c.end_time_s = 100.0;
        c.outputs.snapshot_interval_s = 10.0;
        gas_at(&mut c, 0.2);
        c
    };
    let (frozen, mut stepped) = (packed(), packed());
    assert!(frozen.dem.frozen, "the shipped packed bed is frozen");
    stepped.dem.frozen = false;
    report("frozen_packed_bed", frozen, stepped, 2000);

    let (mut frozen, mut stepped) = (scene(), scene());
    gas_at(&mut frozen, 0.2);
    gas_at(&mut stepped, 0.2);
    frozen.dem.frozen = true;
    report("frozen_small_bed", frozen, stepped, 2000);

    let (mut dry, mut still) = (scene(), scene());
    dry.gas = None;
    gas_at(&mut still, 0.0);
    report("no_gas", dry, still, 2000);

    let (mut smooth, mut rough) = (scene(), scene());
    smooth.gas = None;
    rough.gas = None;
    smooth.particles.sliding_friction = 0.0;
    rough.particles.sliding_friction = 1e-300;
    report("frictionless", smooth, rough, 2000);

    // The paper's particles: a DEM step below the gas's stable step.
    let (mut sub, mut every) = (scene(), scene());
    for c in [&mut sub, &mut every] {
        c.particles.youngs_modulus_pa = 1.2e8;
        c.dem.time_step_s = 1.25e-6;
        gas_at(c, 0.6);
    }
    every.gas.as_mut().expect("gas").time_step_s = Some(1.25e-6);
    report("gas_subcycling", sub, every, 4000);

    let (mut bare, mut full) = (scene(), scene());
    for c in [&mut bare, &mut full] {
        c.gas = None;
        c.outputs.snapshot_interval_s = 20.0 * c.dem.time_step_s;
    }
    bare.outputs.fields = vec![];
    full.outputs.fields = vec![Field::Voidage, Field::Particles];
    report("fields_not_requested", bare, full, 2000);

    let mut last = serde_json::Map::new();
    last.insert("bench".into(), json!("plan"));
    last.extend(speedups);
    println!("{}", serde_json::Value::Object(last));
}
