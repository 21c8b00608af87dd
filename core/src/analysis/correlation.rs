//! Cross-correlation of two signals and the rise velocity of bubbles or slugs it gives (Müller et
//! al. 2007a; PHYSICS.md §12): with x₁(t) at height z₁ and x₂(t) at z₂ > z₁ (cross-section mean
//! voidage, or pressure), τ* = argmax over positive lags of R₁₂(τ), refined by a parabola through
//! the peak and its neighbours, and u = (z₂ − z₁)/τ*. The peak's height is a quality figure: a
//! low peak means no coherent structures travel between the heights.

use super::spectrum::parabola_vertex;
use serde::{Deserialize, Serialize};

/// Normalised cross-correlation R(τ) for τ = 0 … `max_lag` samples, x₂ lagging x₁: Pearson's
/// coefficient of the overlapping pairs (x₁[n], x₂[n + τ]), n < N − τ, each lag with the means
/// and spreads of its own overlap, so R = 1 at the delay of an exact delayed copy and the peak is
/// not pulled toward τ = 0 by a shrinking overlap. Lags whose overlap has fewer than 2 pairs or
/// no spread give 0. Cost O(N · max_lag).
pub fn cross_correlation(x1: &[f64], x2: &[f64], max_lag: usize) -> Vec<f64> {
    let n = x1.len().min(x2.len());
    (0..=max_lag)
        .map(|lag| {
            if lag + 2 > n {
                return 0.0;
            }
            let m = n - lag;
            let (a, b) = (&x1[..m], &x2[lag..lag + m]);
            let (ma, mb) = (a.iter().sum::<f64>() / m as f64, b.iter().sum::<f64>() / m as f64);
            let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
            for (u, v) in a.iter().zip(b) {
                let (du, dv) = (u - ma, v - mb);
                sab += du * dv;
                saa += du * du;
                sbb += dv * dv;
            }
            if saa > 0.0 && sbb > 0.0 {
                sab / (saa * sbb).sqrt()
            } else {
                0.0
            }
        })
        .collect()
}

/// A rise velocity from the delay of the correlation peak between two heights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RiseVelocity {
    pub velocity_m_s: f64,
    /// τ*, the interpolated lag of the peak.
    pub delay_s: f64,
    /// R at the parabola's vertex (≤ 1): the quality figure.
    pub peak: f64,
    /// R(τ) at τ = 0, dt, 2dt, … (for plotting the correlation).
    pub correlation: Vec<f64>,
    pub dt_s: f64,
}

/// Rise velocity between signals `lower` (at z₁) and `upper` (at z₁ + `dz_m`) sampled every
/// `dt` seconds, searching delays up to `max_delay_s`. `None` when the correlation has no peak
/// strictly inside (0, max_delay]: its largest value at lag 0 side of a falling curve, or at the
/// search's end (lengthen the search or the record).
pub fn rise_velocity(lower: &[f64], upper: &[f64], dt: f64, dz_m: f64, max_delay_s: f64) -> Option<RiseVelocity> {
    let max_lag = (max_delay_s / dt).floor() as usize;
    if max_lag < 2 || dt <= 0.0 {
        return None;
    }
    let r = cross_correlation(lower, upper, max_lag);
    let (k, &rk) = r.iter().enumerate().skip(1).max_by(|a, b| a.1.total_cmp(b.1))?;
    if k + 1 >= r.len() || r[k - 1] > rk || rk <= 0.0 {
        return None;
    }
    let (a, c) = (r[k - 1], r[k + 1]);
    let delta = parabola_vertex(a, rk, c);
    // Vertex height of the parabola: b − (a − c) δ / 4.
    let peak = (rk - 0.25 * (a - c) * delta).min(1.0);
    let delay_s = (k as f64 + delta) * dt;
    Some(RiseVelocity { velocity_m_s: dz_m / delay_s, delay_s, peak, correlation: r, dt_s: dt })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::test_signals::Noise;

    /// A train of Gaussian bubbles of width w at random times t_b, seen at a height where they
    /// arrive `delay` later: ε(t) = 0.4 + 0.5 Σ exp(−(t − t_b − delay)²/(2w²)).
    fn bubbles(times: &[f64], n: usize, dt: f64, delay: f64, w: f64) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let t = i as f64 * dt;
                0.4 + 0.5 * times.iter().map(|tb| (-(t - tb - delay).powi(2) / (2.0 * w * w)).exp()).sum::<f64>()
            })
            .collect()
    }

    #[test]
    fn an_exact_copy_delayed_by_whole_samples_correlates_fully_at_that_lag() {
        let mut noise = Noise::new(11);
        let x: Vec<f64> = (0..3000).map(|_| noise.gauss()).collect();
        let y: Vec<f64> = std::iter::repeat_n(0.0, 17).chain(x.iter().copied()).collect();
        let r = cross_correlation(&x, &y, 40);
        assert!((r[17] - 1.0).abs() < 1e-12, "{}", r[17]);
        assert!(r.iter().enumerate().all(|(k, v)| k == 17 || v.abs() < 0.1));
    }

    #[test]
    fn the_rise_velocity_is_dz_over_a_fractional_delay() {
        // Bubbles every ~0.2–0.5 s, width 25 ms, from z₁ to z₁ + 30 mm at 0.35 m/s: τ = 85.714 ms,
        // 42.857 samples of 2 ms. Independent noise at each height.
        let (dt, n, dz, u) = (0.002, 15_000, 0.03, 0.35);
        let mut noise = Noise::new(5);
        let mut times = vec![];
        let mut t = 0.1;
        while t < n as f64 * dt {
            times.push(t);
            t += 0.2 + 0.3 * noise.uniform();
        }
        let (lower, upper) = (bubbles(&times, n, dt, 0.0, 0.025), bubbles(&times, n, dt, dz / u, 0.025));
        // Clean: only the parabola's bias on a peak 18 samples wide, far below a sample.
        let rv = rise_velocity(&lower, &upper, dt, dz, 0.5).unwrap();
        assert!((rv.delay_s - dz / u).abs() < 0.02 * dt, "{} vs {}", rv.delay_s, dz / u);
        assert!((rv.peak - 1.0).abs() < 1e-3, "{}", rv.peak);
        // Noisy (σ = 0.02 against pulses of 0.5): the noise tilts the peak by a tenth of a
        // sample or so, 0.1% of the delay.
        let noisy =
            |v: Vec<f64>, noise: &mut Noise| v.into_iter().map(|e| e + 0.02 * noise.gauss()).collect::<Vec<_>>();
        let rv = rise_velocity(&noisy(lower, &mut noise), &noisy(upper, &mut noise), dt, dz, 0.5).unwrap();
        assert!((rv.delay_s - dz / u).abs() < 0.25 * dt, "{} vs {}", rv.delay_s, dz / u);
        assert!((rv.velocity_m_s / u - 1.0).abs() < 0.005, "{}", rv.velocity_m_s);
        assert!(rv.peak > 0.9 && rv.peak <= 1.0, "{}", rv.peak);
    }

    #[test]
    fn uncorrelated_or_undelayed_signals_have_no_rise_velocity() {
        // The peak at lag 0 (a same-time signal, as pressure is) gives no positive delay.
        let mut noise = Noise::new(2);
        let x: Vec<f64> = bubbles(&[0.3, 0.9, 1.4, 2.2], 1500, 0.002, 0.0, 0.02);
        assert!(rise_velocity(&x, &x, 0.002, 0.03, 0.3).is_none());
        let a: Vec<f64> = (0..1500).map(|_| noise.gauss()).collect();
        let b: Vec<f64> = (0..1500).map(|_| noise.gauss()).collect();
        if let Some(rv) = rise_velocity(&a, &b, 0.002, 0.03, 0.3) {
            assert!(rv.peak < 0.15, "{}", rv.peak);
        }
    }
}
