use super::*;

fn paper_case_json() -> &'static str {
    r#"{"column":{"diameter_m":0.044,"height_m":0.12},"particles":{},"bed":{"generated":{"settled_height_m":0.03,"seed":3}}}"#
}

#[test]
fn defaults_are_the_papers_table_1() {
    let (c, rep) = Case::parse_str(paper_case_json()).expect("valid");
    assert!(rep.errors.is_empty());
    assert_eq!(c.particles.youngs_modulus_pa, 1.2e8);
    assert_eq!(c.particles.poisson_ratio, 0.33);
    assert_eq!(c.particles.sliding_friction, 0.1);
    assert_eq!(c.particles.normal_damping, Damping::TsujiAlpha(0.02));
    assert_eq!(c.particles.tangential_damping, Damping::TsujiAlpha(1e-4));
    assert_eq!(c.dem.time_step_s, 1.25e-6);
    assert!(c.gas.is_none());
}

#[test]
fn restitution_and_alpha_round_trip_the_physics_table() {
    // PHYSICS.md 2.4 table.
    for (e, a) in [(0.99, 0.00715), (0.9, 0.07495), (0.8, 0.15843), (0.5, 0.48177)] {
        assert!((alpha_from_restitution(e) - a).abs() < 1e-5, "e={e}");
        assert!((restitution_from_alpha(a) - e).abs() < 1e-4);
    }
}

#[test]
fn contact_time_matches_physics_md_examples() {
    // PHYSICS.md 2.4: d = 1.2 mm, ρ = 1000, ν = 0.33, v0 = 1 m/s: E = 10 MPa -> 84 µs, 100 MPa -> 33 µs.
    let mut c = Case::parse_str(paper_case_json()).unwrap().0;
    c.particles.youngs_modulus_pa = 1e7;
    assert!((c.hertz_contact_time_s(1.0) - 84e-6).abs() < 1.5e-6);
    c.particles.youngs_modulus_pa = 1e8;
    assert!((c.hertz_contact_time_s(1.0) - 33e-6).abs() < 1e-6);
}

#[test]
fn every_problem_is_reported_with_its_path() {
    let bad = r#"{"column":{"diameter_m":-1,"height_m":0.1},
        "particles":{"poisson_ratio":0.7,"sliding_friction":-0.2},
        "bed":{"generated":{"settled_height_m":0.03,"count":10}},
        "dem":{"time_step_s":1e-3}}"#;
    let rep = Case::parse_str(bad).unwrap_err();
    let paths: Vec<&str> = rep.errors.iter().map(|p| p.path.as_str()).collect();
    for want in [
        "/column/diameter_m",
        "/particles/poisson_ratio",
        "/particles/sliding_friction",
        "/bed/generated",
        "/dem/time_step_s",
    ] {
        assert!(paths.contains(&want), "{want} missing from {paths:?}");
    }
    let dt = rep.errors.iter().find(|p| p.path == "/dem/time_step_s").unwrap();
    assert!(dt.allowed.contains("t_c/10"), "{}", dt.allowed);
}

#[test]
fn missing_sections_and_wrong_types_are_named() {
    let rep = Case::parse_str(r#"{"particles":{"diameter_m":"big"},"dem":{"frozen":1}}"#).unwrap_err();
    let paths: Vec<&str> = rep.errors.iter().map(|p| p.path.as_str()).collect();
    assert!(paths.contains(&"/column"));
    assert!(paths.contains(&"/bed"));
    assert!(paths.contains(&"/particles/diameter_m"), "{paths:?}");
    assert!(paths.contains(&"/dem/frozen"), "{paths:?}");
}

#[test]
fn unknown_fields_are_refused() {
    let rep = Case::parse_str(r#"{"column":{"diameter_mm":44},"particles":{},"bed":{"generated":{}}}"#).unwrap_err();
    assert!(rep.errors.iter().any(|p| p.path.starts_with("/column")), "{:?}", rep.errors);
}

#[test]
fn dt_between_tc_20_and_tc_10_warns() {
    let mut c = Case::parse_str(paper_case_json()).unwrap().0;
    let tc = c.hertz_contact_time_s(1.0);
    c.dem.time_step_s = tc / 15.0;
    let rep = c.validate();
    assert!(rep.is_ok());
    assert!(rep.warnings.iter().any(|w| w.path == "/dem/time_step_s"));
}

#[test]
fn bed_larger_than_column_and_particle_larger_than_cell_are_refused() {
    let mut c = Case::parse_str(paper_case_json()).unwrap().0;
    c.bed = Bed::Generated(GeneratedBed { settled_height_m: None, count: Some(5_000_000), seed: 1 });
    c.gas = Some(Gas::default());
    c.grid.dr_m = 0.0011;
    let rep = c.validate();
    assert!(rep.errors.iter().any(|p| p.path == "/bed/generated/count"));
    assert!(rep.errors.iter().any(|p| p.path == "/particles/diameter_m"), "{:?}", rep.errors);
}

#[test]
fn schema_is_published() {
    let s = Case::json_schema();
    assert!(s.to_string().contains("diameter_m"));
}

#[test]
fn published_schema_is_current() {
    // docs/case.schema.json is generated from these types; regenerate with
    // FLUIDBED_WRITE_SCHEMA=1 cargo test -p fluidbed-core published_schema_is_current
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/case.schema.json");
    let want = serde_json::to_string_pretty(&Case::json_schema()).unwrap() + "\n";
    if std::env::var_os("FLUIDBED_WRITE_SCHEMA").is_some() {
        std::fs::write(path, &want).unwrap();
    }
    let have = std::fs::read_to_string(path).unwrap_or_default();
    assert!(have == want, "docs/case.schema.json is stale: regenerate it (see this test's comment)");
}

#[test]
fn every_shipped_case_parses_without_errors() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../cases");
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).expect("cases/") {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "json") {
            let text = std::fs::read_to_string(&path).unwrap();
            match Case::parse_str(&text) {
                Ok((_, rep)) => assert!(rep.errors.is_empty(), "{}: {:?}", path.display(), rep.errors),
                Err(rep) => panic!("{}: {:?}", path.display(), rep.errors),
            }
            seen += 1;
        }
    }
    assert!(seen >= 9, "found {seen} cases");
}

#[test]
fn a_stored_case_without_the_pressure_force_means_held_and_a_new_one_the_mean() {
    // A case a user submits without the key takes today's default.
    let (fresh, _) = Case::parse_str(paper_case_json()).expect("valid");
    assert_eq!(fresh.coupling.pressure_force, PressureForce::IntervalMean);
    assert_eq!(fresh.coupling.interval_steps, 80);
    assert_eq!(fresh.coupling.gas_drag, crate::case::GasDrag::Implicit);
    // Stored cases always carry it now, and read back as written.
    let text = serde_json::to_string(&fresh).unwrap();
    assert!(text.contains(r#""pressure_force":"interval_mean""#), "{text}");
    assert_eq!(Case::from_stored_json(&text).unwrap(), fresh);
    // A case stored before (the key left out when it was "held", the default then) reads as held,
    // with or without a coupling section.
    let mut old: serde_json::Value = serde_json::from_str(&text).unwrap();
    old["coupling"].as_object_mut().unwrap().remove("pressure_force");
    old["coupling"].as_object_mut().unwrap().remove("gas_drag");
    let held = Case::from_stored_json(&old.to_string()).unwrap();
    assert_eq!(held.coupling.pressure_force, PressureForce::Held);
    assert_eq!(held.coupling.gas_drag, crate::case::GasDrag::Held);
    assert_eq!(held.coupling.interval_steps, 80, "the other keys as stored");
    old.as_object_mut().unwrap().remove("coupling");
    assert_eq!(Case::from_stored_json(&old.to_string()).unwrap().coupling.pressure_force, PressureForce::Held);
}

#[test]
fn a_drag_held_longer_than_tested_warns_and_the_default_does_not() {
    use crate::case::{GasDrag, GasVoidage};
    let gas = |n: u32| {
        let mut c = Case::parse_str(paper_case_json()).expect("valid").0;
        c.gas = Some(Default::default());
        c.coupling.interval_steps = n;
        c
    };
    let warned = |c: &Case| c.validate().warnings.iter().any(|w| w.path == "/coupling/interval_steps");
    // The default: 80 steps of 1.25 µs, 100 µs between couplings, the gas's voidage interpolated
    // and its drag implicit.
    assert!(!warned(&gas(d_coupling_interval())));
    let rep = gas(90).validate();
    assert!(rep.is_ok(), "a warning only: {:?}", rep.errors);
    let w = rep.warnings.iter().find(|w| w.path == "/coupling/interval_steps").expect("warned");
    assert!(w.allowed.contains("<= 80"), "{}", w.allowed);
    // The gas's voidage held: 25 µs; the drag on the gas held: 50 µs.
    let mut held_voidage = gas(30);
    held_voidage.coupling.gas_voidage = GasVoidage::Held;
    let w =
        held_voidage.validate().warnings.into_iter().find(|w| w.path == "/coupling/interval_steps").expect("warned");
    assert!(w.allowed.contains("<= 20") && w.message.contains("voidage"), "{w:?}");
    let mut held_drag = gas(50);
    held_drag.coupling.gas_drag = GasDrag::Held;
    let w = held_drag.validate().warnings.into_iter().find(|w| w.path == "/coupling/interval_steps").expect("warned");
    assert!(w.allowed.contains("<= 40") && w.message.contains("drag"), "{w:?}");
    // A finer DEM step holds the drag for less time at the same count.
    let mut fine = gas(90);
    fine.dem.time_step_s = 0.625e-6;
    assert!(!warned(&fine));
    // No gas, or a frozen bed, holds no drag on moving particles.
    let mut frozen = gas(90);
    frozen.dem.frozen = true;
    assert!(!warned(&frozen));
}

#[test]
fn an_inlet_jet_outside_the_grid_or_its_window_or_the_mach_limit_is_named() {
    let mut c = Case::parse_str(paper_case_json()).unwrap().0;
    let jet =
        |annuli, u, from, until| Some(InletJet { annuli, superficial_velocity_m_s: u, from_s: from, until_s: until });
    c.gas = Some(Gas { inlet_jet: jet(1, 3.0, 0.1, Some(0.2)), ..Gas::default() });
    assert!(c.validate().is_ok(), "{:?}", c.validate().errors);
    // 0.022-m radius in annuli of 4.4 mm: 5 annuli.
    c.gas = Some(Gas { inlet_jet: jet(6, 3.0, 0.2, Some(0.1)), ..Gas::default() });
    let rep = c.validate();
    let paths: Vec<&str> = rep.errors.iter().map(|p| p.path.as_str()).collect();
    assert!(paths.contains(&"/gas/inlet_jet/annuli"), "{paths:?}");
    assert!(paths.contains(&"/gas/inlet_jet/until_s"), "{paths:?}");
    let annuli = rep.errors.iter().find(|p| p.path == "/gas/inlet_jet/annuli").unwrap();
    assert!(annuli.allowed.contains("[1, 5]"), "{}", annuli.allowed);
    c.gas = Some(Gas { inlet_jet: jet(1, 90.0, 0.0, None), ..Gas::default() });
    let rep = c.validate();
    assert!(rep.errors.iter().any(|p| p.path == "/gas/inlet_jet/superficial_velocity_m_s"), "{:?}", rep.errors);
}
