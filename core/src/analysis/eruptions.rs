//! Bubble eruptions at the bed surface against the bed pressure drop (paper section 3.4, Fig. 9:
//! the period of the ΔP oscillation matches the time for bubbles to erupt at the top of the bed,
//! as Müller et al. 2007b measured). An eruption is a bubble front passing a height just below the
//! surface (`count_bubbles` on the cross-section voidage there, which the caller runs). The link
//! is measured two ways:
//! - the eruption-triggered average of ΔP: A(τ) = mean over eruptions e of ΔP(t_e + τ) − ΔP̄ for
//!   |τ| ≤ W, over the eruptions whose window lies inside the record; its maximum and minimum and
//!   their lags say whether ΔP peaks or drops as bubbles break the surface, and by how much;
//! - the ratio of ΔP's dominant frequency to the eruption rate (1 when every eruption makes one
//!   ΔP cycle, ½ when the ΔP period spans a pair of eruptions, the paper's case).

use serde::{Deserialize, Serialize};

/// ΔP around the eruptions: the eruption-triggered average and its extremes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EruptionLink {
    /// Eruptions whose window [t_e − W, t_e + W] lies inside the record (those averaged).
    pub averaged: usize,
    /// The lags τ = −W … W (step dt) and the triggered average A(τ) (Pa) at each.
    pub lag_s: Vec<f64>,
    pub triggered_dp_pa: Vec<f64>,
    /// Lags of A's maximum and minimum (s, + after the eruption) and max A − min A (Pa).
    pub lag_of_max_s: f64,
    pub lag_of_min_s: f64,
    pub swing_pa: f64,
}

/// The eruption-triggered average of the ΔP record `dp` (sampled every `dt`) over the eruptions
/// at `eruptions_s` (from the record's start, e.g. `count_bubbles(..).fronts_s` of the voidage
/// just below the surface), each rounded to its nearest sample, with half-width `half_window_s`.
/// `None` when no eruption's window fits in the record.
pub fn eruption_link(dp: &[f64], eruptions_s: &[f64], dt: f64, half_window_s: f64) -> Option<EruptionLink> {
    let n = dp.len();
    if n < 2 || dt <= 0.0 {
        return None;
    }
    // A window wider than the record fits no eruption (and must not size the sums).
    let w = (half_window_s / dt).round().clamp(0.0, n as f64) as isize;
    let mean = dp.iter().sum::<f64>() / n as f64;
    let mut sum = vec![0.0; (2 * w + 1) as usize];
    let mut averaged = 0usize;
    for &t in eruptions_s {
        let c = (t / dt).round() as isize;
        if c - w < 0 || c + w >= n as isize {
            continue;
        }
        for (j, s) in sum.iter_mut().enumerate() {
            *s += dp[(c - w + j as isize) as usize] - mean;
        }
        averaged += 1;
    }
    if averaged == 0 {
        return None;
    }
    let triggered: Vec<f64> = sum.iter().map(|s| s / averaged as f64).collect();
    let lag_s: Vec<f64> = (-w..=w).map(|j| j as f64 * dt).collect();
    let arg = |better: fn(f64, f64) -> bool| {
        (0..triggered.len()).fold(0, |b, j| if better(triggered[j], triggered[b]) { j } else { b })
    };
    let (hi, lo) = (arg(|a, b| a > b), arg(|a, b| a < b));
    Some(EruptionLink {
        averaged,
        lag_of_max_s: lag_s[hi],
        lag_of_min_s: lag_s[lo],
        swing_pa: triggered[hi] - triggered[lo],
        lag_s,
        triggered_dp_pa: triggered,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::bubble_count::count_bubbles;
    use crate::analysis::test_signals::Noise;

    /// Eruptions at irregular known times (mean 0.2 s apart); the surface voidage jumps from 0.45
    /// to 0.9 for 40 ms at each; ΔP = 150 Pa + a Gaussian bump of 12 Pa, σ = 15 ms, 30 ms after each
    /// eruption, minus 8 Pa in the 20 ms before it; noise σ = 1 Pa. The triggered average then
    /// peaks at +30 ms and dips in the 20 ms before, and its swing is 12 + 8 Pa (the record's
    /// mean, which the average subtracts, does not change it).
    #[test]
    fn a_bump_after_each_eruption_is_found_at_its_lag_and_height() {
        let (dt, secs) = (0.001, 20.0);
        let n = (secs / dt) as usize;
        let mut noise = Noise::new(4);
        let mut times = Vec::new();
        let mut t = 0.3;
        while t < secs - 0.3 {
            times.push(t);
            t += 0.15 + 0.1 * noise.uniform();
        }
        let (lag, sigma, bump, dip) = (0.030, 0.015, 12.0, 8.0);
        let mut dp = vec![150.0; n];
        let mut surface = vec![0.45; n];
        for &te in &times {
            for (i, (p, e)) in dp.iter_mut().zip(surface.iter_mut()).enumerate() {
                let s = i as f64 * dt - te;
                *p += bump * (-0.5 * ((s - lag) / sigma).powi(2)).exp();
                if (-0.02..0.0).contains(&s) {
                    *p -= dip;
                }
                if (0.0..0.04).contains(&s) {
                    *e = 0.9;
                }
            }
        }
        for p in dp.iter_mut() {
            *p += noise.gauss();
        }
        let fronts = count_bubbles(&surface, dt, 0.7, 0.5);
        let l = eruption_link(&dp, &fronts.fronts_s, dt, 0.1).expect("eruptions");
        assert_eq!(fronts.bubbles, times.len());
        for (a, b) in fronts.fronts_s.iter().zip(&times) {
            assert!((a - b).abs() <= dt, "eruption at {a} s, made at {b} s");
        }
        assert!((fronts.per_second - times.len() as f64 / secs).abs() < 1e-9);
        assert!((l.lag_of_max_s - lag).abs() <= 2.0 * dt, "peak at {} s", l.lag_of_max_s);
        assert!((-0.02..0.0).contains(&l.lag_of_min_s), "dip at {} s", l.lag_of_min_s);
        // Within ±0.1 s of an eruption only its own bump and dip (the next is ≥ 0.15 s away).
        let want = bump + dip;
        assert!((l.swing_pa / want - 1.0).abs() < 0.03, "swing {} Pa vs {want} Pa", l.swing_pa);
        assert_eq!(l.lag_s.len(), 201);
        assert!(l.averaged + 2 >= fronts.bubbles);
    }

    #[test]
    fn a_record_without_eruptions_gives_none() {
        let dp = vec![100.0; 500];
        let eps = vec![0.45; 500];
        let fronts = count_bubbles(&eps, 0.001, 0.7, 0.5);
        assert!(eruption_link(&dp, &fronts.fronts_s, 0.001, 0.05).is_none());
        // A window of one over a zero rate (infinite) or wider than the record fits no eruption.
        assert!(eruption_link(&dp, &[0.25], 0.001, f64::INFINITY).is_none());
        assert!(eruption_link(&dp, &[0.25], 0.001, 1.0).is_none());
    }
}
