//! A job as the store keeps it, and its views in the API (fluidbed-api's `Job` and events).

use fluidbed_api::{CaseProblem, JobLinks, ProgressEvent, StatusEvent};
use fluidbed_core::case::Problem;
use serde_json::Value;

pub use fluidbed_api::{JobStatus as Status, SnapshotInfo};

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
    pub warnings: Vec<CaseProblem>,
    pub plan: Option<Value>,
    /// Wall seconds per stage since the job last (re)started.
    pub stage_seconds: Option<Value>,
    /// A DELETE was accepted: the job ends `cancelled` even across a restart.
    pub cancel_requested: bool,
    /// Starts not given back by a clean stop: how often this job went down with its server.
    pub attempts: u32,
}

impl Job {
    pub fn progress(&self) -> f64 {
        match self.status {
            Status::Succeeded => 1.0,
            _ if self.end_time_s > 0.0 => (self.time_s / self.end_time_s).clamp(0.0, 1.0),
            _ => 0.0,
        }
    }
    /// The job as `GET /v1/jobs/{id}` shows it.
    pub fn to_api(&self) -> fluidbed_api::Job {
        fluidbed_api::Job {
            id: self.id.clone(),
            name: self.name.clone(),
            status: self.status,
            created_at: self.created_at.clone(),
            started_at: self.started_at.clone(),
            finished_at: self.finished_at.clone(),
            progress: self.progress(),
            time_s: self.time_s,
            end_time_s: self.end_time_s,
            steps: self.steps,
            wall_time_s: self.wall_s,
            eta_s: self.eta_s,
            message: self.message.clone(),
            warnings: self.warnings.clone(),
            plan: self.plan.clone(),
            stage_seconds: self.stage_seconds.clone(),
            links: JobLinks::of(&self.id),
        }
    }
    /// The `progress` event's payload.
    pub fn progress_event(&self) -> ProgressEvent {
        ProgressEvent {
            status: self.status,
            progress: self.progress(),
            time_s: self.time_s,
            end_time_s: self.end_time_s,
            steps: self.steps,
            wall_time_s: self.wall_s,
            eta_s: self.eta_s,
        }
    }
    /// The `status` and `end` events' payload.
    pub fn status_event(&self) -> StatusEvent {
        StatusEvent { status: self.status, message: self.message.clone() }
    }
}

pub fn case_problems(p: &[Problem]) -> Vec<CaseProblem> {
    p.iter().map(CaseProblem::from).collect()
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
