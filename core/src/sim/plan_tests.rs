//! Each skip of the plan gives the answer of the same scene made to do the skipped work (the
//! speed-up of each is measured by `bench -- plan`): to round-off where the skip is exact, within
//! a stated tolerance where the working scene is a different computation of the same physics.

use super::plan::{aligned_gas_dt, gas_steps_due};
use super::tests::lattice_case;
use super::*;
use crate::case::Gas;

fn run(case: Case) -> (Simulation, Vec<Snapshot>) {
    assert!(case.validate().is_ok(), "{:?}", case.validate().errors);
    let mut snaps: Vec<Snapshot> = Vec::new();
    let mut sim = Simulation::new(case, None).unwrap();
    sim.run(&mut snaps).unwrap();
    (sim, snaps)
}

fn largest_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter().zip(b).flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs())).fold(0.0, f64::max)
}

/// A loose lattice (spacing 1.3 d, each particle shifted sideways by up to ±0.1 d) falling onto
/// the distributor of a 13-mm column: oblique collisions, sliding and spin within the run.
fn falling(mu: f64) -> Case {
    let mut c = lattice_case(0.0132, 0.0264, 0.008, 1.3, None);
    if let crate::case::Bed::Explicit(e) = &mut c.bed {
        let d = c.particles.diameter_m;
        for (k, p) in e.positions_m.iter_mut().enumerate() {
            let phase = k as f64 * 2.399_963;
            p[0] += 0.1 * d * phase.cos();
            p[1] += 0.1 * d * phase.sin();
        }
    }
    c.particles.sliding_friction = mu;
    c.end_time_s = 0.02;
    c.outputs.snapshot_interval_s = 0.001;
    c
}

#[test]
fn frictionless_particles_move_as_on_the_friction_path_with_no_friction() {
    let (smooth, _) = run(falling(0.0));
    let (rough, _) = run(falling(1e-300));
    assert!(!smooth.plan().tangential && rough.plan().tangential);
    assert!(smooth.plan().skipped(smooth.case()).iter().any(|s| s.contains("sliding_friction = 0")));
    // The rough particles spin (so the friction path ran), by no more than round-off allows.
    let spin = rough.dem().angular_velocities().iter().flatten().fold(0.0f64, |m, w| m.max(w.abs()));
    let moved = smooth.dem().velocities().iter().any(|v| v[2].abs() > 0.05);
    assert!(moved, "the particles fall and collide");
    assert!(spin < 1e-200, "spin {spin} rad/s with μ = 1e-300");
    let d = largest_difference(smooth.dem().positions(), rough.dem().positions());
    assert!(d <= 1e-15, "positions differ by {d} m");
}

#[test]
fn fields_not_requested_change_no_particle_state() {
    let (mut bare, mut full) = (falling(0.1), falling(0.1));
    for c in [&mut bare, &mut full] {
        c.outputs.snapshot_interval_s = 20.0 * c.dem.time_step_s;
    }
    bare.outputs.fields = vec![];
    full.outputs.fields = vec![Field::Voidage, Field::Particles];
    let ((a, sa), (b, sb)) = (run(bare), run(full));
    assert!(!a.plan().voidage_field && b.plan().voidage_field);
    assert_eq!(sa.len(), sb.len());
    assert!(sa[1].voidage.is_none() && sb[1].voidage.is_some());
    assert_eq!(a.dem().positions(), b.dem().positions());
    assert_eq!(a.dem().velocities(), b.dem().velocities());
}

/// A simple cubic stack of touching particles (it stands on its own) in a 13-mm column, gas
/// below U_mf. The stack is turned by 0.1 rad about the axis and its axial column left out, so
/// that no centre lies on a cell face: a particle on a face goes to either cell as round-off
/// moves it, and the two runs compared would then differ by that choice alone.
fn stack(gas: Option<Gas>) -> Case {
    let mut c = lattice_case(0.0132, 0.0264, 0.0096, 1.0, gas);
    if let crate::case::Bed::Explicit(e) = &mut c.bed {
        let (cos, sin) = (0.1f64.cos(), 0.1f64.sin());
        e.positions_m.retain(|p| p[0].hypot(p[1]) > 1e-9);
        for p in e.positions_m.iter_mut() {
            *p = [p[0] * cos - p[1] * sin, p[0] * sin + p[1] * cos, p[2]];
        }
    }
    c.grid.dr_m = 0.0022;
    // Layers of 2.4 mm: no face at a centre height (0.6 + 1.2 k mm).
    c.grid.dz_m = Some(0.0024);
    c.end_time_s = 0.01;
    c.outputs.snapshot_interval_s = 0.005;
    c.outputs.fields = vec![Field::Voidage, Field::Pressure];
    c
}

fn below_umf() -> Gas {
    Gas { superficial_velocity_m_s: 0.15, ramp_time_s: 0.002, ..Gas::default() }
}

#[test]
fn a_frozen_packed_bed_has_the_pressure_drop_of_the_same_bed_stepped_at_rest() {
    // The frozen shortcut takes the exchange in O(cells) for particles at rest. The stepped
    // bed is held at rest in a weightless column (gravity 0) with heavy particles
    // (20,000 kg/m³), and the run stops at 5 ms, while drag has moved them by under 1 µm: any
    // voidage change, however small, displaces gas and sends a pressure wave (solver.rs
    // `set_voidage`), so the stepped bed must not move for the two to be compared.
    let at_rest = || {
        let mut c = stack(Some(below_umf()));
        c.gravity_m_s2 = 0.0;
        c.particles.density_kg_m3 = 20_000.0;
        // The exact split: a voidage continuous in the positions (a square grid's sub-boxes
        // jump between cells as a centre crosses their faces).
        c.voidage = crate::case::Voidage::ExactCylindrical;
        c.end_time_s = 0.005;
        c.outputs.snapshot_interval_s = 0.001;
        c
    };
    let mut frozen = at_rest();
    frozen.dem.frozen = true;
    let ((f, sf), (m, sm)) = (run(frozen), run(at_rest()));
    assert!(!f.plan().particles_move && m.plan().particles_move);
    assert!(f.plan().skipped(f.case()).iter().any(|s| s.contains("dem.frozen")), "{:?}", f.plan().skipped(f.case()));
    let moved = largest_difference(f.dem().positions(), m.dem().positions());
    assert!(moved < 1e-6, "the stepped bed moved {moved} m");
    assert_eq!(sf.len(), 6);
    for (x, y) in sf.iter().zip(&sm).skip(1) {
        let (a, b) = (x.pressure_drop_pa.unwrap(), y.pressure_drop_pa.unwrap());
        assert!(a > 1.0, "the bed holds a pressure drop ({a} Pa at {} s)", x.time_s);
        // Tolerance 1e-3: the stepped particles drift up to ≈ 0.2 mm/s by 5 ms, which takes
        // ≈ 5e-4 off the slip of the gas's ≈ 0.3 m/s.
        assert!((a / b - 1.0).abs() < 1e-3, "ΔP at {} s: frozen {a:.6} Pa vs stepped {b:.6} Pa", x.time_s);
    }
}

#[test]
fn gas_sub_cycled_at_its_stable_step_gives_the_pressure_drop_of_every_step() {
    let (mut sub, mut every) = (stack(Some(below_umf())), stack(Some(below_umf())));
    sub.dem.frozen = true;
    every.dem.frozen = true;
    every.gas.as_mut().unwrap().time_step_s = Some(every.dem.time_step_s);
    let ((s, ss), (e, se)) = (run(sub), run(every));
    assert!(s.plan().gas_steps_per_dem_step < 0.9, "sub-cycled: {:?}", s.plan());
    assert!((e.plan().gas_steps_per_dem_step - 1.0).abs() < 1e-12);
    let (a, b) = (ss.last().unwrap().pressure_drop_pa.unwrap(), se.last().unwrap().pressure_drop_pa.unwrap());
    // Tolerance 0.1%: the same steady state, reached with a different time step.
    assert!((a / b - 1.0).abs() < 1e-3, "ΔP sub-cycled {a:.4} Pa vs every step {b:.4} Pa");
}

#[test]
fn a_bed_without_gas_settles_as_under_still_gas() {
    let still = Gas { superficial_velocity_m_s: 0.0, ramp_time_s: 0.002, ..Gas::default() };
    let ((dry, _), (wet, _)) = (run(stack(None)), run(stack(Some(still))));
    assert!(!dry.plan().gas && wet.plan().gas);
    let mean_z = |s: &Simulation| s.dem().positions().iter().map(|p| p[2]).sum::<f64>() / s.dem().len() as f64;
    // Tolerance 1e-4 d: still gas only adds buoyancy, ρ_g/ρ_p ≈ 0.1% of the weight, and changes
    // the contact overlaps (already ≪ d) by that fraction.
    let d = dry.case().particles.diameter_m;
    assert!((mean_z(&dry) - mean_z(&wet)).abs() < 1e-4 * d, "{} vs {}", mean_z(&dry), mean_z(&wet));
}

#[test]
fn the_gas_steps_a_whole_fraction_of_the_coupling_interval_and_meets_the_particles_at_each_coupling() {
    assert_eq!(aligned_gas_dt(3.33e-6, 1.25e-6), 3.33e-6, "an interval shorter than the cap keeps the cap");
    assert!((aligned_gas_dt(3.33e-6, 12.5e-6) - 3.125e-6).abs() < 1e-20);
    assert!((aligned_gas_dt(6.89e-6, 25e-6) - 6.25e-6).abs() < 1e-20);
    assert_eq!(gas_steps_due(3, 1.0, 1.5), 2);
    assert_eq!(gas_steps_due(10_000_000, 1.25e-6, 6.25e-6), 2_000_000, "a whole count up to rounding");

    let mut c = super::resume_tests::case();
    c.coupling.interval_steps = 6;
    let mut sim = Simulation::new(c, None).unwrap();
    let (dt, dt_g) = (sim.case().dem.time_step_s, sim.plan().gas_dt_s.unwrap());
    let per_interval = 6.0 * dt / dt_g;
    assert!(
        per_interval >= 1.0 && (per_interval - per_interval.round()).abs() < 1e-9,
        "{per_interval} gas steps per interval"
    );
    let stable = sim.gas().unwrap().stable_dt();
    assert!(dt_g <= stable && dt_g > 0.5 * stable, "gas step {dt_g:e} s, stable {stable:e} s");
    let mut couplings = 0;
    while sim.steps() < 60 {
        let coupling_at = sim.steps();
        sim.step().unwrap();
        if coupling_at.is_multiple_of(6) && coupling_at > 0 {
            let (t_gas, t_dem) = (sim.gas().unwrap().time(), coupling_at as f64 * dt);
            assert!(
                (t_gas - t_dem).abs() < 1e-12 * t_dem,
                "step {coupling_at}: gas at {t_gas:e} s, particles at {t_dem:e} s"
            );
            couplings += 1;
        }
    }
    assert_eq!(couplings, 9);
}
