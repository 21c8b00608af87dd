//! The analysis functions (core/src/analysis) on synthetic inputs whose answers are known
//! (issue 24: `validate -- analysis-signals`, judged by checks/analysis-signals):
//! - a ΔP record: offset + two tones + white noise → mean, standard deviation, Welch peak
//!   frequency and the power under the peak against what was put in;
//! - a train of bubbles at random times seen at two heights a known delay apart, with noise →
//!   rise velocity by cross-correlation against Δz/τ, bubbles per second against the count put in;
//! - a voidage field whose cells are bubble with a known probability per layer → bubble fraction;
//! - a circulating particle field (upflow at the axis, downflow at the wall) whose particle count
//!   swings with its velocity → the particle-based annulus means against their analytic values,
//!   which a mean of cell means would miss by A β / 2; isotropic noise → granular temperature;
//! - eruptions at the bed surface at random times, each followed by a ΔP bump of known height
//!   and delay → the eruption rate, the delay and the swing of the eruption-triggered ΔP.
//!
//! Seeded (ChaCha8), so the figures repeat. Last line: one JSON object with a `<figure>_rel_err`
//! per figure.

use fluidbed_core::analysis::*;
use fluidbed_core::grid::CylGrid;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;
use std::f64::consts::PI;

struct Noise(ChaCha8Rng);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0.gen()
    }
    /// Box–Muller standard normal.
    fn gauss(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * self.uniform()).cos()
    }
}

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

pub fn run() -> serde_json::Value {
    let mut noise = Noise(ChaCha8Rng::seed_from_u64(2014));
    let mut out = json!({"name": "analysis-signals"});

    // --- ΔP: 600 s at 200 Hz. P0 = 1050 Pa (a bed's weight), a 3.37 Hz tone of 60 Pa (bubble
    // eruptions), a 7.9 Hz tone of 25 Pa, white noise σ = 10 Pa. std = √(A₁²/2 + A₂²/2 + σ²).
    // The record's own variance scatters about this by √(2σ⁴ + 4σ²σ_tones²)/√N ≈ 0.12%.
    let (dt, n) = (0.005, 120_000);
    let (p0, f1, a1, f2, a2, sigma) = (1050.0, 3.37, 60.0, 7.9, 25.0, 10.0);
    let dp: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 * dt;
            p0 + a1 * (2.0 * PI * f1 * t + 0.3).sin() + a2 * (2.0 * PI * f2 * t + 1.1).sin() + sigma * noise.gauss()
        })
        .collect();
    let st = signal_stats(&dp).unwrap();
    let std_want = (a1 * a1 / 2.0 + a2 * a2 / 2.0 + sigma * sigma).sqrt();
    let spec = welch(&dp, dt, 1024).unwrap();
    let f_dom = dominant_frequency(&spec).unwrap();
    // Power under the peak (±4 bins) less the noise floor there (the mean density over 20–90 Hz,
    // where there is only noise), against A₁²/2.
    let half = 4.0 * spec.df_hz;
    let floor_bins: Vec<f64> =
        spec.freq_hz.iter().zip(&spec.psd).filter(|(f, _)| **f >= 20.0 && **f <= 90.0).map(|(_, p)| *p).collect();
    let floor = floor_bins.iter().sum::<f64>() / floor_bins.len() as f64;
    let in_band = spec.freq_hz.iter().filter(|f| (**f - f_dom).abs() <= half).count() as f64;
    let peak_power = spec.band_power(f_dom - half, f_dom + half) - floor * in_band * spec.df_hz;
    let total_power = spec.band_power(0.0, f64::INFINITY);
    eprintln!(
        "ΔP: mean {:.2} Pa (put in {p0}), std {:.3} Pa (√(A₁²/2 + A₂²/2 + σ²) = {std_want:.3}); Welch {} segments of {} (df {:.4} Hz): peak {f_dom:.4} Hz (put in {f1}), power under it {peak_power:.1} Pa² (A₁²/2 = {:.1}), total {total_power:.1} Pa² (variance {:.1}); noise floor {floor:.3} Pa²/Hz (2σ²/f_s = {:.3})",
        st.mean,
        st.std,
        spec.segments,
        spec.segment_len,
        spec.df_hz,
        a1 * a1 / 2.0,
        std_want * std_want,
        2.0 * sigma * sigma * dt
    );
    out["dp_mean_pa"] = json!(st.mean);
    out["dp_mean_rel_err"] = json!(rel(st.mean, p0));
    out["dp_std_pa"] = json!(st.std);
    out["dp_std_rel_err"] = json!(rel(st.std, std_want));
    out["dominant_frequency_hz"] = json!(f_dom);
    out["dominant_frequency_rel_err"] = json!(rel(f_dom, f1));
    // The first 2 s alone (a slugging run's window: too short for Welch's segments to resolve a
    // few hertz): the peak of the whole record's periodogram.
    let f_2s = fluidbed_core::analysis::peak_frequency(&dp[..(2.0 / dt) as usize], dt).unwrap();
    eprintln!("ΔP's first 2 s: periodogram peak {f_2s:.4} Hz (put in {f1})");
    out["peak_frequency_2s_hz"] = json!(f_2s);
    out["peak_frequency_2s_rel_err"] = json!(rel(f_2s, f1));
    out["psd_peak_power_pa2"] = json!(peak_power);
    out["psd_peak_power_rel_err"] = json!(rel(peak_power, a1 * a1 / 2.0));
    out["psd_total_power_rel_err"] = json!(rel(total_power, std_want * std_want));

    // --- Bubbles: 40 s at 500 Hz, a bubble every 0.15–0.35 s (peaks in [0.3, T − 0.3] s),
    // amplitude 0.3–0.5 over ε = 0.42, Gaussian in time of width 25 ms at z₁ and 30 ms at
    // z₂ = z₁ + 30 mm (it grows), rising at 0.45 m/s: τ = 66.67 ms. Noise σ = 0.02 per height.
    let (dt, secs, dz, u_b) = (0.002, 40.0, 0.03, 0.45);
    let n = (secs / dt) as usize;
    let mut bubbles = vec![];
    let mut t = 0.3;
    while t < secs - 0.3 {
        bubbles.push((t, 0.3 + 0.2 * noise.uniform()));
        t += 0.15 + 0.2 * noise.uniform();
    }
    let tau = dz / u_b;
    let mut signal = |delay: f64, w: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let t = i as f64 * dt;
                let pulses: f64 = bubbles
                    .iter()
                    .filter(|(tb, _)| (t - tb - delay).abs() < 8.0 * w)
                    .map(|(tb, a)| a * (-(t - tb - delay).powi(2) / (2.0 * w * w)).exp())
                    .sum();
                0.42 + pulses + 0.02 * noise.gauss()
            })
            .collect()
    };
    let lower = signal(0.0, 0.025);
    let upper = signal(tau, 0.030);
    let rv = rise_velocity(&lower, &upper, dt, dz, 0.5).expect("a correlation peak");
    let count = count_bubbles(&lower, dt, 0.65, 0.5);
    let f_in = bubbles.len() as f64 / secs;
    eprintln!(
        "bubbles: {} put in over {secs} s ({f_in:.3} /s); counted {} ({:.3} /s); rise velocity {:.4} m/s from a delay of {:.3} ms (put in {u_b} m/s, {:.3} ms), correlation peak {:.3}",
        bubbles.len(),
        count.bubbles,
        count.per_second,
        rv.velocity_m_s,
        rv.delay_s * 1e3,
        tau * 1e3,
        rv.peak
    );
    out["rise_velocity_m_s"] = json!(rv.velocity_m_s);
    out["rise_velocity_rel_err"] = json!(rel(rv.velocity_m_s, u_b));
    out["correlation_peak"] = json!(rv.peak);
    out["bubble_frequency_hz"] = json!(count.per_second);
    out["bubble_frequency_rel_err"] = json!(rel(count.per_second, f_in));

    // --- Bubble fraction: a 22-mm column, 10 annuli, 3·(2i+1) cells, 20 layers; each cell is
    // bubble (ε = 0.95) with probability b_k = 0.2 + 0.015 k in each of 5000 samples, else
    // ε = 0.42 ± 0.05. Worst layer's relative error.
    let g = CylGrid::new(0.011, 0.04, 0.0011, 0.002, 3);
    let per = g.cells_per_layer();
    let b = |k: usize| 0.2 + 0.015 * k as f64;
    let mut bf = BubbleFraction::new(&g, 0.8);
    for _ in 0..5000 {
        let field: Vec<f64> = (0..g.num_cells())
            .map(|c| if noise.uniform() < b(c / per) { 0.95 } else { 0.42 + 0.05 * (2.0 * noise.uniform() - 1.0) })
            .collect();
        bf.add_sample(&field);
    }
    let frac = bf.finish();
    let worst_bf = frac.value.iter().enumerate().map(|(k, f)| rel(*f, b(k))).fold(0.0, f64::max);
    eprintln!(
        "bubble fraction: {} layers × {per} cells × {} samples; layer 0 {:.4} (b = {:.3}), layer {} {:.4} (b = {:.3}); worst relative error {worst_bf:.2e}",
        g.nz,
        frac.samples,
        frac.value[0],
        b(0),
        g.nz - 1,
        frac.value[g.nz - 1],
        b(g.nz - 1)
    );
    out["bubble_fraction_rel_err"] = json!(worst_bf);

    // --- Particle-based average: a 40-mm column, 5 annuli, 8 layers. 800 samples; sample s holds
    // N_s = round(N0 (1 + β sin φ_s)) particles, φ_s = 2π s/8, uniform in the column, with
    // v_z = V0 (1 − 2r²/R²) + A sin φ_s + σ N(0,1), v_θ = Ω r, v_r = σ N(0,1). Analytic annulus
    // [r₀, r₁] means: v_z = V0 (1 − (r₀² + r₁²)/R²) + A Σ N_s sin φ_s / Σ N_s (the particle
    // weighting: fast-rising samples hold more particles), v_θ = Ω 2(r₁³ − r₀³)/(3(r₁² − r₀²)).
    // Figure: worst |error| over annuli and both components, over V0.
    let (radius, height) = (0.02, 0.04);
    let g = CylGrid::new(radius, height, 0.004, 0.005, 2);
    let (n0, beta, v0, a, omega, sig) = (4000.0, 0.5, 0.1, 0.05, 3.0, 0.02);
    let mut pa = ParticleAverage::new(&g);
    let (mut sum_n, mut sum_n_sin) = (0.0, 0.0);
    for s in 0..800 {
        let sn = (2.0 * PI * s as f64 / 8.0).sin();
        let count = (n0 * (1.0 + beta * sn)).round() as usize;
        sum_n += count as f64;
        sum_n_sin += count as f64 * sn;
        let (mut xs, mut vs) = (Vec::with_capacity(count), Vec::with_capacity(count));
        for _ in 0..count {
            let r = radius * noise.uniform().sqrt();
            let th = 2.0 * PI * noise.uniform();
            let z = height * noise.uniform();
            let (c, si) = (th.cos(), th.sin());
            let (vr, vt) = (sig * noise.gauss(), omega * r);
            let vz = v0 * (1.0 - 2.0 * r * r / (radius * radius)) + a * sn + sig * noise.gauss();
            xs.push([r * c, r * si, z]);
            vs.push([c * vr - si * vt, si * vr + c * vt, vz]);
        }
        pa.add_sample(&g, &xs, &vs);
    }
    let m = pa.finish();
    let w = m.weights();
    let vz = radial_profile(&g, &m.vz(), Some(&w), 0.0, height);
    let vt_cells: Vec<f64> = m.velocity.iter().map(|v| v[1]).collect();
    let vt = radial_profile(&g, &vt_cells, Some(&w), 0.0, height);
    let shift = a * sum_n_sin / sum_n;
    let mut worst_pa: f64 = 0.0;
    let mut rows = vec![];
    for i in 0..g.nr {
        let (r0, r1) = (i as f64 * g.dr, (i + 1) as f64 * g.dr);
        let want_z = v0 * (1.0 - (r0 * r0 + r1 * r1) / (radius * radius)) + shift;
        let want_t = omega * 2.0 * (r1.powi(3) - r0.powi(3)) / (3.0 * (r1 * r1 - r0 * r0));
        worst_pa = worst_pa.max((vz.value[i] - want_z).abs() / v0).max((vt.value[i] - want_t).abs() / v0);
        rows.push(format!(
            "r {:.1} mm: v_z {:+.5} ({want_z:+.5}), v_θ {:.5} ({want_t:.5})",
            vz.r_m[i] * 1e3,
            vz.value[i],
            vt.value[i]
        ));
    }
    eprintln!(
        "particle-based averages over {} samples ({} visits): {}; the particle weighting adds A Σ N sin/Σ N = {shift:+.5} m/s that a mean of cell means would not; worst |error|/V0 {worst_pa:.2e}",
        m.samples,
        w.iter().sum::<f64>(),
        rows.join("; ")
    );
    out["particle_average_vz_axis_m_s"] = json!(vz.value[0]);
    out["particle_average_rel_err"] = json!(worst_pa);

    // --- Granular temperature: one cell, 3000 samples of 40 particles with v = (0.1, 0, 0.3) +
    // A_s sin(2π s/5) ẑ + σ N(0,1) per component: T = σ² (the swing is common to a sample).
    let g1 = CylGrid::new(0.01, 0.01, 0.01, 0.01, 1);
    let mut pt = ParticleAverage::new(&g1);
    let sig_t = 0.05;
    for s in 0..3000 {
        let swing = 0.2 * (2.0 * PI * s as f64 / 5.0).sin();
        let xs = vec![[0.002, 0.001, 0.005]; 40];
        let vs: Vec<[f64; 3]> = (0..40)
            .map(|_| [0.1 + sig_t * noise.gauss(), sig_t * noise.gauss(), 0.3 + swing + sig_t * noise.gauss()])
            .collect();
        pt.add_sample(&g1, &xs, &vs);
    }
    let tm = pt.finish();
    let t_gran = tm.granular_temperature[0];
    eprintln!(
        "granular temperature: {t_gran:.4e} m²/s² (σ² = {:.4e}); about the time mean {:.4e} (σ² + 0.2²/6 = {:.4e})",
        sig_t * sig_t,
        tm.granular_temperature_total[0],
        sig_t * sig_t + 0.04 / 6.0
    );
    out["granular_temperature_rel_err"] = json!(rel(t_gran, sig_t * sig_t));

    // --- Eruptions: 40 s at 500 Hz, an eruption every 0.25–0.45 s (at whole samples); the
    // surface voidage steps from 0.42 to 0.9 for 40 ms at each, so the front through 0.8 lies in
    // the sample interval before it and rounds to it; ΔP = 150 Pa + 20 Pa exp(−(τ − 40 ms)²/2σ²),
    // σ = 15 ms, after each, noise σ = 0.3 Pa. Within ±0.1 s of an eruption only its own bump.
    let (dt, secs, lag, bump) = (0.002, 40.0, 0.04, 20.0);
    let n = (secs / dt) as usize;
    let mut starts = vec![];
    let mut i = (0.3 / dt) as usize;
    while (i as f64) * dt < secs - 0.3 {
        starts.push(i);
        i += ((0.25 + 0.2 * noise.uniform()) / dt) as usize;
    }
    let mut surface = vec![0.42; n];
    let mut dp = vec![150.0; n];
    for &i0 in &starts {
        surface[i0..i0 + 20].fill(0.9);
        for (j, p) in dp.iter_mut().enumerate().skip(i0.saturating_sub(100)).take(300) {
            let tau = (j as f64 - i0 as f64) * dt;
            *p += bump * (-(tau - lag).powi(2) / (2.0 * 0.015 * 0.015)).exp();
        }
    }
    for p in dp.iter_mut() {
        *p += 0.3 * noise.gauss();
    }
    let fronts = count_bubbles(&surface, dt, 0.8, 0.5);
    let link = eruption_link(&dp, &fronts.fronts_s, dt, 0.1).expect("eruptions");
    let rate_in = starts.len() as f64 / secs;
    eprintln!(
        "eruptions: {} put in ({rate_in:.3} /s), found {} ({:.3} /s); ΔP peak {:.1} ms after them (put in {:.0} ms), swing {:.3} Pa (put in {bump})",
        starts.len(),
        fronts.bubbles,
        fronts.per_second,
        link.lag_of_max_s * 1e3,
        lag * 1e3,
        link.swing_pa
    );
    out["eruption_rate_rel_err"] = json!(rel(fronts.per_second, rate_in));
    out["eruption_dp_lag_rel_err"] = json!(rel(link.lag_of_max_s, lag));
    out["eruption_dp_swing_rel_err"] = json!(rel(link.swing_pa, bump));
    out
}
