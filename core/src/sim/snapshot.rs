//! What a run reports at each snapshot interval. The solver never knows who listens: the
//! server's sink stores and broadcasts, a test's sink collects.

use crate::grid::CylGrid;
use serde::{Deserialize, Serialize};

/// The fluid grid's shape, enough to rebuild it (`CylGrid::new`) for field output.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GridInfo {
    pub radius_m: f64,
    pub height_m: f64,
    pub dr_m: f64,
    pub dz_m: f64,
    pub n0: usize,
    pub nr: usize,
    pub nz: usize,
    pub num_cells: usize,
    pub cell_volume_m3: f64,
}

impl GridInfo {
    pub fn of(g: &CylGrid) -> GridInfo {
        GridInfo {
            radius_m: g.radius,
            height_m: g.height,
            dr_m: g.dr,
            dz_m: g.dz,
            n0: g.n0,
            nr: g.nr,
            nz: g.nz,
            num_cells: g.num_cells(),
            cell_volume_m3: g.cell_volume(),
        }
    }
    pub fn grid(&self) -> CylGrid {
        CylGrid::new(self.radius_m, self.height_m, self.dr_m, self.dz_m, self.n0)
    }
}

/// Particle state in the original particle order (sorted by id).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ParticleSnapshot {
    pub radius_m: f64,
    pub positions_m: Vec<[f64; 3]>,
    pub velocities_m_s: Vec<[f64; 3]>,
}

/// One snapshot. Cell fields are indexed like `CylGrid::index(i, j, k)`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Snapshot {
    /// 0, 1, 2, ... in the order taken.
    pub index: u64,
    pub time_s: f64,
    pub step: u64,
    pub grid: GridInfo,
    /// Gas voidage per fluid cell (present when requested; also for DEM-only runs).
    pub voidage: Option<Vec<f64>>,
    /// Absolute gas pressure per fluid cell (gas runs only).
    pub pressure_pa: Option<Vec<f64>>,
    /// Interstitial gas velocity per cell, cylindrical (U_r, U_θ, U_z).
    pub gas_velocity_m_s: Option<Vec<[f64; 3]>>,
    /// Pressure drop from the bottom layer to the top layer (layer means), gas runs only.
    pub pressure_drop_pa: Option<f64>,
    /// Mean pressure of layer k minus that of layer k+1, per layer boundary (nz − 1 values).
    pub layer_pressure_drop_pa: Option<Vec<f64>>,
    pub particles: Option<ParticleSnapshot>,
}

impl Snapshot {
    /// The first NaN or ∞ in any field, named with its field and cell or particle (None when all
    /// values are finite). O(cells + particles); the simulation checks every snapshot it makes.
    pub fn first_non_finite(&self) -> Option<String> {
        fn scalars(name: &str, what: &str, v: Option<&[f64]>) -> Option<String> {
            let (k, x) = v?.iter().enumerate().find(|(_, x)| !x.is_finite())?;
            Some(format!("{name} = {x} at {what} {k}"))
        }
        fn vectors(name: &str, what: &str, v: Option<&[[f64; 3]]>) -> Option<String> {
            let (k, x) = v?.iter().enumerate().find(|(_, x)| !x.iter().all(|c| c.is_finite()))?;
            Some(format!("{name} = {x:?} at {what} {k}"))
        }
        let p = self.particles.as_ref();
        scalars("voidage", "cell", self.voidage.as_deref())
            .or_else(|| scalars("pressure", "cell", self.pressure_pa.as_deref()))
            .or_else(|| vectors("gas velocity", "cell", self.gas_velocity_m_s.as_deref()))
            .or_else(|| scalars("pressure drop", "snapshot", self.pressure_drop_pa.as_ref().map(std::slice::from_ref)))
            .or_else(|| scalars("layer pressure drop", "layer boundary", self.layer_pressure_drop_pa.as_deref()))
            .or_else(|| vectors("position", "particle", p.map(|p| &p.positions_m[..])))
            .or_else(|| vectors("velocity", "particle", p.map(|p| &p.velocities_m_s[..])))
            .or_else(|| (!self.time_s.is_finite()).then(|| format!("time = {}", self.time_s)))
    }
}

/// Receives snapshots as a run produces them.
pub trait SnapshotSink {
    fn snapshot(&mut self, s: &Snapshot);
}

impl SnapshotSink for Vec<Snapshot> {
    fn snapshot(&mut self, s: &Snapshot) {
        self.push(s.clone());
    }
}
