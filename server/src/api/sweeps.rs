//! Sweep routes: create (one job per point, all or none), list, one sweep with its points'
//! status and summaries, cancel every unfinished point.
// The helpers return the answer to send as their error (a `Response`, large by design).
#![allow(clippy::result_large_err)]

use super::jobs::{cancel_job, invalid_case, new_job, page, queue_room, read_json};
use super::problem::{internal, problem};
use crate::job::{new_id, now_rfc3339, plausible_id, Job, Status};
use crate::store::SweepRecord;
use crate::sweep::{case_of, expand, locate, summarize};
use crate::App;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use fluidbed_api::{PageQuery, Sweep, SweepList, SweepPoint, SweepRequest};
use fluidbed_core::case::bounds::CaseSize;
use fluidbed_core::case::{Case, Problem, Severity};
use serde_json::Value;
use std::sync::Arc;

fn no_sweep() -> Response {
    problem(StatusCode::NOT_FOUND, "Not found", "no such sweep")
}

/// The RFC 6901 pointer of a serde path (`grid[0].values` → `/grid/0/values`).
fn pointer_of(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    path.iter()
        .map(|s| match s {
            Segment::Seq { index } => format!("/{index}"),
            Segment::Map { key } => format!("/{}", key.replace('~', "~0").replace('/', "~1")),
            Segment::Enum { variant } => format!("/{variant}"),
            Segment::Unknown => String::new(),
        })
        .collect()
}

/// Every case of the request, or the 422 (or 413-like refusal) naming each problem by its
/// pointer in the request.
/// A point ready to insert: its job, its case JSON, its values.
type Ready = (Job, String, crate::sweep::Point);

fn cases_of(app: &App, req: &SweepRequest) -> Result<(String, Vec<Ready>), Response> {
    let points = expand(req, app.config.max_queued).map_err(|p| invalid_case(&p, &[]))?;
    let name = req
        .name
        .clone()
        .or_else(|| req.base.get("name").and_then(Value::as_str).map(str::to_string))
        .unwrap_or_else(|| "sweep".into());
    if name.len() > fluidbed_core::case::bounds::MAX_NAME_BYTES {
        let p = Problem {
            path: "/name".into(),
            value: Value::String(format!("{} bytes", name.len())),
            allowed: format!("at most {} bytes", fluidbed_core::case::bounds::MAX_NAME_BYTES),
            message: "sweep name too long".into(),
            severity: Severity::Error,
        };
        return Err(invalid_case(&[p], &[]));
    }
    let (mut errors, mut warnings, mut jobs) = (Vec::new(), Vec::<Problem>::new(), Vec::new());
    // All the points' cases together are held to what a few cases may be (an explicit bed is
    // copied into every point).
    let (mut stored, budget) = (0usize, 4 * app.config.max_body_bytes);
    for (k, point) in points.into_iter().enumerate() {
        let doc = match case_of(&req.base, &name, k, &point) {
            Ok(d) => d,
            Err(p) => {
                errors.extend(p);
                continue;
            }
        };
        match Case::parse_value(&doc) {
            Err(report) => {
                errors.extend(report.errors.into_iter().map(|p| locate(p, k, &point)));
            }
            Ok((case, report)) => {
                if let Some(p) = CaseSize::of(&case).memory_problem(&case, app.config.max_job_memory) {
                    errors.push(locate(p, k, &point));
                }
                // Each warning once, by where it is named (the base's warnings hold for every point).
                for w in report.warnings.iter().map(|w| locate(w.clone(), k, &point)) {
                    if !warnings.iter().any(|seen: &Problem| seen.path == w.path) {
                        warnings.push(w);
                    }
                }
                let text = serde_json::to_string(&case).map_err(|e| internal(e.into()))?;
                stored += text.len();
                jobs.push((new_job(&case, &report.warnings), text, point));
            }
        }
        if errors.len() > 100 {
            break;
        }
    }
    if errors.is_empty() && stored > budget {
        let p = Problem {
            path: "/base".into(),
            value: Value::String(format!("{stored} bytes in all")),
            allowed: format!("at most {budget} bytes of cases in one sweep"),
            message: "the base case is too large to copy into every point: fewer points, or a generated bed".into(),
            severity: Severity::Error,
        };
        errors.push(p);
    }
    if errors.is_empty() {
        Ok((name, jobs))
    } else {
        Err(invalid_case(&errors, &warnings))
    }
}

/// Submit a sweep: one job per point, queued together (all or none).
#[utoipa::path(
    post,
    path = "/v1/sweeps",
    operation_id = "create_sweep",
    tag = "sweeps",
    request_body(content = SweepRequest, content_type = "application/json",
        description = "A base case and a grid of values or a list of points, each value set at a JSON pointer."),
    responses(
        (status = 201, description = "Created: every point is a queued job", body = Sweep,
            headers(("Location" = String, description = "/v1/sweeps/{id}"))),
        (status = 400, description = "Not JSON", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 413, description = "Over --max-body-bytes", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 415, description = "A Content-Type other than JSON", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
        (status = 422, description = "An invalid request or point: `errors` names each by its pointer in the request",
            body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 429, description = "Too many submissions, or the points do not fit in the queue", body = fluidbed_api::Problem,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "seconds"))),
    )
)]
pub async fn create(State(app): State<Arc<App>>, headers: HeaderMap, body: Result<Bytes, BytesRejection>) -> Response {
    let value = match read_json(&app, &headers, body) {
        Ok(v) => v,
        Err(r) => return r,
    };
    let req: SweepRequest = match serde_path_to_error::deserialize(&value) {
        Ok(r) => r,
        Err(e) => {
            let path = pointer_of(e.path());
            let p = Problem {
                path: path.clone(),
                value: value.pointer(&path).cloned().unwrap_or(Value::Null),
                allowed: "see the SweepRequest schema (GET /openapi.json)".into(),
                message: e.inner().to_string(),
                severity: Severity::Error,
            };
            return invalid_case(&[p], &[]);
        }
    };
    let a = app.clone();
    let built = tokio::task::spawn_blocking(move || -> Result<Sweep, Response> {
        let (name, jobs) = cases_of(&a, &req)?;
        queue_room(&a, jobs.len())?;
        let record = SweepRecord {
            id: new_id(),
            name,
            created_at: now_rfc3339(),
            points: jobs.iter().map(|(j, _, p)| (j.id.clone(), p.set.clone())).collect(),
        };
        let rows: Vec<(Job, String)> = jobs.iter().map(|(j, text, _)| (j.clone(), text.clone())).collect();
        a.store.insert_sweep(&record, &rows).map_err(internal)?;
        let jobs: Vec<Job> = rows.into_iter().map(|(j, _)| j).collect();
        Ok(view(&record, &jobs, |_| None))
    })
    .await;
    match built {
        Ok(Ok(sweep)) => {
            app.queue.ring();
            let location = format!("/v1/sweeps/{}", sweep.id);
            (StatusCode::CREATED, [(header::LOCATION, location)], Json(sweep)).into_response()
        }
        Ok(Err(r)) => r,
        Err(e) => internal(e.into()),
    }
}

/// The sweep as the API shows it, from its record and its jobs (in the record's order), with
/// `summary` giving each succeeded point's summary.
fn view(record: &SweepRecord, jobs: &[Job], summary: impl Fn(&Job) -> Option<fluidbed_api::PointSummary>) -> Sweep {
    let points: Vec<SweepPoint> = record
        .points
        .iter()
        .zip(jobs)
        .enumerate()
        .map(|(k, ((_, set), job))| SweepPoint {
            index: k as u64,
            set: set.clone(),
            job: job.id.clone(),
            status: job.status,
            progress: job.progress(),
            message: job.message.clone(),
            summary: if job.status == Status::Succeeded { summary(job) } else { None },
        })
        .collect();
    let statuses: Vec<Status> = points.iter().map(|p| p.status).collect();
    Sweep {
        id: record.id.clone(),
        name: record.name.clone(),
        created_at: record.created_at.clone(),
        status: Sweep::status_of(&statuses),
        progress: points.iter().map(|p| p.progress).sum::<f64>() / points.len().max(1) as f64,
        points,
    }
}

/// The jobs of a sweep's points; a job that is gone shows as failed with a message.
fn jobs_of(app: &App, record: &SweepRecord) -> anyhow::Result<Vec<Job>> {
    record
        .points
        .iter()
        .map(|(id, _)| {
            Ok(app.store.get(id)?.unwrap_or_else(|| Job {
                id: id.clone(),
                name: String::new(),
                status: Status::Failed,
                created_at: record.created_at.clone(),
                started_at: None,
                finished_at: None,
                time_s: 0.0,
                end_time_s: 0.0,
                steps: 0,
                wall_s: 0.0,
                eta_s: None,
                message: Some("the point's job record is missing".into()),
                warnings: Vec::new(),
                plan: None,
                stage_seconds: None,
                cancel_requested: false,
                attempts: 0,
            }))
        })
        .collect()
}

/// A finished point's summary from its case and snapshot index.
fn summary_of(app: &App, job: &Job) -> Option<fluidbed_api::PointSummary> {
    let case = Case::from_stored_json(&app.store.case_json(&job.id).ok()??).ok()?;
    let infos = app.store.snapshots(&job.id).ok()?;
    Some(summarize(&case, &infos))
}

/// The sweep, its jobs, or the answer to send instead (404 / 500).
fn find(app: &App, id: &str) -> Result<(SweepRecord, Vec<Job>), Response> {
    if !plausible_id(id) {
        return Err(no_sweep());
    }
    let record = match app.store.sweep(id) {
        Ok(Some(r)) => r,
        Ok(None) => return Err(no_sweep()),
        Err(e) => return Err(internal(e)),
    };
    let jobs = jobs_of(app, &record).map_err(internal)?;
    Ok((record, jobs))
}

/// One sweep: each point's values, job, status and (once succeeded) summary: the pressure drop's
/// mean and standard deviation and the mean particle height over the second half of its run.
#[utoipa::path(
    get,
    path = "/v1/sweeps/{id}",
    operation_id = "get_sweep",
    tag = "sweeps",
    params(("id" = String, Path, description = "The sweep id")),
    responses(
        (status = 200, description = "The sweep", body = Sweep),
        (status = 404, description = "No such sweep", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn get_one(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    let a = app.clone();
    let out = tokio::task::spawn_blocking(move || {
        find(&a, &id).map(|(record, jobs)| view(&record, &jobs, |job| summary_of(&a, job)))
    })
    .await;
    match out {
        Ok(Ok(sweep)) => Json(sweep).into_response(),
        Ok(Err(r)) => r,
        Err(e) => internal(e.into()),
    }
}

/// List sweeps, newest first (each point's status and progress; summaries in `GET /v1/sweeps/{id}`).
#[utoipa::path(
    get,
    path = "/v1/sweeps",
    operation_id = "list_sweeps",
    tag = "sweeps",
    params(PageQuery),
    responses(
        (status = 200, description = "One page of sweeps", body = SweepList),
        (status = 400, description = "A bad query string", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn list(State(app): State<Arc<App>>, Query(q): Query<PageQuery>) -> Response {
    let (limit, offset) = match page(q.limit, q.offset) {
        Ok(p) => p,
        Err(r) => return r,
    };
    let a = app.clone();
    let out = tokio::task::spawn_blocking(move || -> anyhow::Result<SweepList> {
        let (records, total) = a.store.sweeps(limit as usize, offset as usize)?;
        let sweeps =
            records.iter().map(|r| Ok(view(r, &jobs_of(&a, r)?, |_| None))).collect::<anyhow::Result<Vec<_>>>()?;
        let (end, total) = (offset + sweeps.len() as u64, total as u64);
        Ok(SweepList { sweeps, total, limit, offset, next_offset: (end < total).then_some(end) })
    })
    .await;
    match out {
        Ok(Ok(list)) => Json(list).into_response(),
        Ok(Err(e)) => internal(e),
        Err(e) => internal(e.into()),
    }
}

/// Cancel every point that has not ended (finished points keep their results).
#[utoipa::path(
    delete,
    path = "/v1/sweeps/{id}",
    operation_id = "cancel_sweep",
    tag = "sweeps",
    params(("id" = String, Path, description = "The sweep id")),
    responses(
        (status = 202, description = "Cancel accepted for every unfinished point", body = Sweep),
        (status = 404, description = "No such sweep", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn cancel(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    let a = app.clone();
    let sid = id.clone();
    let (_, jobs) = match tokio::task::spawn_blocking(move || find(&a, &sid)).await {
        Ok(Ok(found)) => found,
        Ok(Err(r)) => return r,
        Err(e) => return internal(e.into()),
    };
    for job in jobs.iter().filter(|j| !j.status.is_final()) {
        if let Err(r) = cancel_job(&app, job).await {
            // A point that ended meanwhile (409) keeps its result; anything else is an error.
            if r.status() != StatusCode::CONFLICT {
                return r;
            }
        }
    }
    let a = app.clone();
    match tokio::task::spawn_blocking(move || find(&a, &id).map(|(r, j)| view(&r, &j, |_| None))).await {
        Ok(Ok(sweep)) => (StatusCode::ACCEPTED, Json(sweep)).into_response(),
        Ok(Err(r)) => r,
        Err(e) => internal(e.into()),
    }
}
