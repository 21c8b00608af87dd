//! A sweep: one base case and the values to set in it, one job per point (`POST /v1/sweeps`),
//! and the sweep as `GET /v1/sweeps/{id}` shows it, with each finished point's summary.

use crate::job::JobStatus;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use utoipa::ToSchema;

/// One axis of a grid: a JSON pointer into the base case and the values it takes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GridAxis {
    /// RFC 6901 pointer into the case, e.g. `/gas/superficial_velocity_m_s`.
    #[schema(example = "/gas/superficial_velocity_m_s")]
    pub pointer: String,
    /// The values, in order (at least one).
    #[schema(value_type = Vec<Object>)]
    pub values: Vec<Value>,
}

/// `POST /v1/sweeps`: the base case and either a grid (every combination, the first axis
/// slowest) or a list of points (each a map from JSON pointer to value).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepRequest {
    /// Shown in the sweep list (default: the base case's name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// A case (see `/v1/schema/case`); each point's values are set in a copy of it.
    #[schema(value_type = Object)]
    pub base: Value,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<Vec<GridAxis>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<Vec<Object>>)]
    pub points: Option<Vec<Map<String, Value>>>,
}

/// What a finished point gave: the pressure drop over the second half of its run (snapshots
/// with t ≥ end_time_s / 2), read from its snapshot index.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct PointSummary {
    /// The point's inlet superficial velocity (m/s; null for a case without gas).
    pub superficial_velocity_m_s: Option<f64>,
    pub from_s: f64,
    pub to_s: f64,
    /// Snapshots in the window.
    pub samples: u64,
    pub pressure_drop_mean_pa: Option<f64>,
    pub pressure_drop_std_pa: Option<f64>,
    /// Mean particle height over the window (m): the bed's expansion.
    pub mean_particle_height_m: Option<f64>,
}

/// One point of a sweep: the values set, its job, and (once the job succeeded) its summary.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct SweepPoint {
    pub index: u64,
    /// Pointer → value, as set in the base case.
    #[schema(value_type = Object)]
    pub set: Map<String, Value>,
    pub job: String,
    pub status: JobStatus,
    #[schema(minimum = 0.0, maximum = 1.0)]
    pub progress: f64,
    pub message: Option<String>,
    pub summary: Option<PointSummary>,
}

/// A sweep and its points. `status` is `queued` until a point starts, `running` until every
/// point ended, then `succeeded` if every point did, else `failed` (or `cancelled` when all of
/// the unsuccessful points were cancelled).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct Sweep {
    #[schema(example = "5f0c2a9e41d7b388")]
    pub id: String,
    pub name: String,
    #[schema(format = DateTime)]
    pub created_at: String,
    pub status: JobStatus,
    /// Mean progress of the points, 0 to 1.
    #[schema(minimum = 0.0, maximum = 1.0)]
    pub progress: f64,
    pub points: Vec<SweepPoint>,
}

/// One page of the sweep list, newest first (points without summaries).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct SweepList {
    pub sweeps: Vec<Sweep>,
    pub total: u64,
    pub limit: u64,
    pub offset: u64,
    pub next_offset: Option<u64>,
}

impl Sweep {
    /// The sweep's status from its points' (see `Sweep`).
    pub fn status_of(points: &[JobStatus]) -> JobStatus {
        use JobStatus::*;
        if points.iter().all(|s| *s == Queued) {
            Queued
        } else if points.iter().any(|s| !s.is_final()) {
            Running
        } else if points.iter().all(|s| *s == Succeeded) {
            Succeeded
        } else if points.iter().all(|s| matches!(s, Succeeded | Cancelled)) {
            Cancelled
        } else {
            Failed
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use JobStatus::*;

    #[test]
    fn a_sweep_is_running_until_every_point_ended() {
        assert_eq!(Sweep::status_of(&[Queued, Queued]), Queued);
        assert_eq!(Sweep::status_of(&[Succeeded, Queued]), Running);
        assert_eq!(Sweep::status_of(&[Succeeded, Succeeded]), Succeeded);
        assert_eq!(Sweep::status_of(&[Succeeded, Cancelled]), Cancelled);
        assert_eq!(Sweep::status_of(&[Failed, Cancelled]), Failed);
    }
}
