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
