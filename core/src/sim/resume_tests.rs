//! Resume from a checkpoint continues bit-identically on the shipped quickstart physics: a
//! generated (poured) bed, square-grid voidage, gas sub-cycled at its own step, a coupling
//! interval above 1, two threads (several chunks in the DEM's pair pass).

use super::*;

/// DEM steps of the run; the checkpoint is taken at `CUT`, which is neither a coupling step
/// (interval 3) nor a snapshot step (every 167), so the drag, voidage and gas held between
/// couplings all cross it; the snapshot at 501 is the first one taken from the restored state.
const STEPS: u64 = 1002;
const CUT: u64 = 500;

/// The resume case (also the pressure-force test's, pressure_follow.rs).
pub(super) fn case() -> Case {
    let mut c: Case = serde_json::from_str(
        r#"{"name":"resume","column":{"diameter_m":0.016,"height_m":0.048},
            "particles":{"diameter_m":0.0012,"density_kg_m3":1000.0,"youngs_modulus_pa":1.0e7,
              "poisson_ratio":0.33,"sliding_friction":0.1,
              "normal_damping":{"tsuji_alpha":0.02},"tangential_damping":{"tsuji_alpha":0.0001}},
            "bed":{"generated":{"count":1600,"seed":4}},
            "dem":{"time_step_s":4.0e-6},
            "gas":{"superficial_velocity_m_s":0.9,"ramp_time_s":0.001},
            "grid":{"dr_m":0.004,"n0":3},
            "voidage":{"method":"square_grid","split":"cuboid"},
            "coupling":{"interval_steps":3},
            "outputs":{"snapshot_interval_s":0.000668,"fields":["voidage","pressure","gas_velocity","particles"]},
            "end_time_s":0.004008}"#,
    )
    .unwrap();
    c.end_time_s = STEPS as f64 * c.dem.time_step_s;
    c
}

/// Step `sim` until it has run `steps` DEM steps, collecting the snapshots on the way.
fn run_to(sim: &mut Simulation, steps: u64, snaps: &mut Vec<Snapshot>) {
    while sim.steps() < steps {
        if let Some(s) = sim.advance(steps - sim.steps()).unwrap() {
            snaps.push(s);
        }
    }
    assert_eq!(sim.steps(), steps);
}

#[test]
fn resume_of_a_generated_bubbling_bed_on_two_threads_is_bit_identical() {
    resume_is_bit_identical(case());
}

#[test]
fn resume_with_a_slowed_acoustic_speed_reports_the_same_absolute_pressures() {
    // The solver carries p = c²ρ; the reported pressure adds p_out − c²ρ_out, which a restored
    // run must add too (it is not in the gas state).
    let mut c = case();
    c.gas.as_mut().unwrap().acoustic_speed_factor = 0.5;
    let p_out = c.gas.as_ref().unwrap().outlet_pressure_pa;
    let snaps = resume_is_bit_identical(c);
    let p = snaps.last().unwrap().pressure_pa.as_ref().unwrap();
    let max = p.iter().fold(0.0f64, |m, &x| m.max((x - p_out).abs()));
    assert!(max < 1e3, "pressures {max} Pa from the outlet's {p_out} Pa: the offset is lost");
}

#[test]
fn resume_with_the_gas_voidage_interpolated_or_extrapolated_is_bit_identical() {
    // The cut falls inside a voidage ramp, which the checkpoint must carry (and the case says
    // which way it runs).
    for how in [crate::case::GasVoidage::Interpolated, crate::case::GasVoidage::Extrapolated] {
        let mut c = case();
        c.coupling.gas_voidage = how;
        resume_is_bit_identical(c);
    }
}

#[test]
fn resume_with_the_gas_stepped_forward_backward_is_bit_identical() {
    // The checkpoint's gas holds no scheme: the resumed gas takes it from the checkpoint's case.
    let mut c = case();
    c.gas.as_mut().unwrap().time_scheme = crate::cfd::TimeScheme::ForwardBackward;
    resume_is_bit_identical(c);
}

#[test]
fn resume_inside_an_inlet_jets_window_is_bit_identical() {
    // The checkpoint's gas holds no jet: the resumed gas takes it from the checkpoint's case.
    let mut c = case();
    c.gas.as_mut().unwrap().inlet_jet =
        Some(crate::case::InletJet { annuli: 1, superficial_velocity_m_s: 3.0, from_s: 0.001, until_s: Some(0.003) });
    resume_is_bit_identical(c);
}

#[test]
fn resume_with_the_drag_on_the_gas_implicit_is_bit_identical() {
    // The cut falls between couplings: the gas's drag coefficients and the coupling's gas
    // velocity are part of its state (cfd/implicit_drag.rs), on both gas schemes.
    for scheme in [crate::cfd::TimeScheme::ForwardBackward, crate::cfd::TimeScheme::Ab3] {
        let mut c = case();
        c.coupling.gas_drag = crate::case::GasDrag::Implicit;
        c.gas.as_mut().unwrap().time_scheme = scheme;
        resume_is_bit_identical(c);
    }
}

#[test]
fn resume_with_the_pressure_force_following_the_gas_is_bit_identical() {
    // The cut falls between couplings, where each particle's −V_p∇p has moved with the gas since
    // the coupling; the checkpoint carries the cells and the gradients it moves from.
    let mut c = case();
    c.coupling.pressure_force = crate::case::PressureForce::GasStep;
    resume_is_bit_identical(c);
}

#[test]
fn resume_with_the_interval_mean_pressure_force_is_bit_identical() {
    // The cut falls between couplings, where the sum of the gas's gradients is part of the state.
    let mut c = case();
    c.coupling.pressure_force = crate::case::PressureForce::IntervalMean;
    resume_is_bit_identical(c);
}

/// The resume tests' bed coupled every 6 DEM steps with the particles' pressure force `how`, run
/// to `steps`; and a copy of that state with the force held: two runs from one state.
pub(super) fn held_and(how: crate::case::PressureForce, steps: u64) -> (Simulation, Simulation) {
    let mut c = case();
    c.coupling.interval_steps = 6;
    c.coupling.pressure_force = how;
    // The gas's voidage set at each coupling: a ramp would move ε at the start of each gas step,
    // after the state these tests read their gradients from.
    c.coupling.gas_voidage = crate::case::GasVoidage::Held;
    assert!(c.validate().is_ok(), "{:?}", c.validate().errors);
    let mut a = Simulation::new(c, None).unwrap();
    while a.steps() < steps {
        a.step().unwrap();
    }
    let mut b = Simulation::restore(&a.checkpoint()).unwrap();
    b.st.case.coupling.pressure_force = crate::case::PressureForce::Held;
    (a, b)
}

/// Run `case` straight and with a checkpoint and restore at `CUT`: the snapshots and the final
/// state are the same bits. Returns the snapshots.
fn resume_is_bit_identical(case: Case) -> Vec<Snapshot> {
    assert!(case.validate().is_ok(), "{:?}", case.validate().errors);
    let pool = crate::dem::solver_pool().num_threads(2).build().unwrap();
    pool.install(|| {
        let straight = {
            let mut sim = Simulation::new(case.clone(), None).unwrap();
            let plan = sim.plan();
            assert!(plan.gas && plan.coupling && plan.particles_move && plan.coupling_interval == 3);
            let dt_g = plan.gas_dt_s.unwrap();
            let ratio = case.dem.time_step_s / dt_g;
            assert!((ratio - ratio.round()).abs() > 1e-3, "the gas step {dt_g} s is not a DEM-step fraction");
            let mut snaps = Vec::new();
            run_to(&mut sim, STEPS, &mut snaps);
            (sim, snaps)
        };
        let (a, full) = straight;
        assert!(a.dem().len() >= 1024, "enough particles for several pair-pass chunks");

        let mut first = Simulation::new(case.clone(), None).unwrap();
        let mut part = Vec::new();
        run_to(&mut first, CUT, &mut part);
        let bytes = first.checkpoint();
        drop(first);
        let mut b = Simulation::restore(&bytes).unwrap();
        run_to(&mut b, STEPS, &mut part);

        assert_eq!(full.len(), 7, "snapshots every 167 steps from 0 to {STEPS}");
        assert_eq!(part.len(), full.len());
        let mut differ = Vec::new();
        for (x, y) in full.iter().zip(&part) {
            assert_eq!(x.step, y.step);
            let fields = [
                ("voidage", x.voidage == y.voidage),
                ("pressure", x.pressure_pa == y.pressure_pa),
                ("gas velocity", x.gas_velocity_m_s == y.gas_velocity_m_s),
                ("particles", x.particles == y.particles),
                ("ΔP", x.pressure_drop_pa == y.pressure_drop_pa),
            ];
            differ.extend(fields.iter().filter(|f| !f.1).map(|f| format!("{} at step {}", f.0, x.step)));
        }
        if a.checkpoint() != b.checkpoint() {
            differ.push(format!("the checkpointed state at step {STEPS}"));
        }
        assert!(differ.is_empty(), "after resume at step {CUT}, these differ from the straight run: {differ:?}");
        // The bed really bubbles: the test is not met by particles at rest.
        let v = full.last().unwrap().particles.as_ref().unwrap();
        assert!(v.velocities_m_s.iter().any(|u| u[2].abs() > 1e-2), "the particles did not move");
        full
    })
}

/// One DEM step per `advance` call brings the gas to the particles' time after every step, as
/// the paper's loop does; longer calls take the gas steps of an interval together at the next
/// coupling (`sync_gas`). Both give the same snapshots and the same final state, bit for bit.
#[test]
fn the_gas_caught_up_at_couplings_gives_the_same_bits_as_step_by_step() {
    caught_up_equals_step_by_step(case());
}

#[test]
fn with_the_gas_voidage_ramped_the_gas_caught_up_at_couplings_gives_the_same_bits() {
    for how in [crate::case::GasVoidage::Interpolated, crate::case::GasVoidage::Extrapolated] {
        let mut c = case();
        c.coupling.gas_voidage = how;
        caught_up_equals_step_by_step(c);
    }
}

fn caught_up_equals_step_by_step(case: Case) {
    let pool = crate::dem::solver_pool().num_threads(2).build().unwrap();
    pool.install(|| {
        let steps = 340;
        let mut c = case;
        c.end_time_s = steps as f64 * c.dem.time_step_s;
        let (mut lazy, mut eager) = (Simulation::new(c.clone(), None).unwrap(), Simulation::new(c, None).unwrap());
        let (mut a, mut b) = (Vec::new(), Vec::new());
        run_to(&mut lazy, steps, &mut a);
        let dt_g = eager.plan().gas_dt_s.unwrap();
        while eager.steps() < steps {
            if let Some(s) = eager.advance(1).unwrap() {
                b.push(s);
            }
            // each call leaves the gas less than one gas step ahead of the particles
            let (tg, t) = (eager.gas().unwrap().time(), eager.time());
            assert!(tg >= t - 1e-12 && tg < t + dt_g, "gas at {tg} s, particles at {t} s");
        }
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            assert!(x.pressure_pa == y.pressure_pa && x.particles == y.particles, "snapshot at step {}", x.step);
        }
        assert!(lazy.checkpoint() == eager.checkpoint(), "the final states differ");
    })
}
