//! A job as the API shows it: status, progress, times, warnings, plan.

use fluidbed_core::case::Problem;
use serde::Serialize;
use serde_json::{json, Value};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Queued,
    Running,
    Succeeded,
    Failed,
    Cancelled,
}

impl Status {
    pub const ALL: [Status; 5] =
        [Status::Queued, Status::Running, Status::Succeeded, Status::Failed, Status::Cancelled];

    pub fn as_str(self) -> &'static str {
        match self {
            Status::Queued => "queued",
            Status::Running => "running",
            Status::Succeeded => "succeeded",
            Status::Failed => "failed",
            Status::Cancelled => "cancelled",
        }
    }
    pub fn parse(s: &str) -> Option<Status> {
        Some(match s {
            "queued" => Status::Queued,
            "running" => Status::Running,
            "succeeded" => Status::Succeeded,
            "failed" => Status::Failed,
            "cancelled" => Status::Cancelled,
            _ => return None,
        })
    }
    pub fn is_final(self) -> bool {
        matches!(self, Status::Succeeded | Status::Failed | Status::Cancelled)
    }
}

#[derive(Clone, Debug)]
pub struct Job {
    pub id: String,
    pub name: String,
    pub status: Status,
    pub created_at: String,
    pub started_at: Option<String>,
    pub finished_at: Option<String>,
    pub time_s: f64,
    pub end_time_s: f64,
    pub steps: u64,
    pub wall_s: f64,
    pub eta_s: Option<f64>,
    pub message: Option<String>,
    pub warnings: Vec<Value>,
    pub plan: Option<Value>,
    /// A DELETE was accepted: the job ends `cancelled` even across a restart.
    pub cancel_requested: bool,
    /// Starts not given back by a clean stop: how often this job went down with its server.
    pub attempts: u32,
}

/// One row of a job's snapshot index.
#[derive(Clone, Debug, Serialize)]
pub struct SnapshotInfo {
    pub n: u64,
    pub time_s: f64,
    pub step: u64,
    pub pressure_drop_pa: Option<f64>,
    pub mean_particle_height_m: Option<f64>,
}

impl Job {
    pub fn progress(&self) -> f64 {
        match self.status {
            Status::Succeeded => 1.0,
            _ if self.end_time_s > 0.0 => (self.time_s / self.end_time_s).clamp(0.0, 1.0),
            _ => 0.0,
        }
    }
    pub fn to_json(&self) -> Value {
        json!({
            "id": self.id,
            "name": self.name,
            "status": self.status.as_str(),
            "created_at": self.created_at,
            "started_at": self.started_at,
            "finished_at": self.finished_at,
            "progress": self.progress(),
            "time_s": self.time_s,
            "end_time_s": self.end_time_s,
            "steps": self.steps,
            "wall_time_s": self.wall_s,
            "eta_s": self.eta_s,
            "message": self.message,
            "warnings": self.warnings,
            "plan": self.plan,
            "links": {
                "self": format!("/v1/jobs/{}", self.id),
                "events": format!("/v1/jobs/{}/events", self.id),
                "snapshots": format!("/v1/jobs/{}/snapshots", self.id),
                "pressure_drop": format!("/v1/jobs/{}/pressure-drop", self.id),
            },
        })
    }
    /// The `progress` event's payload.
    pub fn progress_json(&self) -> Value {
        json!({
            "status": self.status.as_str(),
            "progress": self.progress(),
            "time_s": self.time_s,
            "end_time_s": self.end_time_s,
            "steps": self.steps,
            "wall_time_s": self.wall_s,
            "eta_s": self.eta_s,
        })
    }
    pub fn status_json(&self) -> Value {
        json!({ "status": self.status.as_str(), "message": self.message })
    }
}

pub fn problems_json(p: &[Problem]) -> Vec<Value> {
    p.iter().map(|p| serde_json::to_value(p).unwrap_or(Value::Null)).collect()
}

/// A new job id: 16 random hex digits (never derived from user input, safe as a folder name).
pub fn new_id() -> String {
    format!("{:016x}", rand::random::<u64>())
}

/// Whether a string could be a job id; anything else is answered 404 before any lookup.
pub fn plausible_id(id: &str) -> bool {
    !id.is_empty() && id.len() <= 64 && id.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-')
}

/// Now as RFC 3339 UTC, e.g. 2024-05-01T12:00:00.123Z.
pub fn now_rfc3339() -> String {
    let d = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
    let secs = d.as_secs() as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (H. Hinnant, "chrono-Compatible Low-Level Date Algorithms").
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}.{:03}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60,
        d.subsec_millis()
    )
}
