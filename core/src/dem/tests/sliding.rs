//! A sphere launched sliding without spin on the plate: friction μmg decelerates it at μg
//! and spins it up until it rolls at 5/7 of its initial speed (solid sphere, textbook result);
//! the Coulomb limit |F_t| ≤ μ|F_n| holds at every step.

use super::{test_case, with_damping};
use crate::dem::DemSystem;

#[test]
fn sliding_sphere_decelerates_at_mu_g_and_rolls_at_five_sevenths() {
    let (mu, g, v0) = (0.3, 9.81, 0.5);
    let case = with_damping(test_case(0.05, 0.05, false, g, 1.25e-6), 0.3, 0.3, mu);
    let r = case.particles.diameter_m / 2.0;
    let m = case.particle_mass_kg();
    let law = crate::dem::DemParams::new(&case).wall;
    let delta_eq = (m * g / law.kn).powf(2.0 / 3.0); // static Hertz overlap on the plate
    let mut sys = DemSystem::new(&case, vec![[-0.015, 0.0, r - delta_eq]], vec![[v0, 0.0, 0.0]]);
    sys.set_audit(true);
    let mut measured = 0;
    let t_slide = 2.0 * v0 / (7.0 * mu * g);
    let dt = case.dem.time_step_s;
    let at = |f: f64| (f * t_slide / dt).round() as u64;
    let (s1, s2, s_end) = (at(0.2), at(0.8), at(1.6));
    let (mut v1, mut v2) = (0.0, 0.0);
    while sys.steps() < s_end {
        sys.step();
        assert!(sys.max_coulomb_excess() <= 1e-9, "Coulomb limit broken at step {}", sys.steps());
        measured += (sys.max_coulomb_excess() > f64::NEG_INFINITY) as u64;
        if sys.steps() == s1 {
            v1 = sys.velocities()[0][0];
        }
        if sys.steps() == s2 {
            v2 = sys.velocities()[0][0];
        }
    }
    assert_eq!(measured, s_end, "the plate contact's Coulomb excess measured at every step");
    let decel = (v1 - v2) / ((s2 - s1) as f64 * dt);
    assert!((decel / (mu * g) - 1.0).abs() < 0.01, "deceleration {decel}, μg = {}", mu * g);
    let v_end = sys.velocities()[0][0];
    assert!((v_end / (5.0 / 7.0 * v0) - 1.0).abs() < 0.01, "final speed {v_end}, 5/7 v0 = {}", 5.0 / 7.0 * v0);
    let spin = sys.angular_velocities()[0][1] * r;
    assert!((spin / v_end - 1.0).abs() < 0.01, "not rolling: ωR = {spin}, v = {v_end}");
}
