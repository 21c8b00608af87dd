//! Snapshots as the API shows them: the index of a job's snapshots, one snapshot as JSON
//! (`format=json`), and the pressure-drop series.

use fluidbed_core::sim::snapshot as core;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// A downloaded file (npy, PNG): its bytes.
#[derive(ToSchema)]
#[schema(value_type = String, format = Binary)]
pub struct Binary(pub Vec<u8>);

/// One row of a job's snapshot index.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct SnapshotInfo {
    /// The snapshot number, 0, 1, 2, … in the order taken.
    pub n: u64,
    pub time_s: f64,
    pub step: u64,
    /// Bed pressure drop, bottom layer to top layer (Pa); null without gas.
    pub pressure_drop_pa: Option<f64>,
    /// Mean particle-centre height (m); null without particles.
    pub mean_particle_height_m: Option<f64>,
}

/// `GET /v1/jobs/{id}/snapshots`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct SnapshotList {
    pub snapshots: Vec<SnapshotInfo>,
}

/// `GET /v1/jobs/{id}/pressure-drop?format=json`: one entry per snapshot in each array.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct PressureDropSeries {
    pub time_s: Vec<f64>,
    /// Null entries for runs without gas.
    pub pressure_drop_pa: Vec<Option<f64>>,
    pub mean_particle_height_m: Vec<Option<f64>>,
}

/// The fluid grid's shape: equal-volume cylindrical cells, annulus i holding n0·(2i+1) cells.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct GridInfo {
    pub radius_m: f64,
    pub height_m: f64,
    pub dr_m: f64,
    pub dz_m: f64,
    pub n0: u64,
    pub nr: u64,
    pub nz: u64,
    pub num_cells: u64,
    pub cell_volume_m3: f64,
}

impl From<&core::GridInfo> for GridInfo {
    fn from(g: &core::GridInfo) -> GridInfo {
        GridInfo {
            radius_m: g.radius_m,
            height_m: g.height_m,
            dr_m: g.dr_m,
            dz_m: g.dz_m,
            n0: g.n0 as u64,
            nr: g.nr as u64,
            nz: g.nz as u64,
            num_cells: g.num_cells as u64,
            cell_volume_m3: g.cell_volume_m3,
        }
    }
}

/// Particle state in particle-id order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct ParticleState {
    pub radius_m: f64,
    /// x, y, z per particle (m).
    pub positions_m: Vec<[f64; 3]>,
    /// vx, vy, vz per particle (m/s).
    pub velocities_m_s: Vec<[f64; 3]>,
}

/// One snapshot as JSON. Cell fields are in grid order (within a layer annulus by annulus,
/// starting at n0·i²; layers bottom to top).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct SnapshotDocument {
    pub index: u64,
    pub time_s: f64,
    pub step: u64,
    pub grid: GridInfo,
    /// Gas voidage per cell (from the particles by the direct method when only they were stored).
    pub voidage: Option<Vec<f64>>,
    /// Absolute gas pressure per cell (Pa); gas runs only.
    pub pressure_pa: Option<Vec<f64>>,
    /// Interstitial gas velocity (U_r, U_θ, U_z) per cell (m/s).
    pub gas_velocity_m_s: Option<Vec<[f64; 3]>>,
    /// Bottom-layer mean minus top-layer mean pressure (Pa).
    pub pressure_drop_pa: Option<f64>,
    /// Layer k's mean pressure minus layer k+1's (Pa), nz − 1 values.
    pub layer_pressure_drop_pa: Option<Vec<f64>>,
    pub particles: Option<ParticleState>,
}

impl SnapshotDocument {
    /// The snapshot with its voidage (stored, or computed from the particles).
    pub fn of(s: &core::Snapshot) -> SnapshotDocument {
        SnapshotDocument {
            index: s.index,
            time_s: s.time_s,
            step: s.step,
            grid: GridInfo::from(&s.grid),
            voidage: fluidbed_core::output::fields::voidage(s),
            pressure_pa: s.pressure_pa.clone(),
            gas_velocity_m_s: s.gas_velocity_m_s.clone(),
            pressure_drop_pa: s.pressure_drop_pa,
            layer_pressure_drop_pa: s.layer_pressure_drop_pa.clone(),
            particles: s.particles.as_ref().map(|p| ParticleState {
                radius_m: p.radius_m,
                positions_m: p.positions_m.clone(),
                velocities_m_s: p.velocities_m_s.clone(),
            }),
        }
    }
}
