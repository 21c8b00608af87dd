//! Time averages of the cell fields: voidage ⟨ε⟩, solid fraction 1 − ⟨ε⟩, the gas velocity ⟨u⟩
//! and its gas-weighted (Favre) form ⟨ε u⟩/⟨ε⟩, the gas counterpart of the particle-based
//! average (each cell's gas counts by how much gas it holds, as ε u is the superficial flux).

use serde::{Deserialize, Serialize};

/// Sums of the cell fields over samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldAverage {
    n_cells: usize,
    samples: u64,
    sum_eps: Vec<f64>,
    /// Samples that had a gas velocity, and Σε, Σu, Σεu over those.
    gas_samples: u64,
    sum_eps_gas: Vec<f64>,
    sum_u: Vec<[f64; 3]>,
    sum_eps_u: Vec<[f64; 3]>,
}

/// Per-cell time averages (cell order of the grid).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldMeans {
    pub samples: u64,
    pub voidage: Vec<f64>,
    pub solid_fraction: Vec<f64>,
    pub gas_samples: u64,
    /// ⟨u⟩ in the components given (the snapshot's are cylindrical (U_r, U_θ, U_z)); `None`
    /// without gas samples.
    pub gas_velocity: Option<Vec<[f64; 3]>>,
    /// ⟨ε u⟩/⟨ε⟩ over the gas samples.
    pub gas_velocity_gas_weighted: Option<Vec<[f64; 3]>>,
}

impl FieldAverage {
    pub fn new(n_cells: usize) -> FieldAverage {
        FieldAverage {
            n_cells,
            samples: 0,
            sum_eps: vec![0.0; n_cells],
            gas_samples: 0,
            sum_eps_gas: vec![0.0; n_cells],
            sum_u: vec![[0.0; 3]; n_cells],
            sum_eps_u: vec![[0.0; 3]; n_cells],
        }
    }

    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// One sample of the voidage field and, for gas runs, the gas velocity at the cells.
    pub fn add_sample(&mut self, voidage: &[f64], gas_velocity: Option<&[[f64; 3]]>) {
        assert_eq!(voidage.len(), self.n_cells, "FieldAverage: voidage size");
        for (s, e) in self.sum_eps.iter_mut().zip(voidage) {
            *s += e;
        }
        if let Some(u) = gas_velocity {
            assert_eq!(u.len(), self.n_cells, "FieldAverage: gas velocity size");
            for c in 0..self.n_cells {
                let e = voidage[c];
                self.sum_eps_gas[c] += e;
                for ((su, seu), uc) in self.sum_u[c].iter_mut().zip(self.sum_eps_u[c].iter_mut()).zip(u[c]) {
                    *su += uc;
                    *seu += e * uc;
                }
            }
            self.gas_samples += 1;
        }
        self.samples += 1;
    }

    /// The averages so far (NaN voidage before any sample).
    pub fn finish(&self) -> FieldMeans {
        let n = self.samples as f64;
        let voidage: Vec<f64> = self.sum_eps.iter().map(|s| if self.samples > 0 { s / n } else { f64::NAN }).collect();
        let ng = self.gas_samples as f64;
        let (gas_velocity, gas_velocity_gas_weighted) = if self.gas_samples > 0 {
            let u = self.sum_u.iter().map(|s| s.map(|v| v / ng)).collect();
            let uw = self.sum_eps_u.iter().zip(&self.sum_eps_gas).map(|(s, e)| s.map(|v| v / e)).collect();
            (Some(u), Some(uw))
        } else {
            (None, None)
        };
        FieldMeans {
            samples: self.samples,
            solid_fraction: voidage.iter().map(|e| 1.0 - e).collect(),
            voidage,
            gas_samples: self.gas_samples,
            gas_velocity,
            gas_velocity_gas_weighted,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn oscillating_fields_average_to_their_offsets_and_the_flux_weighting_adds_the_covariance() {
        // Over whole periods: ε = ε0 + a sin φ, u_z = U0 + b sin φ give ⟨ε⟩ = ε0, ⟨u_z⟩ = U0 and
        // ⟨ε u_z⟩/⟨ε⟩ = U0 + a b /(2 ε0) (the bubbles, where ε is high, carry the fast gas).
        let (e0, a, u0, b) = (0.6, 0.3, 0.5, 1.0);
        let mut fa = FieldAverage::new(2);
        for s in 0..40 {
            let ph = (2.0 * PI * s as f64 / 10.0).sin();
            let eps = [e0 + a * ph, 0.4];
            fa.add_sample(&eps, Some(&[[0.0, 0.0, u0 + b * ph], [0.1, 0.0, -0.2]]));
        }
        fa.add_sample(&[0.6, 0.4], None);
        let m = fa.finish();
        assert_eq!((m.samples, m.gas_samples), (41, 40));
        assert!((m.voidage[0] - e0).abs() < 1e-12 && (m.solid_fraction[1] - 0.6).abs() < 1e-12);
        let u = m.gas_velocity.unwrap();
        assert!((u[0][2] - u0).abs() < 1e-12 && (u[1][0] - 0.1).abs() < 1e-12);
        let uw = m.gas_velocity_gas_weighted.unwrap();
        assert!((uw[0][2] - (u0 + a * b / (2.0 * e0))).abs() < 1e-12, "{}", uw[0][2]);
        assert!((uw[1][2] + 0.2).abs() < 1e-12);
    }

    #[test]
    fn without_gas_there_is_no_gas_velocity() {
        let mut fa = FieldAverage::new(1);
        fa.add_sample(&[0.5], None);
        let m = fa.finish();
        assert!(m.gas_velocity.is_none() && m.gas_velocity_gas_weighted.is_none());
        let back: FieldAverage = serde_json::from_str(&serde_json::to_string(&fa).unwrap()).unwrap();
        assert_eq!(back, fa);
    }
}
