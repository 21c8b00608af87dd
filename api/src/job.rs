//! A job as the API shows it (`GET /v1/jobs/{id}`, the answer to POST and DELETE), its status,
//! the case's warnings, and a page of the job list.

use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

/// Where a job is in its life; the last three are final.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JobStatus {
    Queued,
    Running,
    Succeeded,
    Failed,
    Cancelled,
}

impl JobStatus {
    pub const ALL: [JobStatus; 5] =
        [JobStatus::Queued, JobStatus::Running, JobStatus::Succeeded, JobStatus::Failed, JobStatus::Cancelled];

    pub fn as_str(self) -> &'static str {
        match self {
            JobStatus::Queued => "queued",
            JobStatus::Running => "running",
            JobStatus::Succeeded => "succeeded",
            JobStatus::Failed => "failed",
            JobStatus::Cancelled => "cancelled",
        }
    }
    pub fn parse(s: &str) -> Option<JobStatus> {
        JobStatus::ALL.into_iter().find(|st| st.as_str() == s)
    }
    pub fn is_final(self) -> bool {
        matches!(self, JobStatus::Succeeded | JobStatus::Failed | JobStatus::Cancelled)
    }
}

impl std::fmt::Display for JobStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Errors refuse a case; warnings are reported and the case runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    Error,
    Warning,
}

/// One problem with a case, as `fluidbed validate` and the job's `warnings` show it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct CaseProblem {
    /// JSON pointer (RFC 6901) of the field, e.g. `/dem/time_step_s`.
    pub path: String,
    /// The value given (null when missing).
    pub value: Value,
    /// The allowed range or form.
    pub allowed: String,
    pub message: String,
    pub severity: Severity,
}

impl From<&fluidbed_core::case::Problem> for CaseProblem {
    fn from(p: &fluidbed_core::case::Problem) -> CaseProblem {
        CaseProblem {
            path: p.path.clone(),
            value: p.value.clone(),
            allowed: p.allowed.clone(),
            message: p.message.clone(),
            severity: match p.severity {
                fluidbed_core::case::Severity::Error => Severity::Error,
                fluidbed_core::case::Severity::Warning => Severity::Warning,
            },
        }
    }
}

/// The job's related resources.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct JobLinks {
    #[serde(rename = "self")]
    pub self_: String,
    pub events: String,
    pub snapshots: String,
    pub pressure_drop: String,
}

impl JobLinks {
    pub fn of(id: &str) -> JobLinks {
        JobLinks {
            self_: format!("/v1/jobs/{id}"),
            events: format!("/v1/jobs/{id}/events"),
            snapshots: format!("/v1/jobs/{id}/snapshots"),
            pressure_drop: format!("/v1/jobs/{id}/pressure-drop"),
        }
    }
}

/// A job: its status, progress in simulated time, wall time and ETA.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct Job {
    /// 16 hex digits.
    #[schema(example = "8d8b803de9e7b632")]
    pub id: String,
    /// The case's `name`.
    pub name: String,
    pub status: JobStatus,
    /// RFC 3339 UTC.
    #[schema(format = DateTime)]
    pub created_at: String,
    #[schema(format = DateTime)]
    pub started_at: Option<String>,
    #[schema(format = DateTime)]
    pub finished_at: Option<String>,
    /// Simulated time over the case's end time, 0 to 1 (1 once succeeded).
    #[schema(minimum = 0.0, maximum = 1.0)]
    pub progress: f64,
    /// Simulated time reached (s).
    pub time_s: f64,
    /// The case's `end_time_s`.
    pub end_time_s: f64,
    /// DEM steps taken.
    pub steps: u64,
    /// Wall time spent running, added up over restarts (s).
    pub wall_time_s: f64,
    /// Remaining simulated time over the stepping rate since the job (re)started (s).
    pub eta_s: Option<f64>,
    /// Why a job failed, or what a running job is doing before its first step.
    pub message: Option<String>,
    /// The case's validation warnings.
    pub warnings: Vec<CaseProblem>,
    /// Which solver parts run (decided when the run is built; null before), with `skipped`:
    /// each part that does not run and why.
    #[schema(value_type = Option<Object>)]
    pub plan: Option<Value>,
    /// Wall seconds per stage since the job last (re)started: neighbours, contacts_integration,
    /// voidage, exchange, gas, output (null before the first progress report).
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    pub stage_seconds: Option<Value>,
    pub links: JobLinks,
}

/// One page of the job list, newest first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct JobList {
    pub jobs: Vec<Job>,
    /// Jobs matching the filter in all.
    pub total: u64,
    pub limit: u64,
    pub offset: u64,
    /// The offset of the next page; null on the last.
    pub next_offset: Option<u64>,
}
