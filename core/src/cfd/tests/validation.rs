//! `validate_gas`: a gas step beyond the stable limit is refused, with the limit in the message.

use super::support::case_with;
use crate::case::Gas;
use crate::cfd::{case_stable_time_step, GasSolver, AB3_IMAGINARY_LIMIT, FACE_FLUX_RATE};
use crate::grid::CylGrid;

#[test]
fn too_large_a_gas_step_is_refused_with_the_limit() {
    let mut case = case_with(Gas::default(), 9.81, 0.022, 0.12);
    case.grid.dz_m = Some(0.0044444444444444444);
    let limit = case_stable_time_step(&case).unwrap();
    // Acoustic bound: AB3's 0.7236 over a'·((1 + n0/π)/dr + 1/dz), a' = a/√(1 − s₀) with the face
    // correction's rate s₀ (stability.rs), times the CFL factor 0.9.
    let a_eff = 290.1 / (1.0 - FACE_FLUX_RATE).sqrt();
    let acoustic =
        0.9 * AB3_IMAGINARY_LIMIT / (a_eff * ((1.0 + 3.0 / std::f64::consts::PI) / 0.0044 + 1.0 / 0.0044444));
    assert!(limit < acoustic && limit > 0.95 * acoustic, "limit {limit:e} vs acoustic {acoustic:e}");
    let dem = case.dem.time_step_s;
    let n_ok = (limit / dem).floor();
    case.gas.as_mut().unwrap().time_step_s = Some(n_ok * dem);
    assert!(case.validate().is_ok(), "{:?}", case.validate().errors);
    case.gas.as_mut().unwrap().time_step_s = Some((n_ok + 1.0) * dem);
    let rep = case.validate();
    let e = rep.errors.iter().find(|p| p.path == "/gas/time_step_s").expect("refused");
    assert!(e.allowed.contains(&format!("{limit:.4e}")), "{e}");
    case.gas.as_mut().unwrap().time_step_s = Some(1.5 * dem);
    assert!(case.validate().errors.iter().any(|p| p.path == "/gas/time_step_s" && p.message.contains("whole number")));
}

#[test]
fn solver_stable_step_at_rest_is_at_least_the_case_limit() {
    // The case limit assumes the inlet speed everywhere; gas at rest allows a slightly longer step.
    let case = case_with(Gas::default(), 9.81, 0.022, 0.12);
    let s = GasSolver::new(&case, CylGrid::new(0.022, 0.12, 0.0044, case.grid_dz_m(), 3));
    let limit = case_stable_time_step(&case).unwrap();
    assert!(s.stable_dt() >= limit && s.stable_dt() < 1.01 * limit, "{} vs {limit}", s.stable_dt());
}
