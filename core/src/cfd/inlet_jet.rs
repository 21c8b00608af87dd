//! A jet through the distributor (case `gas.inlet_jet`): over a time window the inlet cells of the
//! grid's inner annuli blow at their own superficial velocity, the others at the bed's. Used for a
//! single injected bubble (a bed at U_mf with a short jet, as Kuipers et al. 1992 did) or a
//! distributor that is not uniform. The same ramp from zero applies to both velocities.

use crate::grid::CylGrid;

/// The jet as the gas solver's inlet reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InletJet {
    /// Inlet cells in the jet: the first `cells` of the bottom layer (annuli 0..n hold n0·n² cells).
    pub cells: usize,
    pub superficial_velocity: f64,
    pub from: f64,
    pub until: f64,
}

impl InletJet {
    pub fn new(spec: &crate::case::InletJet, grid: &CylGrid) -> InletJet {
        let annuli = spec.annuli.min(grid.nr);
        InletJet {
            cells: (0..annuli).map(|i| grid.cells_in_annulus(i)).sum(),
            superficial_velocity: spec.superficial_velocity_m_s,
            from: spec.from_s,
            until: spec.until_s.unwrap_or(f64::INFINITY),
        }
    }

    /// Superficial velocity (before the ramp) of inlet cell `c` at time `t`, the bed's `u_bed`
    /// outside the jet or its window.
    #[inline]
    pub fn velocity(&self, c: usize, t: f64, u_bed: f64) -> f64 {
        if c < self.cells && t >= self.from && t < self.until {
            self.superficial_velocity
        } else {
            u_bed
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_jet_covers_whole_inner_annuli_inside_its_window() {
        // 3 annuli of n0 = 3: 3, 9 and 15 cells per annulus.
        let grid = CylGrid::new(0.015, 0.01, 0.005, 0.005, 3);
        let spec = crate::case::InletJet { annuli: 2, superficial_velocity_m_s: 4.0, from_s: 0.1, until_s: Some(0.2) };
        let jet = InletJet::new(&spec, &grid);
        assert_eq!(jet.cells, 12);
        assert_eq!(jet.velocity(11, 0.15, 0.3), 4.0);
        assert_eq!(jet.velocity(12, 0.15, 0.3), 0.3);
        assert_eq!(jet.velocity(0, 0.05, 0.3), 0.3);
        assert_eq!(jet.velocity(0, 0.2, 0.3), 0.3);
        let open = crate::case::InletJet { until_s: None, ..spec };
        assert_eq!(InletJet::new(&open, &grid).velocity(0, 1e6, 0.3), 4.0);
    }
}
