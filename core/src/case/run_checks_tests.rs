//! Tests of the run checks (run_checks.rs): each check refuses or warns with its JSON path.

use super::*;

fn case(json: &str) -> Case {
    serde_json::from_str(json).expect("case parses")
}

fn gas_case() -> Case {
    case(r#"{"column":{"diameter_m":0.044,"height_m":0.12},"particles":{},"bed":{"generated":{"count":100}},"gas":{}}"#)
}

fn paths(ps: &[Problem]) -> Vec<&str> {
    ps.iter().map(|p| p.path.as_str()).collect()
}

#[test]
fn the_dem_step_is_checked_at_the_largest_impact_speed() {
    // t_c/12 at 1 m/s passes; the same step with particles thrown at 20 m/s (t_c × 20^-0.2 = 0.55 t_c) does not.
    let mut c = case(
        r#"{"column":{"diameter_m":0.044,"height_m":0.12},"particles":{},
            "bed":{"explicit":{"positions_m":[[0,0,0.01],[0.005,0,0.01]],"velocities_m_s":[[0,0,0],[0,0,0]]}}}"#,
    );
    c.dem.time_step_s = c.hertz_contact_time_s(1.0) / 12.0;
    assert!(c.largest_impact_speed_m_s() > 1.5 && c.largest_impact_speed_m_s() < 1.6, "√(2gH)");
    assert!(c.validate().is_ok(), "{:?}", c.validate().errors);
    if let Bed::Explicit(e) = &mut c.bed {
        e.velocities_m_s = Some(vec![[20.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
    }
    assert_eq!(c.largest_impact_speed_m_s(), 20.0);
    let rep = c.validate();
    let e = rep.errors.iter().find(|p| p.path == "/dem/time_step_s").expect("refused");
    assert!(e.allowed.contains("20.00 m/s"), "{}", e.allowed);
}

#[test]
fn terminal_velocity_is_schiller_naumanns_and_a_faster_inlet_warns() {
    // PHYSICS.md: d = 1.2 mm, ρ_p = 1000 kg/m³, air at 293 K: u_t = 4.52 m/s.
    let mut c = gas_case();
    let ut = c.terminal_velocity_m_s().unwrap();
    assert!((ut - 4.52).abs() < 0.03, "u_t = {ut}");
    assert!(!c.validate().warnings.iter().any(|w| w.path == "/gas/superficial_velocity_m_s"));
    c.gas.as_mut().unwrap().superficial_velocity_m_s = 6.0;
    let rep = c.validate();
    assert!(rep.is_ok(), "a warning only: {:?}", rep.errors);
    let w = rep.warnings.iter().find(|w| w.path == "/gas/superficial_velocity_m_s").expect("warned");
    assert!(w.message.contains("blown out"), "{}", w.message);
}

#[test]
fn an_inlet_beyond_mach_0_3_is_refused() {
    let mut c = gas_case();
    // a = 290 m/s, ε_inlet = 0.4: at most 0.3·290·0.4 = 34.8 m/s.
    c.gas.as_mut().unwrap().superficial_velocity_m_s = 30.0;
    assert!(!c.validate().errors.iter().any(|p| p.path == "/gas/superficial_velocity_m_s"));
    c.gas.as_mut().unwrap().superficial_velocity_m_s = 40.0;
    let rep = c.validate();
    let e = rep.errors.iter().find(|p| p.path == "/gas/superficial_velocity_m_s").expect("refused");
    assert!(e.message.contains("Mach"), "{}", e.message);
}

#[test]
fn overlapping_explicit_particles_are_refused_and_touching_ones_warned() {
    let bed = |gap: f64| {
        case(&format!(
            r#"{{"column":{{"diameter_m":0.044,"height_m":0.12}},"particles":{{}},
                "bed":{{"explicit":{{"positions_m":[[0,0,0.01],[0.01,0,0.01],[{},0,0.01]]}}}}}}"#,
            0.01 + gap
        ))
    };
    let rep = bed(0.0006).validate();
    assert_eq!(paths(&rep.errors), ["/bed/explicit/positions_m/2"], "{:?}", rep.errors);
    assert!(rep.errors[0].message.contains("particles 1 and 2 overlap by 50.0%"), "{}", rep.errors[0].message);
    let rep = bed(0.00117).validate();
    assert!(rep.is_ok(), "{:?}", rep.errors);
    assert_eq!(paths(&rep.warnings), ["/bed/explicit/positions_m/2"]);
    assert!(bed(0.0012).validate().warnings.is_empty());
}

#[test]
fn cells_narrower_than_a_particle_along_theta_are_refused() {
    // dr = 4.4 mm: cells are π·dr/n0 wide, 1.15 mm for n0 = 12 < d = 1.2 mm.
    let mut c = gas_case();
    c.grid.n0 = 11;
    assert!(!c.validate().errors.iter().any(|p| p.path == "/grid/n0"));
    c.grid.n0 = 12;
    let rep = c.validate();
    let e = rep.errors.iter().find(|p| p.path == "/grid/n0").expect("refused");
    assert!(e.allowed.contains("11.52"), "{}", e.allowed);
}

#[test]
fn a_run_of_more_than_1e12_steps_is_refused() {
    let mut c = gas_case();
    c.dem.time_step_s = 1e-9;
    c.end_time_s = 1e4;
    assert!(paths(&c.validate().errors).contains(&"/end_time_s"));
    c.end_time_s = 100.0;
    assert!(!paths(&c.validate().errors).contains(&"/end_time_s"));
}

#[test]
fn soft_particles_at_the_largest_impact_speed_warn_of_a_deep_overlap() {
    // d = 1.2 mm, ρ = 1000, E = 1.2e8 Pa: 0.88% of d at 1 m/s (1.2% at √(2gH) = 1.53 m/s); E = 1e5 Pa: 21%.
    let mut c = gas_case();
    let f = c.impact_overlap_fraction(1.0);
    assert!(f > 0.0087 && f < 0.0089, "{f}");
    assert!(!c.validate().warnings.iter().any(|w| w.path == "/particles/youngs_modulus_pa"));
    c.particles.youngs_modulus_pa = 1e5;
    let rep = c.validate();
    let w = rep.warnings.iter().find(|w| w.path == "/particles/youngs_modulus_pa").expect("warned");
    assert!(w.message.contains("watchdog"), "{}", w.message);
    // the E it asks for keeps the overlap at 10%
    let e: f64 = w.allowed.split_whitespace().nth(1).unwrap().parse().unwrap();
    c.particles.youngs_modulus_pa = e;
    assert!((c.impact_overlap_fraction(c.largest_impact_speed_m_s()) - 0.1).abs() < 1e-3);
}

#[test]
fn an_explicit_bed_far_outside_the_column_is_refused_without_overflow() {
    // Coordinates of ±1e300 m: the overlap check must not overflow its i64 cell keys.
    let c = case(
        r#"{"column":{"diameter_m":0.044,"height_m":0.12},"particles":{},
            "bed":{"explicit":{"positions_m":[[1e300,0,0.01],[1e300,0,0.01],[-1e300,1e300,1e300]]}}}"#,
    );
    let rep = c.validate();
    assert!(paths(&rep.errors).iter().any(|p| p.starts_with("/bed/explicit/positions_m")), "{:?}", rep.errors);
}
