//! Particle-based time averages on the fluid grid (Boyce, Holland, Scott & Dennis 2013, the
//! paper's MR comparison; PHYSICS.md §12): for cell c over samples s,
//!   ⟨q⟩_c = Σ_s Σ_{p ∈ c(s)} q_p / Σ_s N_c(s),
//! each particle found in the cell counting once per sample, so a cell seen with 1 fast particle
//! in a bubble and 9 slow ones in the emulsion averages to (q₁ + 9 q₂)/10, as an MR velocity
//! signal weighted by the particles present does, not to (q₁ + q₂)/2 as a mean of cell means.
//!
//! Velocities are kept in cylindrical components (v_r, v_θ, v_z) about the column axis, each at
//! the particle's own angle. Granular temperature (a bonus), per cell:
//! - `granular_temperature`, the usual DEM one: the fluctuation about the cell's mean velocity at
//!   the same sample, pooled over samples, T = Σ_s Σ_p |v_p − v̄_c(s)|² / (3 Σ_s (N_c(s) − 1));
//!   unbiased for independent particles;
//! - `granular_temperature_total`: about the cell's time-mean velocity,
//!   T = (⟨|v|²⟩ − |⟨v⟩|²)/3, which also holds the mean flow's unsteadiness (bubble passages).

use crate::grid::CylGrid;
use serde::{Deserialize, Serialize};

/// Sums over samples and the particles found in each cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParticleAverage {
    n_cells: usize,
    samples: u64,
    /// Σ_s N_c(s).
    count: Vec<u64>,
    /// Σ_s Σ_p (v_r, v_θ, v_z).
    sum_v: Vec<[f64; 3]>,
    /// Σ_s Σ_p |v|².
    sum_v2: Vec<f64>,
    /// Σ_s Σ_p |v_p − v̄_c(s)|² and Σ_s (N_c(s) − 1) over visits with N_c(s) ≥ 1.
    sum_dev2: Vec<f64>,
    dof: Vec<u64>,
}

/// The per-cell averages (cell order of the grid). Cells never visited hold NaN.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParticleMeans {
    pub samples: u64,
    /// Σ_s N_c(s): the weight of each cell's average (for particle-based profiles).
    pub count: Vec<u64>,
    /// Mean particles per sample, Σ_s N_c(s) / samples.
    pub mean_count: Vec<f64>,
    /// ⟨(v_r, v_θ, v_z)⟩_c, m/s.
    pub velocity: Vec<[f64; 3]>,
    /// m²/s² (NaN where no visit had two particles).
    pub granular_temperature: Vec<f64>,
    pub granular_temperature_total: Vec<f64>,
}

impl ParticleMeans {
    /// Vertical particle velocity per cell.
    pub fn vz(&self) -> Vec<f64> {
        self.velocity.iter().map(|v| v[2]).collect()
    }
    /// Particle-centre solid fraction φ_c = ⟨N_c⟩ V_p / V_cell (counts centres, so it is coarse
    /// at the wall and the bed surface; the voidage field's `FieldAverage` is the smooth one).
    pub fn solid_fraction(&self, particle_volume: f64, cell_volume: f64) -> Vec<f64> {
        self.mean_count.iter().map(|n| n * particle_volume / cell_volume).collect()
    }
    /// Counts as f64 weights for `radial_profile` / `axial_map`.
    pub fn weights(&self) -> Vec<f64> {
        self.count.iter().map(|&c| c as f64).collect()
    }
}

/// (v_r, v_θ, v_z) of velocity `v` at position `x` (on the axis, r̂ = x̂).
fn cylindrical(x: &[f64; 3], v: &[f64; 3]) -> [f64; 3] {
    let r = x[0].hypot(x[1]);
    let (c, s) = if r > 0.0 { (x[0] / r, x[1] / r) } else { (1.0, 0.0) };
    [c * v[0] + s * v[1], -s * v[0] + c * v[1], v[2]]
}

impl ParticleAverage {
    pub fn new(grid: &CylGrid) -> ParticleAverage {
        let n = grid.num_cells();
        ParticleAverage {
            n_cells: n,
            samples: 0,
            count: vec![0; n],
            sum_v: vec![[0.0; 3]; n],
            sum_v2: vec![0.0; n],
            sum_dev2: vec![0.0; n],
            dof: vec![0; n],
        }
    }

    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// One sample: every particle (centre `positions[p]`, velocity `velocities[p]`, Cartesian) is
    /// put in the cell holding its centre (`CylGrid::locate`; centres beyond the wall go to the
    /// outer annulus, above the top to the top layer). O(particles + cells).
    pub fn add_sample(&mut self, grid: &CylGrid, positions: &[[f64; 3]], velocities: &[[f64; 3]]) {
        assert_eq!(grid.num_cells(), self.n_cells, "ParticleAverage: another grid");
        assert_eq!(positions.len(), velocities.len(), "ParticleAverage: positions and velocities");
        // This sample's sums per cell, for the fluctuation about its own cell means.
        let mut n = vec![0u32; self.n_cells];
        let mut sv = vec![[0.0f64; 3]; self.n_cells];
        let mut sv2 = vec![0.0f64; self.n_cells];
        for (x, v) in positions.iter().zip(velocities) {
            let c = grid.locate(x[0], x[1], x[2]);
            let w = cylindrical(x, v);
            n[c] += 1;
            for d in 0..3 {
                sv[c][d] += w[d];
            }
            sv2[c] += w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        }
        for c in 0..self.n_cells {
            if n[c] == 0 {
                continue;
            }
            let nc = n[c] as f64;
            let s = sv[c];
            self.count[c] += n[c] as u64;
            for (a, b) in self.sum_v[c].iter_mut().zip(s) {
                *a += b;
            }
            self.sum_v2[c] += sv2[c];
            // Σ_p |v_p − v̄|² = Σ|v|² − |Σv|²/N (≥ 0 up to rounding).
            self.sum_dev2[c] += (sv2[c] - (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) / nc).max(0.0);
            self.dof[c] += n[c] as u64 - 1;
        }
        self.samples += 1;
    }

    /// The averages so far (the accumulator is kept, so a run can report and go on).
    pub fn finish(&self) -> ParticleMeans {
        let samples = self.samples.max(1) as f64;
        let mut velocity = vec![[f64::NAN; 3]; self.n_cells];
        let mut t_total = vec![f64::NAN; self.n_cells];
        let mut t_inst = vec![f64::NAN; self.n_cells];
        for c in 0..self.n_cells {
            if self.count[c] > 0 {
                let n = self.count[c] as f64;
                let m = self.sum_v[c].map(|s| s / n);
                velocity[c] = m;
                t_total[c] = ((self.sum_v2[c] / n - (m[0] * m[0] + m[1] * m[1] + m[2] * m[2])) / 3.0).max(0.0);
            }
            if self.dof[c] > 0 {
                t_inst[c] = self.sum_dev2[c] / (3.0 * self.dof[c] as f64);
            }
        }
        ParticleMeans {
            samples: self.samples,
            count: self.count.clone(),
            mean_count: self.count.iter().map(|&c| c as f64 / samples).collect(),
            velocity,
            granular_temperature: t_inst,
            granular_temperature_total: t_total,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::profiles::radial_profile;
    use crate::analysis::test_signals::Noise;
    use std::f64::consts::PI;

    /// A point uniform in the disc of radius R at height z.
    fn in_disc(noise: &mut Noise, radius: f64, z: f64) -> ([f64; 3], f64) {
        let r = radius * noise.uniform().sqrt();
        let th = 2.0 * PI * noise.uniform();
        ([r * th.cos(), r * th.sin(), z], r)
    }

    #[test]
    fn particles_weigh_by_count_not_by_cell() {
        // One cell; sample 1 holds 1 particle at +1 m/s, sample 2 nine at −0.1 m/s:
        // particle-based (1 − 0.9)/10 = 0.01 m/s (a mean of cell means would say 0.45).
        let g = CylGrid::new(0.01, 0.01, 0.01, 0.01, 1);
        let mut pa = ParticleAverage::new(&g);
        pa.add_sample(&g, &[[0.001, 0.0, 0.005]], &[[0.0, 0.0, 1.0]]);
        pa.add_sample(&g, &[[0.0, 0.002, 0.005]; 9], &[[0.0, 0.0, -0.1]; 9]);
        let m = pa.finish();
        assert_eq!(m.count, vec![10]);
        assert!((m.mean_count[0] - 5.0).abs() < 1e-12);
        assert!((m.vz()[0] - 0.01).abs() < 1e-12, "{}", m.vz()[0]);
        // No spread inside either sample; about the time mean: (1·0.99² + 9·0.11²)/10/3.
        assert!(m.granular_temperature[0].abs() < 1e-12);
        let want = (0.99f64.powi(2) + 9.0 * 0.11f64.powi(2)) / 10.0 / 3.0;
        assert!((m.granular_temperature_total[0] - want).abs() < 1e-12);
    }

    #[test]
    fn a_circulating_field_averages_to_its_analytic_annulus_means() {
        // v_z = V0 (1 − 2r²/R²) + A sin(2π s/8) + noise (upflow at the axis, downflow at the wall,
        // zero net flux), v_θ = Ω r, v_r = noise, over whole periods of 8 samples. For centres
        // uniform in area, the annulus [r₀, r₁] means are V0 (1 − (r₀² + r₁²)/R²) and
        // Ω · 2(r₁³ − r₀³)/(3(r₁² − r₀²)); the oscillation averages out.
        let (radius, v0, a, omega, sigma) = (0.02, 0.1, 0.05, 3.0, 0.02);
        let g = CylGrid::new(radius, 0.02, 0.004, 0.01, 2);
        let mut pa = ParticleAverage::new(&g);
        let mut noise = Noise::new(21);
        for s in 0..400 {
            let osc = a * (2.0 * PI * s as f64 / 8.0).sin();
            let (mut xs, mut vs) = (vec![], vec![]);
            for _ in 0..2000 {
                let z = 0.02 * noise.uniform();
                let (x, r) = in_disc(&mut noise, radius, z);
                let (c, sn) = (x[0] / r, x[1] / r);
                let (vr, vt) = (sigma * noise.gauss(), omega * r);
                let vz = v0 * (1.0 - 2.0 * r * r / (radius * radius)) + osc + sigma * noise.gauss();
                xs.push(x);
                vs.push([c * vr - sn * vt, sn * vr + c * vt, vz]);
            }
            pa.add_sample(&g, &xs, &vs);
        }
        let m = pa.finish();
        let w = m.weights();
        let vz = radial_profile(&g, &m.vz(), Some(&w), 0.0, 0.02);
        let vt: Vec<f64> = m.velocity.iter().map(|v| v[1]).collect();
        let vt = radial_profile(&g, &vt, Some(&w), 0.0, 0.02);
        for i in 0..g.nr {
            let (r0, r1) = (i as f64 * g.dr, (i + 1) as f64 * g.dr);
            let want_z = v0 * (1.0 - (r0 * r0 + r1 * r1) / (radius * radius));
            let want_t = omega * 2.0 * (r1.powi(3) - r0.powi(3)) / (3.0 * (r1 * r1 - r0 * r0));
            // Four standard errors of the annulus's visits (≈ 8·10⁵ (2i + 1)/25), with a spread per
            // visit below √(σ² + A²/2 + (0.72 V0)²/12) < 0.05 m/s for v_z and Ω dr for v_θ.
            let visits = vz.weight[i];
            let (tol_z, tol_t) = (4.0 * 0.05 / visits.sqrt(), 4.0 * omega * g.dr / visits.sqrt());
            assert!((vz.value[i] - want_z).abs() < tol_z, "annulus {i}: v_z {} vs {want_z}", vz.value[i]);
            assert!((vt.value[i] - want_t).abs() < tol_t, "annulus {i}: v_θ {} vs {want_t}", vt.value[i]);
        }
    }

    #[test]
    fn granular_temperature_is_the_noise_variance_and_the_total_adds_the_mean_flow_swing() {
        // Every particle: v = U + A sin(2π s/4) ẑ + σ·N(0, 1) per component. Within a sample the
        // swing is common, so T = σ²; about the time mean, T_total = σ² + A²/6 (|swing|² = A²/2
        // over whole periods, a third per component), less σ²/N_c of the 1/N form.
        let (sigma, a) = (0.05, 0.2);
        let g = CylGrid::new(0.01, 0.01, 0.01, 0.01, 1);
        let mut pa = ParticleAverage::new(&g);
        let mut noise = Noise::new(8);
        for s in 0..2000 {
            let swing = a * (2.0 * PI * s as f64 / 4.0).sin();
            let xs = vec![[0.002, 0.001, 0.005]; 50];
            let vs: Vec<[f64; 3]> = (0..50)
                .map(|_| [0.1 + sigma * noise.gauss(), sigma * noise.gauss(), 0.3 + swing + sigma * noise.gauss()])
                .collect();
            pa.add_sample(&g, &xs, &vs);
        }
        let m = pa.finish();
        // 3·2000·49 deviates: relative standard error of σ² ≈ √(2/294000) = 0.26%.
        assert!((m.granular_temperature[0] / (sigma * sigma) - 1.0).abs() < 0.013, "{}", m.granular_temperature[0]);
        let want = sigma * sigma + a * a / 6.0;
        assert!((m.granular_temperature_total[0] / want - 1.0).abs() < 0.01, "{}", m.granular_temperature_total[0]);
        assert!((m.vz()[0] - 0.3).abs() < 1e-3);
        let back: ParticleAverage = serde_json::from_str(&serde_json::to_string(&pa).unwrap()).unwrap();
        assert_eq!(back, pa);
    }

    #[test]
    fn count_solid_fraction_is_particles_per_cell_times_volume_ratio() {
        let g = CylGrid::new(0.01, 0.02, 0.01, 0.01, 1);
        let mut pa = ParticleAverage::new(&g);
        // Layer 0 holds 30 centres in sample 1 and 10 in sample 2; layer 1 none.
        pa.add_sample(&g, &[[0.0, 0.0, 0.004]; 30], &[[0.0; 3]; 30]);
        pa.add_sample(&g, &[[0.0, 0.0, 0.004]; 10], &[[0.0; 3]; 10]);
        let (vp, vc) = (PI / 6.0 * 1.2e-3f64.powi(3), g.cell_volume());
        let phi = pa.finish().solid_fraction(vp, vc);
        assert!((phi[0] - 20.0 * vp / vc).abs() < 1e-15);
        assert_eq!(phi[1], 0.0);
        assert!(pa.finish().vz()[1].is_nan());
    }
}
