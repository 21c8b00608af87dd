//! Variable-step Adams–Bashforth coefficients (PHYSICS.md 7) and the stability constants.
//! Start-up: Heun (2nd-order one-step, keeps the global error 3rd order), then AB2, then AB3.

/// AB3 stability limit on the imaginary axis, |λh| ≤ 0.7236 (PHYSICS.md 7).
pub const AB3_IMAGINARY_LIMIT: f64 = 0.7236;
/// AB3 stability limit on the negative real axis, λh ≥ −6/11 (PHYSICS.md 7).
pub const AB3_REAL_LIMIT: f64 = 6.0 / 11.0;

/// Weights (b0, b1, b2) of f_n, f_{n−1}, f_{n−2} for y_{n+1} = y_n + h Σ b_i f_{n−i}, with
/// h = t_{n+1} − t_n, h1 = t_n − t_{n−1}, h2 = t_{n−1} − t_{n−2} (PHYSICS.md 7, sympy-derived).
pub fn ab3_weights(h: f64, h1: f64, h2: f64) -> [f64; 3] {
    let b0 = (2.0 * h * h + 6.0 * h * h1 + 3.0 * h * h2 + 6.0 * h1 * h1 + 6.0 * h1 * h2) / (6.0 * h1 * (h1 + h2));
    let b1 = -h * (2.0 * h + 3.0 * h1 + 3.0 * h2) / (6.0 * h1 * h2);
    let b2 = h * (2.0 * h + 3.0 * h1) / (6.0 * h2 * (h1 + h2));
    [b0, b1, b2]
}

/// Variable-step AB2 weights (b0, b1): b0 = (h + 2h1)/(2h1), b1 = −h/(2h1) (PHYSICS.md 7).
pub fn ab2_weights(h: f64, h1: f64) -> [f64; 2] {
    [(h + 2.0 * h1) / (2.0 * h1), -h / (2.0 * h1)]
}

/// y = y0 + Σ w_i f_i (the weights include the step) over one, two or three right-hand sides.
pub fn combine(y: &mut [f64], y0: &[f64], f: &[&[f64]], w: &[f64]) {
    match *f {
        [a] => y.iter_mut().zip(y0).zip(a).for_each(|((y, y0), a)| *y = y0 + w[0] * a),
        [a, b] => y.iter_mut().zip(y0).zip(a.iter().zip(b)).for_each(|((y, y0), (a, b))| *y = y0 + w[0] * a + w[1] * b),
        [a, b, c] => y
            .iter_mut()
            .zip(y0)
            .zip(a.iter().zip(b.iter().zip(c)))
            .for_each(|((y, y0), (a, (b, c)))| *y = y0 + w[0] * a + w[1] * b + w[2] * c),
        _ => unreachable!("one to three right-hand sides"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integrate y' = λy from y(0) = 1 to t_end with Heun → AB2 → AB3, alternating step sizes
    /// h and 0.8h to exercise the variable-step weights; returns |y − e^{λt}|.
    fn error(lambda: (f64, f64), n: usize) -> f64 {
        type C = (f64, f64);
        let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
        let f = |y: C| mul(lambda, y);
        let t_end = 1.0;
        let steps: Vec<f64> = (0..n).map(|i| if i % 2 == 0 { 1.0 } else { 0.8 }).collect();
        let scale = t_end / steps.iter().sum::<f64>();
        let mut y: C = (1.0, 0.0);
        let (mut hist, mut hs): (Vec<C>, Vec<f64>) = (vec![], vec![]);
        for s in steps {
            let h = s * scale;
            let f0 = f(y);
            y = match hist.len() {
                0 => {
                    let ys = (y.0 + h * f0.0, y.1 + h * f0.1);
                    let fs = f(ys);
                    (y.0 + 0.5 * h * (f0.0 + fs.0), y.1 + 0.5 * h * (f0.1 + fs.1))
                }
                1 => {
                    let b = ab2_weights(h, hs[0]);
                    (y.0 + h * (b[0] * f0.0 + b[1] * hist[0].0), y.1 + h * (b[0] * f0.1 + b[1] * hist[0].1))
                }
                _ => {
                    let b = ab3_weights(h, hs[0], hs[1]);
                    let (f1, f2) = (hist[0], hist[1]);
                    (
                        y.0 + h * (b[0] * f0.0 + b[1] * f1.0 + b[2] * f2.0),
                        y.1 + h * (b[0] * f0.1 + b[1] * f1.1 + b[2] * f2.1),
                    )
                }
            };
            hist.insert(0, f0);
            hs.insert(0, h);
        }
        let ex = (lambda.0 * t_end).exp();
        let want = (ex * (lambda.1 * t_end).cos(), ex * (lambda.1 * t_end).sin());
        ((y.0 - want.0).powi(2) + (y.1 - want.1).powi(2)).sqrt()
    }

    #[test]
    fn weights_reduce_to_the_constant_step_values() {
        let b = ab3_weights(0.1, 0.1, 0.1);
        assert!(
            (b[0] - 23.0 / 12.0).abs() < 1e-14
                && (b[1] + 16.0 / 12.0).abs() < 1e-14
                && (b[2] - 5.0 / 12.0).abs() < 1e-14
        );
        let b = ab2_weights(0.1, 0.1);
        assert!((b[0] - 1.5).abs() < 1e-15 && (b[1] + 0.5).abs() < 1e-15);
    }

    #[test]
    fn ab3_is_third_order_for_decay_and_oscillation() {
        // PHYSICS.md 7 test: halving h divides the error by 8 for y' = −y and y' = iωy.
        for lambda in [(-1.0, 0.0), (0.0, 5.0)] {
            let (e1, e2) = (error(lambda, 200), error(lambda, 400));
            let ratio = e1 / e2;
            assert!((ratio - 8.0).abs() < 0.8, "λ={lambda:?}: error ratio {ratio} ({e1:e} → {e2:e})");
        }
    }

    #[test]
    fn ab3_amplification_is_one_at_the_imaginary_axis_limit() {
        // Root of ρ(ζ) − λh σ(ζ) on |ζ| = 1 at λh = 0.7236i (PHYSICS.md 7): scan |ζ|max below and above.
        let max_root = |mu: f64| -> f64 {
            // ζ³ − ζ² − iμ(23ζ² − 16ζ + 5)/12 = 0, solved by Durand–Kerner.
            type C = (f64, f64);
            let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
            let c2: C = (-1.0, -23.0 * mu / 12.0);
            let c1: C = (0.0, 16.0 * mu / 12.0);
            let c0: C = (0.0, -5.0 * mu / 12.0);
            let p = |z: C| {
                let z2 = mul(z, z);
                let z3 = mul(z2, z);
                let a = mul(c2, z2);
                let b = mul(c1, z);
                (z3.0 + a.0 + b.0 + c0.0, z3.1 + a.1 + b.1 + c0.1)
            };
            let div = |a: C, b: C| {
                let d = b.0 * b.0 + b.1 * b.1;
                ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
            };
            let mut r: [C; 3] = [(0.4, 0.9), (-0.7, 0.3), (0.2, -0.8)];
            for _ in 0..500 {
                for i in 0..3 {
                    let mut den: C = (1.0, 0.0);
                    for j in 0..3 {
                        if i != j {
                            den = mul(den, (r[i].0 - r[j].0, r[i].1 - r[j].1));
                        }
                    }
                    let d = div(p(r[i]), den);
                    r[i] = (r[i].0 - d.0, r[i].1 - d.1);
                }
            }
            r.iter().map(|z| z.0.hypot(z.1)).fold(0.0, f64::max)
        };
        assert!(max_root(AB3_IMAGINARY_LIMIT - 0.005) <= 1.0 + 1e-9);
        assert!(max_root(AB3_IMAGINARY_LIMIT + 0.005) > 1.0);
    }
}
