//! Welch's averaged periodogram (Welch 1967) and the dominant frequency of a signal (PHYSICS.md
//! §12 "Spectrum"): Hann windows with 50% overlap, each segment's mean removed, one-sided power
//! spectral density in units² / Hz.

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A one-sided power spectral density: `psd[k]` at `freq_hz[k] = k · df_hz`, k = 0 … n/2.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spectrum {
    pub freq_hz: Vec<f64>,
    /// Units² per Hz; Σ psd · df is the signal's variance (Parseval, below).
    pub psd: Vec<f64>,
    pub df_hz: f64,
    /// Samples per segment and segments averaged.
    pub segment_len: usize,
    pub segments: usize,
}

impl Spectrum {
    /// Power in [f_lo, f_hi]: Σ psd · df over the bins inside.
    pub fn band_power(&self, f_lo: f64, f_hi: f64) -> f64 {
        self.freq_hz
            .iter()
            .zip(&self.psd)
            .filter(|(f, _)| **f >= f_lo && **f <= f_hi)
            .map(|(_, p)| p * self.df_hz)
            .sum()
    }
}

/// Welch's estimate of the spectrum of `x` sampled every `dt` seconds, with segments of
/// `segment_len` samples (even, ≥ 8) starting every `segment_len / 2`; samples after the last
/// whole segment are not used. Window: periodic Hann w_n = ½ − ½ cos(2π n / L). Each segment's
/// mean is removed (scipy's `detrend="constant"`), then
///   P_k = c_k Σ_segments |X_k|² / (K f_s Σ w_n²),  c_k = 2 except c_0 = c_{L/2} = 1,
/// so Σ_k P_k df with df = f_s / L is the mean over segments of Σ (w x)² / Σ w²: the variance
/// for a stationary signal. A tone A sin(2π f t) on a bin gives Σ P df = A²/2 exactly.
/// `None` if the record is shorter than one segment.
pub fn welch(x: &[f64], dt: f64, segment_len: usize) -> Option<Spectrum> {
    let l = segment_len;
    if l < 8 || !l.is_multiple_of(2) || x.len() < l || dt <= 0.0 {
        return None;
    }
    let hop = l / 2;
    let segments = (x.len() - l) / hop + 1;
    let w: Vec<f64> = (0..l).map(|n| 0.5 - 0.5 * (2.0 * PI * n as f64 / l as f64).cos()).collect();
    let w2: f64 = w.iter().map(|v| v * v).sum();
    let fft = FftPlanner::<f64>::new().plan_fft_forward(l);
    let mut buf = vec![Complex::new(0.0, 0.0); l];
    let mut acc = vec![0.0; l / 2 + 1];
    for s in 0..segments {
        let seg = &x[s * hop..s * hop + l];
        let mean = seg.iter().sum::<f64>() / l as f64;
        for ((b, v), wn) in buf.iter_mut().zip(seg).zip(&w) {
            *b = Complex::new((v - mean) * wn, 0.0);
        }
        fft.process(&mut buf);
        for (a, b) in acc.iter_mut().zip(&buf) {
            *a += b.norm_sqr();
        }
    }
    let fs = 1.0 / dt;
    let scale = 1.0 / (segments as f64 * fs * w2);
    let psd: Vec<f64> =
        acc.iter().enumerate().map(|(k, a)| if k == 0 || k == l / 2 { a * scale } else { 2.0 * a * scale }).collect();
    let df_hz = fs / l as f64;
    Some(Spectrum { freq_hz: (0..=l / 2).map(|k| k as f64 * df_hz).collect(), psd, df_hz, segment_len: l, segments })
}

/// The frequency of the spectrum's highest peak above the lowest bin (bin 0 holds what is left of
/// the mean). Refined between bins by a parabola through the logarithms of the peak bin and its
/// two neighbours, δ = ½ (a − c)/(a − 2b + c) bins (Gaussian interpolation): for a Hann window
/// the bias is below 0.02 bin. A peak at bin 1 or the last bin is returned unrefined.
/// `None` if the spectrum has fewer than 3 bins or no power.
pub fn dominant_frequency(s: &Spectrum) -> Option<f64> {
    let n = s.psd.len();
    if n < 3 {
        return None;
    }
    let (k, &pk) = s.psd.iter().enumerate().skip(1).max_by(|a, b| a.1.total_cmp(b.1))?;
    if pk <= 0.0 || !pk.is_finite() {
        return None;
    }
    if k == 1 || k == n - 1 {
        return Some(s.freq_hz[k]);
    }
    let (p0, p2) = (s.psd[k - 1], s.psd[k + 1]);
    let delta = if p0 > 0.0 && p2 > 0.0 {
        let (a, b, c) = (p0.ln(), pk.ln(), p2.ln());
        parabola_vertex(a, b, c)
    } else {
        parabola_vertex(p0, pk, p2)
    };
    Some(s.freq_hz[k] + delta * s.df_hz)
}

/// Offset in samples (within ±½) of the vertex of the parabola through (−1, a), (0, b), (1, c),
/// b being the largest.
pub(crate) fn parabola_vertex(a: f64, b: f64, c: f64) -> f64 {
    let den = a - 2.0 * b + c;
    if den < 0.0 {
        (0.5 * (a - c) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::test_signals::Noise;

    fn tone(n: usize, dt: f64, f: f64, a: f64, phase: f64) -> Vec<f64> {
        (0..n).map(|i| a * (2.0 * PI * f * i as f64 * dt + phase).sin()).collect()
    }

    #[test]
    fn a_tone_on_a_bin_carries_exactly_half_its_amplitude_squared() {
        // L = 256, f_s = 100 Hz: bin 20 is 7.8125 Hz. Hann on a bin: |X| = A L/4 at the bin and
        // A L/8 at its neighbours, Σ w² = 3L/8, so Σ P df = A²/2, and all of it within ±1 bin.
        let (dt, l, a) = (0.01, 256, 3.0);
        let f = 20.0 / (l as f64 * dt);
        let x: Vec<f64> = tone(4096, dt, f, a, 0.4).iter().map(|v| v + 10.0).collect();
        let s = welch(&x, dt, l).unwrap();
        assert_eq!(s.segments, (4096 - 256) / 128 + 1);
        assert!((s.df_hz - 100.0 / 256.0).abs() < 1e-12);
        let total: f64 = s.psd.iter().sum::<f64>() * s.df_hz;
        assert!((total - a * a / 2.0).abs() < 1e-9 * a * a, "{total}");
        let peak = s.band_power(f - 1.01 * s.df_hz, f + 1.01 * s.df_hz);
        assert!((peak - a * a / 2.0).abs() < 1e-9 * a * a, "{peak}");
        // The three bins in the ratio 1 : 4 : 1 (power of L/8, L/4, L/8).
        assert!((s.psd[20] / s.psd[19] - 4.0).abs() < 1e-9 && (s.psd[20] / s.psd[21] - 4.0).abs() < 1e-9);
        assert!((dominant_frequency(&s).unwrap() - f).abs() < 1e-9);
    }

    #[test]
    fn white_noise_has_a_flat_density_of_two_sigma_squared_over_fs() {
        // One-sided density of white noise of variance σ²: 2σ²/f_s at every bin but the ends.
        let (dt, sigma) = (0.005, 2.0);
        let mut noise = Noise::new(7);
        let x: Vec<f64> = (0..200_000).map(|_| sigma * noise.gauss()).collect();
        let s = welch(&x, dt, 512).unwrap();
        let want = 2.0 * sigma * sigma * dt;
        let inner = &s.psd[1..s.psd.len() - 1];
        let mean = inner.iter().sum::<f64>() / inner.len() as f64;
        assert!((mean / want - 1.0).abs() < 0.01, "{mean} vs {want}");
        // Parseval: the integral is the variance, to the sampling error of σ² (≈ 0.3% here).
        let total: f64 = s.psd.iter().sum::<f64>() * s.df_hz;
        assert!((total / (sigma * sigma) - 1.0).abs() < 0.01, "{total}");
    }

    #[test]
    fn the_dominant_frequency_is_found_between_bins_within_two_hundredths_of_a_bin() {
        // Tones at fractions δ of a bin past bin 40, with a weaker second tone and noise.
        let (dt, l) = (0.005, 512);
        let df = 1.0 / (l as f64 * dt);
        let mut noise = Noise::new(3);
        for delta in [0.0, 0.1, 0.25, 0.37, 0.5, 0.73, 0.9] {
            let f = (40.0 + delta) * df;
            let x: Vec<f64> = tone(20_000, dt, f, 5.0, 1.0)
                .iter()
                .zip(tone(20_000, dt, 2.7 * f, 2.0, 0.2))
                .map(|(a, b)| 1000.0 + a + b + 0.5 * noise.gauss())
                .collect();
            let s = welch(&x, dt, l).unwrap();
            let got = dominant_frequency(&s).unwrap();
            assert!((got - f).abs() < 0.02 * df, "δ = {delta}: {got} vs {f} (df {df})");
        }
    }

    #[test]
    fn short_or_odd_inputs_give_none() {
        assert!(welch(&[1.0; 100], 0.01, 128).is_none());
        assert!(welch(&[1.0; 100], 0.01, 15).is_none());
        let flat = welch(&[1.0; 256], 0.01, 64).unwrap();
        assert!(flat.psd.iter().all(|p| p.abs() < 1e-20));
        assert!(dominant_frequency(&flat).is_none());
    }
}
