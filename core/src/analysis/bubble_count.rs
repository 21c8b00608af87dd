//! Bubbles passing a height per second, from the cross-section mean voidage there: a bubble is a
//! rise through `rise` after the signal was last below `fall` (< `rise`), so noise that stays
//! within the band between the two thresholds never counts twice (hysteresis, a Schmitt trigger).

use serde::{Deserialize, Serialize};

/// Bubble fronts found in a signal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BubbleCount {
    pub bubbles: usize,
    /// The record's length N · dt.
    pub duration_s: f64,
    /// bubbles / duration.
    pub per_second: f64,
    /// Time of each front: where the signal crosses `rise`, interpolated between samples
    /// (sample i at t = i · dt).
    pub fronts_s: Vec<f64>,
}

/// Count the bubble fronts in `x` sampled every `dt`. A bubble already above `rise` at the first
/// sample is not counted (its front passed before the record). Panics unless `fall < rise`.
pub fn count_bubbles(x: &[f64], dt: f64, rise: f64, fall: f64) -> BubbleCount {
    assert!(fall < rise, "count_bubbles: fall ({fall}) must be below rise ({rise})");
    let mut armed = x.first().is_some_and(|&v| v < rise);
    let mut fronts_s = Vec::new();
    for i in 1..x.len() {
        let (prev, v) = (x[i - 1], x[i]);
        if armed && v >= rise {
            // Armed implies prev < rise, so the crossing lies in (i − 1, i]: interpolate it.
            let frac = if v > prev { ((rise - prev) / (v - prev)).clamp(0.0, 1.0) } else { 1.0 };
            fronts_s.push((i as f64 - 1.0 + frac) * dt);
            armed = false;
        } else if !armed && v < fall {
            armed = true;
        }
    }
    let duration_s = x.len() as f64 * dt;
    let per_second = if duration_s > 0.0 { fronts_s.len() as f64 / duration_s } else { 0.0 };
    BubbleCount { bubbles: fronts_s.len(), duration_s, per_second, fronts_s }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::test_signals::Noise;
    use std::f64::consts::PI;

    #[test]
    fn a_noisy_periodic_train_gives_its_frequency_and_front_times() {
        // ε = 0.45 + 0.4 max(0, sin(2π f t))^2 at f = 8 Hz over 4 s: 32 bubbles whose fronts cross
        // 0.65 where sin² = ½, at t = (n + 1/8)/f. Noise ±0.03 (σ = 0.01) against a band of 0.2.
        let (dt, f, secs) = (0.001, 8.0, 4.0);
        let n = (secs / dt) as usize;
        let mut noise = Noise::new(9);
        let x: Vec<f64> = (0..n)
            .map(|i| {
                let s = (2.0 * PI * f * i as f64 * dt).sin().max(0.0);
                0.45 + 0.4 * s * s + 0.01 * noise.gauss()
            })
            .collect();
        let c = count_bubbles(&x, dt, 0.65, 0.5);
        assert_eq!(c.bubbles, 32);
        assert!((c.per_second - f).abs() < 1e-9, "{}", c.per_second);
        for (m, t) in c.fronts_s.iter().enumerate() {
            let want = (m as f64 + 0.125) / f;
            assert!((t - want).abs() < 3.0 * dt, "front {m}: {t} vs {want}");
        }
    }

    #[test]
    fn chatter_inside_the_band_counts_once_and_a_bubble_at_the_start_not_at_all() {
        // Starts inside a bubble (not counted), then one bubble whose top chatters across `rise`.
        let x = [0.9, 0.9, 0.4, 0.45, 0.7, 0.6, 0.71, 0.62, 0.8, 0.4, 0.3];
        let c = count_bubbles(&x, 0.1, 0.65, 0.5);
        assert_eq!(c.bubbles, 1);
        // Crossing 0.65 between 0.45 (i = 3) and 0.7 (i = 4): 3 + 0.2/0.25 = 3.8 samples.
        assert!((c.fronts_s[0] - 0.38).abs() < 1e-12);
        assert!((c.duration_s - 1.1).abs() < 1e-12);
    }
}
