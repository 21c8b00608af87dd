//! PHYSICS.md 7: Heun → AB2 → AB3 is globally third order (error ÷ 8 when h halves).

use crate::dem::integrator::integrate;

/// Linear spring x'' = −x from (1, 0): exact x(T) = cos T, v(T) = −sin T.
fn spring_error(h: f64, t_end: f64) -> f64 {
    let steps = (t_end / h).round() as usize;
    let y = integrate(|y| vec![y[1], -y[0]], &[1.0, 0.0], h, steps);
    let t = steps as f64 * h;
    ((y[0] - t.cos()).powi(2) + (y[1] + t.sin()).powi(2)).sqrt()
}

#[test]
fn ab3_is_third_order_on_a_linear_spring() {
    let e = [0.02, 0.01, 0.005].map(|h| spring_error(h, 2.0));
    for k in 0..2 {
        let ratio = e[k] / e[k + 1];
        assert!((7.0..9.0).contains(&ratio), "error ratio {ratio} (errors {e:?}); third order gives 8");
    }
}

#[test]
fn ab3_weights_sum_to_one_and_match_the_formula() {
    use crate::dem::integrator::{AB2, AB3};
    assert!((AB3.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    assert!((AB2.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    assert_eq!(AB3, [23.0 / 12.0, -16.0 / 12.0, 5.0 / 12.0]);
}

/// The past derivatives are stored in single precision (`forces::PastV3`). Free fall is the
/// case where that rounding is systematic (every step the same g and nearly the same v): Heun,
/// AB2 and AB3 are exact for a constant acceleration, so after 40,000 steps (50 ms) a particle
/// dropped with an initial speed must sit on z₀ + u t − g t²/2 and move at u − g t to the
/// history's rounding, at most 2⁻²⁴·(21/12) of the increments: 1e-7 relative.
#[test]
fn free_fall_with_single_precision_history_is_exact_to_1e_7() {
    use super::test_case;
    use crate::dem::DemSystem;
    let (g, dt, steps) = (9.81, 1.25e-6, 40_000u32);
    let case = test_case(0.02, 1.0, false, g, dt);
    let (z0, u) = (0.9, 0.37);
    let mut sys = DemSystem::new(&case, vec![[0.001, -0.002, z0]], vec![[0.05, 0.0, u]]);
    for _ in 0..steps {
        sys.step();
    }
    let t = steps as f64 * dt;
    let (z, vz) = (sys.positions()[0][2], sys.velocities()[0][2]);
    let (z_exact, v_exact) = (z0 + u * t - 0.5 * g * t * t, u - g * t);
    let drop = (z_exact - z0).abs();
    assert!((z - z_exact).abs() <= 1e-7 * drop, "z {z} against {z_exact} (drop {drop} m)");
    assert!((vz - v_exact).abs() <= 1e-7 * (g * t + u.abs()), "v_z {vz} against {v_exact}");
    let x = sys.positions()[0][0];
    assert!((x - (0.001 + 0.05 * t)).abs() <= 1e-7 * 0.05 * t, "x {x}");
}
