//! Mean and standard deviation of a sampled signal (the bed pressure drop ΔP(t)).

use serde::{Deserialize, Serialize};

/// Summary of a signal: its sample count, mean and standard deviation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SignalStats {
    pub samples: usize,
    pub mean: f64,
    /// Population form √(Σ(x − x̄)²/N): the record's own spread, so a whole number of periods of
    /// A sin ωt gives exactly A/√2.
    pub std: f64,
}

/// Mean and standard deviation of `x` (two passes, so a large mean does not cost digits of the
/// spread). `None` for an empty slice.
pub fn signal_stats(x: &[f64]) -> Option<SignalStats> {
    if x.is_empty() {
        return None;
    }
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
    Some(SignalStats { samples: x.len(), mean, std: var.sqrt() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn a_sine_over_whole_periods_has_its_offset_as_mean_and_amplitude_over_root_two_as_std() {
        // x = P0 + A sin(2π n/m): over 7 whole periods of m samples, mean P0 and std A/√2 exactly.
        let (p0, a, m) = (1500.0, 80.0, 64);
        let x: Vec<f64> = (0..7 * m).map(|n| p0 + a * (2.0 * PI * n as f64 / m as f64).sin()).collect();
        let s = signal_stats(&x).unwrap();
        assert_eq!(s.samples, 7 * m);
        assert!((s.mean - p0).abs() < 1e-9, "{}", s.mean);
        assert!((s.std - a / 2f64.sqrt()).abs() < 1e-9, "{}", s.std);
    }

    #[test]
    fn two_levels_give_the_binary_mean_and_std() {
        // A fraction q at level b, the rest at 0: mean q b, std b √(q(1 − q)).
        let x: Vec<f64> = (0..1000).map(|n| if n % 4 == 0 { 2.0 } else { 0.0 }).collect();
        let s = signal_stats(&x).unwrap();
        assert!((s.mean - 0.5).abs() < 1e-12);
        assert!((s.std - 2.0 * (0.25f64 * 0.75).sqrt()).abs() < 1e-12);
        assert!(signal_stats(&[]).is_none());
    }
}
