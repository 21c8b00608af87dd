//! The query strings the API reads, as typed parameters (serde for the server and the client,
//! `IntoParams` for the OpenAPI document).

use crate::job::JobStatus;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};

/// Largest page of the job list.
pub const MAX_LIMIT: u64 = 500;
/// Offsets and event ids are stored as SQLite integers (i64).
pub const MAX_OFFSET: u64 = i64::MAX as u64;

/// `GET /v1/jobs`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ListQuery {
    /// Only jobs with this status.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(inline)]
    pub status: Option<JobStatus>,
    /// Page size (default 50).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(minimum = 1, maximum = 500)]
    pub limit: Option<u64>,
    /// Jobs to skip (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(minimum = 0, maximum = 9223372036854775807_i64)]
    pub offset: Option<u64>,
}

/// A page of a list without a filter (`GET /v1/sweeps`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct PageQuery {
    /// Page size (default 50).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(minimum = 1, maximum = 500)]
    pub limit: Option<u64>,
    /// Entries to skip (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(minimum = 0, maximum = 9223372036854775807_i64)]
    pub offset: Option<u64>,
}

/// How one snapshot is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SnapshotFormat {
    /// The whole snapshot (`SnapshotDocument`).
    Json,
    /// A float64 array of one field.
    Npy,
    /// Legacy ASCII VTK.
    Vtk,
    /// VTK XML unstructured grid of the cells.
    Vtu,
    /// VTK XML poly data of the particles.
    Vtp,
    /// A picture of the field on the axial plane.
    Png,
}

/// Which field of a snapshot (`voidage` by default).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SnapshotField {
    #[serde(alias = "cells")]
    Voidage,
    #[serde(alias = "pressure_pa")]
    Pressure,
    GasVelocity,
    Particles,
}

/// `GET /v1/jobs/{id}/snapshots/{n}`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct SnapshotQuery {
    /// The encoding (default json).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(inline)]
    pub format: Option<SnapshotFormat>,
    /// The field (default voidage; `npy`: voidage, pressure, gas_velocity, particles; `png`:
    /// voidage, pressure; `vtk`, `vtp`: particles or the cells).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(inline)]
    pub field: Option<SnapshotField>,
    /// Another name for `field`; it wins when both are given.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(inline)]
    pub what: Option<SnapshotField>,
}

impl SnapshotQuery {
    /// The field asked for: `what`, else `field`, else voidage.
    pub fn field(&self) -> SnapshotField {
        self.what.or(self.field).unwrap_or(SnapshotField::Voidage)
    }
}

/// How the pressure-drop series is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SeriesFormat {
    /// `PressureDropSeries`.
    Json,
    /// `time_s,pressure_drop_pa,mean_particle_height_m`, one row per snapshot.
    Csv,
    /// A plot of ΔP (or, without gas, the mean particle height) against time.
    Png,
}

/// `GET /v1/jobs/{id}/pressure-drop`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct SeriesQuery {
    /// The encoding (default json).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(inline)]
    pub format: Option<SeriesFormat>,
}

/// `GET /v1/jobs/{id}/analysis` and its figures.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct AnalysisQuery {
    /// Simulated time (s) from which the time-series statistics (ΔP, bubble count, rise velocity)
    /// are taken; the maps and profiles keep the whole accumulated window (default: all of it).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(minimum = 0)]
    pub from: Option<f64>,
}

/// The figures of `GET /v1/jobs/{id}/analysis/{figure}`, the server's and the client's one list.
pub const ANALYSIS_FIGURES: [&str; 5] = [
    "pressure_spectrum.png",
    "rise_correlation.png",
    "eruption_link.png",
    "particle_velocity_map.png",
    "voidage_map.png",
];

/// `GET /v1/jobs/{id}/events`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct EventsQuery {
    /// Replay only snapshots after this number (as the `Last-Event-ID` header; the header wins).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[param(pattern = r"^\s*[0-9]+\s*$")]
    pub last_event_id: Option<String>,
}
