//! The paper's analyses accumulated while a run goes (case `analysis`): every `sample_interval_s`
//! from `from_s` on, the bed pressure drop, the layer means of the voidage, the bubble fraction,
//! the particle-based averages (Boyce et al. 2013) and the field averages take one sample; the
//! state travels in the checkpoint's `analysis` section, so a resumed job keeps its window.
//! `report` turns the sums into the statistics of `analysis` (no sample is kept beyond the ΔP
//! series and the layer means).
//!
//! Choices (stated in docs/VALIDATION.md "Analysis during a run"): the bed height is the top of
//! the highest layer whose time-averaged voidage is below 0.8; bubbles are counted where the
//! cross-section mean voidage at the lower rise height rises through its time mean + one standard
//! deviation after it was last below its mean (`count_bubbles`' hysteresis); the Welch segments
//! are the longest power of two with at least four half-overlapping segments in the record; the
//! rise velocity searches delays up to half the record.

use crate::analysis::{
    axial_map, bed_pressure_drop, count_bubbles, eruption_link, layer_means, peak_frequency, radial_profile,
    rise_velocity, signal_stats, surface_height, welch, AxialMap, BubbleCount, BubbleFraction, ByHeight, EruptionLink,
    FieldAverage, LayerSeries, ParticleAverage, RadialProfile, RiseVelocity, Spectrum,
};
use crate::case::{AnalysisSpec, Case};
use crate::grid::CylGrid;
use serde::{Deserialize, Serialize};

/// Cell voidage below which a layer counts as bed, for the bed height.
const BED_VOIDAGE: f64 = 0.8;

/// Eruptions are bubble fronts at this fraction of the bed height (just below the surface).
const ERUPTION_HEIGHT: f64 = 0.9;

/// The accumulated samples of one run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunAnalysis {
    spec: AnalysisSpec,
    /// DEM steps between samples.
    every: u64,
    first_s: Option<f64>,
    last_s: f64,
    pressure_drop_pa: Vec<f64>,
    voidage_layers: LayerSeries,
    bubbles: BubbleFraction,
    particles: ParticleAverage,
    fields: FieldAverage,
}

/// The inputs of one sample.
pub struct Sample<'a> {
    pub time_s: f64,
    pub voidage: &'a [f64],
    /// Absolute gas pressure per cell (gas runs).
    pub pressure_pa: Option<&'a [f64]>,
    pub gas_velocity: Option<&'a [[f64; 3]]>,
    pub positions: &'a [[f64; 3]],
    pub velocities: &'a [[f64; 3]],
}

/// Everything `GET /v1/jobs/{id}/analysis` shows: each statistic with its window and samples.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AnalysisReport {
    pub from_s: f64,
    pub to_s: f64,
    pub samples: u64,
    /// Start and sample count of the window of the time-series statistics (ΔP, bubble count, rise
    /// velocity): `from_s` and `samples` unless the request asked for a later start.
    pub series_from_s: f64,
    pub series_samples: u64,
    pub sample_interval_s: f64,
    pub pressure_drop: Option<PressureDropStats>,
    /// Top of the highest layer whose time-averaged voidage is below 0.8 (m).
    pub bed_height_m: Option<f64>,
    pub bubbles: Option<Bubbles>,
    pub bubble_fraction: ByHeight,
    pub rise_velocity: Option<Rise>,
    /// Bubble eruptions at the bed surface against ΔP (paper Fig. 9).
    pub eruptions: Option<Eruptions>,
    /// Particle-based ⟨v_z⟩ (m/s) and the time-averaged voidage on the axial plane (r, z).
    pub particle_velocity_map: AxialMap,
    pub voidage_map: AxialMap,
    pub radial_profiles: Vec<Profiles>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PressureDropStats {
    pub mean_pa: f64,
    pub std_pa: f64,
    /// The highest peak of the whole window's periodogram (analysis/peak_frequency.rs), at or
    /// above two cycles per window; `spectrum` (Welch's, smoother, coarser) is for the plot.
    pub dominant_frequency_hz: Option<f64>,
    pub spectrum: Option<Spectrum>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Bubbles {
    pub height_m: f64,
    /// Thresholds on the cross-section mean voidage (rise through `rise` after below `fall`).
    pub rise: f64,
    pub fall: f64,
    pub count: BubbleCount,
}

/// Eruptions: the bubble fronts at 0.9 of the bed height (counted as `bubbles` is), and the
/// triggered average of ΔP over one mean eruption period (at most 0.5 s) each side.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Eruptions {
    pub fronts: Bubbles,
    pub link: EruptionLink,
    /// ΔP's dominant frequency over the eruption rate (1: one ΔP cycle per eruption).
    pub dp_frequency_per_eruption: Option<f64>,
    /// The dominant frequency of the bed surface's height (the top of the highest layer below
    /// voidage 0.8 at each sample), which falls once at each eruption: a rate without thresholds
    /// and resolved over the whole window (analysis/peak_frequency.rs).
    pub surface_frequency_hz: Option<f64>,
    /// ΔP's dominant frequency over the surface's (½: one ΔP period per pair of eruptions, the
    /// paper's Fig. 9).
    pub dp_frequency_per_surface_cycle: Option<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Rise {
    pub lower_m: f64,
    pub upper_m: f64,
    /// From the cross-section voidage at the two heights (Müller et al. 2007a).
    pub voidage: Option<RiseVelocity>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Profiles {
    pub height_m: f64,
    pub particle_velocity_z: RadialProfile,
    pub voidage: RadialProfile,
}

impl RunAnalysis {
    pub fn new(case: &Case, grid: &CylGrid) -> RunAnalysis {
        let spec = case.analysis.clone();
        let every = ((spec.sample_interval_s / case.dem.time_step_s).round() as u64).max(1);
        RunAnalysis {
            every,
            first_s: None,
            last_s: 0.0,
            pressure_drop_pa: Vec::new(),
            voidage_layers: LayerSeries::new(grid),
            bubbles: BubbleFraction::new(grid, spec.bubble_voidage),
            particles: ParticleAverage::new(grid),
            fields: FieldAverage::new(grid.num_cells()),
            spec,
        }
    }

    /// Whether DEM step `step` at time `t` takes a sample.
    pub fn due(&self, step: u64, t: f64) -> bool {
        step.is_multiple_of(self.every) && t >= self.spec.from_s - 1e-12
    }

    pub fn samples(&self) -> u64 {
        self.fields.samples()
    }

    pub fn add(&mut self, grid: &CylGrid, s: &Sample) {
        self.first_s.get_or_insert(s.time_s);
        self.last_s = s.time_s;
        if let Some(p) = s.pressure_pa {
            self.pressure_drop_pa.push(bed_pressure_drop(&layer_means(grid, p)));
        }
        self.voidage_layers.add_sample(s.time_s, s.voidage);
        self.bubbles.add_sample(s.voidage);
        self.particles.add_sample(grid, s.positions, s.velocities);
        self.fields.add_sample(s.voidage, s.gas_velocity);
    }

    pub fn report(&self, grid: &CylGrid) -> AnalysisReport {
        self.report_from(grid, None)
    }

    /// The report with the time series (ΔP statistics and spectrum, bubble count, rise velocity)
    /// over the samples at or after `from_s` only; the maps, profiles, bubble fraction and bed
    /// height are sums and keep the whole window (`from_s`–`to_s` of the report).
    pub fn report_from(&self, grid: &CylGrid, from_s: Option<f64>) -> AnalysisReport {
        let dt = self.every_s();
        let times = self.voidage_layers.times_s();
        let skip = from_s.map_or(0, |t| times.partition_point(|&x| x < t - 1e-12));
        let series_from_s = times.get(skip).copied().unwrap_or(self.last_s);
        let dp = &self.pressure_drop_pa[skip.min(self.pressure_drop_pa.len())..];
        let pressure_drop = signal_stats(dp).map(|st| {
            let spectrum = welch_of(dp, dt);
            PressureDropStats {
                mean_pa: st.mean,
                std_pa: st.std,
                dominant_frequency_hz: peak_frequency(dp, dt),
                spectrum,
            }
        });
        let fields = self.fields.finish();
        let particles = self.particles.finish();
        let voidage_map = axial_map(grid, &fields.voidage, None);
        let weights = particles.weights();
        let particle_velocity_map = axial_map(grid, &particles.vz(), Some(&weights));
        let layer_voidage = layer_means(grid, &fields.voidage);
        let bed_height_m = (self.samples() > 0).then(|| surface_height(&layer_voidage, BED_VOIDAGE, grid.dz)).flatten();
        let rise_heights = self.spec.rise_heights_m.or(bed_height_m.map(|h| [0.3 * h, 0.7 * h]));
        let bubbles = rise_heights.and_then(|[lo, _]| self.bubbles_at(lo, dt, skip));
        let rise_velocity = rise_heights.map(|[lo, hi]| {
            let (a, b) = (&self.voidage_layers.at_height(lo)[skip..], &self.voidage_layers.at_height(hi)[skip..]);
            let (klo, khi) = (grid.locate_k(lo), grid.locate_k(hi));
            let dz = (khi as f64 - klo as f64) * grid.dz;
            let half = 0.5 * a.len() as f64 * dt;
            Rise { lower_m: lo, upper_m: hi, voidage: (dz > 0.0).then(|| rise_velocity(a, b, dt, dz, half)).flatten() }
        });
        let dp_hz = pressure_drop.as_ref().and_then(|p| p.dominant_frequency_hz);
        let eruptions = bed_height_m.and_then(|h| self.eruptions_at(ERUPTION_HEIGHT * h, dt, skip, dp, dp_hz));
        let heights = if self.spec.profile_heights_m.is_empty() {
            bed_height_m.map(|h| vec![0.5 * h]).unwrap_or_default()
        } else {
            self.spec.profile_heights_m.clone()
        };
        let radial_profiles = heights
            .iter()
            .map(|&z| Profiles {
                height_m: z,
                particle_velocity_z: radial_profile(grid, &particles.vz(), Some(&weights), z, z),
                voidage: radial_profile(grid, &fields.voidage, None, z, z),
            })
            .collect();
        AnalysisReport {
            from_s: self.first_s.unwrap_or(self.spec.from_s),
            to_s: self.last_s,
            samples: self.samples(),
            series_from_s,
            series_samples: (times.len() - skip) as u64,
            sample_interval_s: dt,
            pressure_drop,
            bed_height_m,
            bubbles,
            bubble_fraction: self.bubbles.finish(),
            rise_velocity,
            eruptions,
            particle_velocity_map,
            voidage_map,
            radial_profiles,
        }
    }

    /// Seconds between samples (whole DEM steps).
    fn every_s(&self) -> f64 {
        match (self.first_s, self.samples()) {
            (Some(t0), n) if n > 1 => (self.last_s - t0) / (n - 1) as f64,
            _ => self.spec.sample_interval_s,
        }
    }

    fn bubbles_at(&self, z: f64, dt: f64, skip: usize) -> Option<Bubbles> {
        let x = self.voidage_layers.at_height(z).split_off(skip);
        let st = signal_stats(&x)?;
        let (rise, fall) = (st.mean + st.std, st.mean);
        (rise > fall).then(|| Bubbles { height_m: z, rise, fall, count: count_bubbles(&x, dt, rise, fall) })
    }

    fn eruptions_at(&self, z: f64, dt: f64, skip: usize, dp: &[f64], dp_hz: Option<f64>) -> Option<Eruptions> {
        let fronts = self.bubbles_at(z, dt, skip).filter(|b| b.count.bubbles > 0)?;
        let rate = fronts.count.per_second;
        let link = eruption_link(dp, &fronts.count.fronts_s, dt, (1.0 / rate).min(0.5))?;
        let dp_frequency_per_eruption = dp_hz.map(|f| f / rate);
        let surface = self.voidage_layers.surface_heights(BED_VOIDAGE).split_off(skip);
        let surface_frequency_hz = peak_frequency(&surface, dt);
        let dp_frequency_per_surface_cycle = dp_hz.zip(surface_frequency_hz).map(|(f, s)| f / s);
        Some(Eruptions {
            fronts,
            link,
            dp_frequency_per_eruption,
            surface_frequency_hz,
            dp_frequency_per_surface_cycle,
        })
    }
}

/// Welch's spectrum with the longest power-of-two segments that still give four segments.
fn welch_of(x: &[f64], dt: f64) -> Option<Spectrum> {
    let mut l = 8usize;
    while (x.len().saturating_sub(2 * l)) / l + 1 >= 4 && 2 * l <= x.len() {
        l *= 2;
    }
    welch(x, dt, l).or_else(|| welch(x, dt, 8))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The analysis of a 20-mm column (4 annuli of 2.5 mm, 3 cells in the first, layers of 2 mm,
    /// 30 mm tall) stepped at `dt` and sampled every `interval` s from `from_s`.
    fn small_column(dt: f64, from_s: f64, interval: f64) -> (RunAnalysis, CylGrid) {
        let case: Case = serde_json::from_value(serde_json::json!({
            "column": {"diameter_m": 0.02, "height_m": 0.03}, "particles": {},
            "bed": {"generated": {"settled_height_m": 0.01}}, "dem": {"time_step_s": dt},
            "analysis": {"from_s": from_s, "sample_interval_s": interval}}))
        .unwrap();
        let grid = CylGrid::new(0.01, 0.03, 0.0025, 0.002, 3);
        (RunAnalysis::new(&case, &grid), grid)
    }

    /// One sample at `t` of a column whose pressure is linear in the layer index, so that its bed
    /// drop (plate to the top two layers' mean) is `dp` over nz − 1 layers.
    fn add_sample(a: &mut RunAnalysis, grid: &CylGrid, t: f64, eps: &[f64], dp: f64, particles: [&[[f64; 3]]; 2]) {
        let (per, slope) = (grid.cells_per_layer(), dp / (grid.nz as f64 - 1.0));
        let p: Vec<f64> = (0..grid.num_cells()).map(|c| 1e5 - slope * (c / per) as f64).collect();
        let [positions, velocities] = particles;
        let s = Sample { time_s: t, voidage: eps, pressure_pa: Some(&p), gas_velocity: None, positions, velocities };
        a.add(grid, &s);
    }

    /// A ΔP of 100 + 10 sin(2π·4 t) Pa before 0.5 s and 200 + 20 sin(2π·10 t) Pa after: the report
    /// from 0.5 s has the second signal's statistics, the whole report their mixture.
    #[test]
    fn a_later_start_gives_the_time_series_statistics_of_that_window_only() {
        let (mut a, grid) = small_column(1e-3, 0.0, 0.001);
        let n = grid.num_cells();
        let eps = vec![0.4; n];
        let none: Vec<[f64; 3]> = vec![];
        for step in 0..1000u64 {
            let t = step as f64 * 1e-3;
            let dp = if t < 0.5 {
                100.0 + 10.0 * (2.0 * PI * 4.0 * t).sin()
            } else {
                200.0 + 20.0 * (2.0 * PI * 10.0 * t).sin()
            };
            add_sample(&mut a, &grid, t, &eps, dp, [&none, &none]);
        }
        let late = a.report_from(&grid, Some(0.5));
        assert_eq!((late.series_samples, late.samples), (500, 1000));
        assert!(
            (late.series_from_s - 0.5).abs() < 1e-12 && late.from_s == 0.0,
            "window {} / {}",
            late.series_from_s,
            late.from_s
        );
        let dp = late.pressure_drop.as_ref().unwrap();
        assert!((dp.mean_pa - 200.0).abs() < 0.01, "mean {}", dp.mean_pa);
        assert!((dp.std_pa / (20.0 / 2f64.sqrt()) - 1.0).abs() < 0.01, "std {}", dp.std_pa);
        let f = dp.dominant_frequency_hz.unwrap();
        assert!((f - 10.0).abs() <= dp.spectrum.as_ref().unwrap().df_hz, "dominant {f} Hz");
        let all = a.report(&grid);
        assert_eq!((all.series_samples, all.series_from_s), (1000, 0.0));
        assert!((all.pressure_drop.unwrap().mean_pa - 150.0).abs() < 0.01);
        assert_eq!(late.voidage_map.value, all.voidage_map.value, "the maps keep the whole window");
    }

    /// Synthetic samples whose statistics are known: a bed of ε = 0.4 below 12 mm (ε = 1 above,
    /// a bubble of ε = 0.9 in the lower layers every 0.1 s), a pressure field whose bed drop is
    /// 100 + 10 sin(2π·5 t) Pa, particles moving up at v_z = 0.2 − 10 r² (m/s).
    #[test]
    fn a_run_of_known_samples_gives_its_mean_spread_frequency_bed_height_and_particle_map() {
        let (mut a, grid) = small_column(1e-5, 0.05, 0.002);
        let n = grid.num_cells();
        let (mut t, mut taken) = (0.0, 0);
        // Samples at 0.05, 0.052, … 1.048 s: 500 samples, five whole periods of the ΔP signal.
        for step in 1..=104_800u64 {
            t = step as f64 * 1e-5;
            if !a.due(step, t) {
                continue;
            }
            taken += 1;
            let bubble = (t * 10.0).fract() < 0.3;
            let eps: Vec<f64> = (0..n)
                .map(|c| match (grid.centre_xyz(c)[2], bubble) {
                    (z, _) if z > 0.012 => 1.0,
                    (z, true) if z < 0.006 => 0.9,
                    _ => 0.4,
                })
                .collect();
            let dp = 100.0 + 10.0 * (2.0 * PI * 5.0 * t).sin();
            let pos: Vec<[f64; 3]> = (0..n).map(|c| grid.centre_xyz(c)).collect();
            let vel: Vec<[f64; 3]> = pos.iter().map(|x| [0.0, 0.0, 0.2 - 10.0 * (x[0] * x[0] + x[1] * x[1])]).collect();
            add_sample(&mut a, &grid, t, &eps, dp, [&pos, &vel]);
        }
        let r = a.report(&grid);
        assert_eq!(r.samples, taken);
        assert!(
            (r.from_s - 0.05).abs() < 1e-9 && (r.to_s - t).abs() < 1e-9 && (r.sample_interval_s - 0.002).abs() < 1e-12
        );
        let dp = r.pressure_drop.as_ref().unwrap();
        assert!((dp.mean_pa - 100.0).abs() < 0.01, "mean {}", dp.mean_pa);
        assert!((dp.std_pa / (10.0 / 2f64.sqrt()) - 1.0).abs() < 0.01, "std {}", dp.std_pa);
        let f = dp.dominant_frequency_hz.unwrap();
        assert!((f - 5.0).abs() <= dp.spectrum.as_ref().unwrap().df_hz, "dominant {f} Hz");
        assert!((r.bed_height_m.unwrap() - 0.012).abs() < 1e-12, "bed height {:?}", r.bed_height_m);
        // Bubbles: 10 per second in the lower rise height (0.3 × 12 mm = 3.6 mm, inside the bubble zone).
        let b = r.bubbles.as_ref().unwrap();
        let rate = b.count.per_second;
        assert!((rate - 10.0).abs() < 0.5, "bubbles per second {rate}");
        // Particle velocity on the axial plane: the annulus means of 0.2 − 10 r² at the cell centres.
        for k in 0..grid.nz {
            for i in 0..grid.nr {
                let want: f64 = (0..grid.cells_in_annulus(i))
                    .map(|j| {
                        let x = grid.centre_xyz(grid.index(i, j, k));
                        0.2 - 10.0 * (x[0] * x[0] + x[1] * x[1])
                    })
                    .sum::<f64>()
                    / grid.cells_in_annulus(i) as f64;
                let got = r.particle_velocity_map.value[k * grid.nr + i];
                assert!((got - want).abs() < 1e-12, "({i}, {k}): {got} vs {want}");
            }
        }
        // The profile at half the bed height, 6 mm, is layer 3's.
        assert_eq!(r.radial_profiles.len(), 1);
        assert!((r.radial_profiles[0].height_m - 0.006).abs() < 1e-12);
    }

    /// Eruptions: a bed of ε = 0.4 below 12 mm whose top layers (the eruption height, 0.9 × 12 mm,
    /// among them) open to ε = 0.9 for 30 ms every 0.1 s from t = 0.1 s on, and a bed drop of
    /// 100 + 10 sin(2π·10 t) Pa. Ten eruptions per second, each at a ΔP phase of 0, so the
    /// triggered average is 10 sin(2π·10 τ): swing 20 Pa, and one ΔP cycle per eruption.
    #[test]
    fn eruptions_at_the_surface_are_counted_and_linked_to_the_pressure_drop() {
        // ΔP at the eruption rate (10 Hz) and at half of it (the paper's pair of eruptions per
        // ΔP period).
        for dp_hz in [10.0, 5.0] {
            eruptions_with_dp_at(dp_hz);
        }
    }

    fn eruptions_with_dp_at(dp_hz: f64) {
        let (mut a, grid) = small_column(1e-3, 0.05, 0.002);
        let n = grid.num_cells();
        let none: Vec<[f64; 3]> = vec![];
        for step in 0..=2050u64 {
            let t = step as f64 * 1e-3;
            if !a.due(step, t) {
                continue;
            }
            let open = (t * 10.0 + 1e-9).fract() < 0.3;
            let eps: Vec<f64> = (0..n)
                .map(|c| match grid.centre_xyz(c)[2] {
                    z if z > 0.012 => 1.0,
                    z if z > 0.008 && open => 0.9,
                    _ => 0.4,
                })
                .collect();
            let dp = 100.0 + 10.0 * (2.0 * PI * dp_hz * t).sin();
            add_sample(&mut a, &grid, t, &eps, dp, [&none, &none]);
        }
        let r = a.report(&grid);
        let e = r.eruptions.as_ref().expect("eruptions");
        assert!((e.fronts.height_m - 0.9 * 0.012).abs() < 1e-12, "height {}", e.fronts.height_m);
        // Fronts at 0.1, 0.2, … 2.0 s: 20 in a record of 2.0 s.
        let count = &e.fronts.count;
        assert_eq!(count.bubbles, 20, "{:?}", count.fronts_s);
        assert!((count.per_second - 10.0).abs() < 0.1, "{}", count.per_second);
        if dp_hz == 10.0 {
            assert!((e.link.swing_pa - 20.0).abs() < 0.2, "swing {}", e.link.swing_pa);
        }
        let want = dp_hz / 10.0;
        let ratio = e.dp_frequency_per_eruption.expect("ratio");
        assert!((ratio - want).abs() < 0.05 * want, "ΔP cycles per eruption {ratio}");
        // The surface drops from 12 to 8 mm for 0.03 s of every 0.1 s: 10 Hz.
        let surface = e.surface_frequency_hz.expect("surface frequency");
        assert!((surface / 10.0 - 1.0).abs() < 0.01, "surface {surface} Hz");
        let per_cycle = e.dp_frequency_per_surface_cycle.expect("per surface cycle");
        assert!((per_cycle / want - 1.0).abs() < 0.02, "ΔP cycles per surface cycle {per_cycle}");
    }
}
