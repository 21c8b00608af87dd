//! Third-order Adams–Bashforth with a second-order start (PHYSICS.md 7; paper section 2.1):
//! step 1 Heun (two derivative evaluations), step 2 AB2, then AB3, so the global order is 3.

/// Constant-step AB3 weights: y_{n+1} = y_n + h(23 f_n − 16 f_{n−1} + 5 f_{n−2})/12.
pub const AB3: [f64; 3] = [23.0 / 12.0, -16.0 / 12.0, 5.0 / 12.0];
/// AB2 weights: y_{n+1} = y_n + h(3 f_n − f_{n−1})/2.
pub const AB2: [f64; 3] = [1.5, -0.5, 0.0];

/// Weights for a multistep update when `levels` derivative values are available (2 → AB2, ≥3 → AB3).
#[inline(always)]
pub fn weights(levels: u8) -> [f64; 3] {
    if levels >= 3 {
        AB3
    } else {
        AB2
    }
}

/// Integrate y' = f(y) over `steps` steps of size h with the same scheme the DEM uses
/// (Heun, AB2, then AB3). Used to check the order of the method on its own.
#[cfg(test)]
pub fn integrate<F: FnMut(&[f64]) -> Vec<f64>>(mut f: F, y0: &[f64], h: f64, steps: usize) -> Vec<f64> {
    let mut y = y0.to_vec();
    let mut hist: Vec<Vec<f64>> = Vec::new(); // f_{n-1}, f_{n-2}
    for s in 0..steps {
        let f0 = f(&y);
        if s == 0 {
            // Heun: predictor Euler, corrector trapezoid.
            let pred: Vec<f64> = y.iter().zip(&f0).map(|(a, b)| a + h * b).collect();
            let fp = f(&pred);
            for k in 0..y.len() {
                y[k] += 0.5 * h * (f0[k] + fp[k]);
            }
        } else {
            let w = weights(if s == 1 { 2 } else { 3 });
            for k in 0..y.len() {
                let f1 = hist[0][k];
                let f2 = if s >= 2 { hist[1][k] } else { 0.0 };
                y[k] += h * (w[0] * f0[k] + w[1] * f1 + w[2] * f2);
            }
        }
        hist.insert(0, f0);
        hist.truncate(2);
    }
    y
}
