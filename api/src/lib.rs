//! fluidbed-api: the request and response types of fluidbed's HTTP API (docs/API.md), in one place
//! that the server and the client share. Each type derives its OpenAPI schema (utoipa); the
//! server's routes assemble them into the document served at `/openapi.json`, and the case schema
//! itself comes from fluidbed-core (schemars), merged in by `case_schema`.

pub mod case_schema;
pub mod events;
pub mod health;
pub mod job;
pub mod problem;
pub mod query;
pub mod snapshot;
pub mod sweep;

pub use events::{ProgressEvent, SnapshotEvent, StatusEvent};
pub use health::{DataDirReport, Health, HealthStatus};
pub use job::{CaseProblem, Job, JobLinks, JobList, JobStatus, Severity};
pub use problem::{FieldError, Problem};
pub use query::{
    AnalysisQuery, EventsQuery, ListQuery, PageQuery, SeriesFormat, SeriesQuery, SnapshotField, SnapshotFormat,
    SnapshotQuery, ANALYSIS_FIGURES,
};
pub use snapshot::{Binary, GridInfo, ParticleState, PressureDropSeries, SnapshotDocument, SnapshotInfo, SnapshotList};
pub use sweep::{GridAxis, PointSummary, Sweep, SweepList, SweepPoint, SweepRequest};

/// The name of the bearer-token security scheme in the OpenAPI document.
pub const BEARER: &str = "bearer";
