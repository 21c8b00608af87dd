//! The payloads of a job's server-sent events (`GET /v1/jobs/{id}/events`): `status` and `end`
//! carry a `StatusEvent`, `progress` a `ProgressEvent`, `snapshot` (with `id: n`) a `SnapshotEvent`.

use crate::job::JobStatus;
use crate::snapshot::GridInfo;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// `status` and the final `end` event.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct StatusEvent {
    pub status: JobStatus,
    pub message: Option<String>,
}

/// `progress`: as in the job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct ProgressEvent {
    pub status: JobStatus,
    #[schema(minimum = 0.0, maximum = 1.0)]
    pub progress: f64,
    pub time_s: f64,
    pub end_time_s: f64,
    pub steps: u64,
    pub wall_time_s: f64,
    pub eta_s: Option<f64>,
}

/// `snapshot`: the grid, the cell voidage and pressure, total and per-layer ΔP.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct SnapshotEvent {
    pub n: u64,
    pub time_s: f64,
    pub step: u64,
    pub cells_per_layer: u64,
    pub nz: u64,
    pub grid: GridInfo,
    pub voidage: Option<Vec<f64>>,
    /// Absolute pressure per cell (Pa).
    pub pressure_pa: Option<Vec<f64>>,
    pub pressure_drop_pa: Option<f64>,
    pub layer_pressure_drop_pa: Option<Vec<f64>>,
    pub mean_particle_height_m: Option<f64>,
}

/// The events of a job's stream, each with its payload type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    Status,
    Progress,
    Snapshot,
    End,
}

impl EventKind {
    pub const ALL: [EventKind; 4] = [EventKind::Status, EventKind::Progress, EventKind::Snapshot, EventKind::End];

    /// The `event:` name.
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::Status => "status",
            EventKind::Progress => "progress",
            EventKind::Snapshot => "snapshot",
            EventKind::End => "end",
        }
    }
    /// The component schema of the `data:` JSON.
    pub fn payload_schema(self) -> &'static str {
        match self {
            EventKind::Status | EventKind::End => "StatusEvent",
            EventKind::Progress => "ProgressEvent",
            EventKind::Snapshot => "SnapshotEvent",
        }
    }
}

/// The component name of one event of the stream.
pub const STREAM_EVENT: &str = "JobStreamEvent";

/// The schema of one server-sent event of a job's stream (the SSE fields `event`, `data`, `id`,
/// as OpenAPI 3.2's `itemSchema` describes a stream), with each event's `data` tied to its payload
/// type through `contentMediaType` and `contentSchema`. Only `snapshot` events carry an `id`.
pub fn stream_event_schema() -> serde_json::Value {
    let one_of: Vec<serde_json::Value> = EventKind::ALL
        .iter()
        .map(|k| {
            let mut properties = serde_json::json!({
                "event": {"const": k.as_str()},
                "data": {
                    "type": "string",
                    "contentMediaType": "application/json",
                    "contentSchema": {"$ref": format!("#/components/schemas/{}", k.payload_schema())},
                },
            });
            let mut required = vec!["event", "data"];
            if *k == EventKind::Snapshot {
                properties["id"] = serde_json::json!({"type": "string", "pattern": "^[0-9]+$"});
                required.push("id");
            }
            serde_json::json!({"type": "object", "properties": properties, "required": required})
        })
        .collect();
    serde_json::json!({
        "description": "One server-sent event: `event` names it, `data` is its JSON payload, and a snapshot's `id` is its number (send it back as Last-Event-ID to resume).",
        "oneOf": one_of,
    })
}
