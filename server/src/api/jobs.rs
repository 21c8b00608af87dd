//! Job routes: create, list, status, cancel, event stream.

use super::problem::{internal, no_job, problem, problem_with};
use crate::events::{pump, JobEvent};
use crate::job::{new_id, now_rfc3339, plausible_id, problems_json, Job, Status};
use crate::worker::cancel_flag;
use crate::App;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::Json;
use fluidbed_core::case::bounds::CaseSize;
use fluidbed_core::case::strict_json::{self, StrictJsonError};
use fluidbed_core::case::{Case, Problem, Severity};
use serde::Deserialize;
use serde_json::{json, Value};
use std::convert::Infallible;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

pub async fn create(State(app): State<Arc<App>>, body: Result<Bytes, BytesRejection>) -> Response {
    let body = match body {
        Ok(b) => b,
        Err(e) if e.status() == StatusCode::PAYLOAD_TOO_LARGE => {
            let d = format!("a case may be at most {} bytes", app.config.max_body_bytes);
            return problem(StatusCode::PAYLOAD_TOO_LARGE, "Request body too large", &d);
        }
        Err(e) => {
            // A body that stalled or broke off: answer and close (the rest is not waited for).
            let mut r = problem(e.status(), "Unreadable request body", &e.body_text());
            r.headers_mut().insert(header::CONNECTION, header::HeaderValue::from_static("close"));
            return r;
        }
    };
    if !app.take_submission_token() {
        let mut r = problem(
            StatusCode::TOO_MANY_REQUESTS,
            "Too many submissions",
            "slow down: the server accepts a few jobs per second",
        );
        r.headers_mut().insert(header::RETRY_AFTER, header::HeaderValue::from_static("1"));
        return r;
    }
    let Ok(text) = std::str::from_utf8(&body) else {
        return problem(StatusCode::BAD_REQUEST, "Malformed JSON", "the body is not UTF-8 text");
    };
    let value = match strict_json::parse(text) {
        Ok(v) => v,
        Err(StrictJsonError::Syntax(e)) => {
            return problem(StatusCode::BAD_REQUEST, "Malformed JSON", &format!("the body is not valid JSON: {e}"))
        }
        Err(StrictJsonError::DuplicateKey { pointer, message }) => {
            let p = Problem {
                path: pointer,
                value: Value::Null,
                allowed: "each key once".into(),
                message,
                severity: Severity::Error,
            };
            return invalid_case(&[p], &[]);
        }
    };
    let (case, report) = match Case::parse_value(&value) {
        Ok(ok) => ok,
        Err(report) => return invalid_case(&report.errors, &report.warnings),
    };
    // The server's own limit on what one job may take (the fixed bounds are in `validate`).
    if let Some(p) = CaseSize::of(&case).memory_problem(&case, app.config.max_job_memory) {
        return invalid_case(&[p], &report.warnings);
    }
    match app.store.count(Status::Queued) {
        Ok(n) if n >= app.config.max_queued => {
            let d = format!("{n} jobs are already waiting; try again later");
            let mut r = problem(StatusCode::TOO_MANY_REQUESTS, "Queue full", &d);
            r.headers_mut().insert(header::RETRY_AFTER, header::HeaderValue::from_static("30"));
            return r;
        }
        Ok(_) => {}
        Err(e) => return internal(e),
    }
    let job = Job {
        id: new_id(),
        name: case.name.clone(),
        status: Status::Queued,
        created_at: now_rfc3339(),
        started_at: None,
        finished_at: None,
        time_s: 0.0,
        end_time_s: case.end_time_s,
        steps: 0,
        wall_s: 0.0,
        eta_s: None,
        message: None,
        warnings: problems_json(&report.warnings),
        plan: None,
        cancel_requested: false,
        attempts: 0,
    };
    let case_json = match serde_json::to_string(&case) {
        Ok(s) => s,
        Err(e) => return internal(e.into()),
    };
    if let Err(e) = app.store.insert(&job, &case_json) {
        return internal(e);
    }
    app.queue.push(job.id.clone());
    let location = format!("/v1/jobs/{}", job.id);
    (StatusCode::CREATED, [(header::LOCATION, location)], Json(job.to_json())).into_response()
}

/// 422 with every problem named by its JSON pointer.
fn invalid_case(errors: &[Problem], warnings: &[Problem]) -> Response {
    let list: Vec<_> = errors
        .iter()
        .map(|p| json!({"pointer": p.path, "value": p.value, "allowed": p.allowed, "message": p.message}))
        .collect();
    let detail = errors.iter().map(|p| p.to_string()).collect::<Vec<_>>().join("; ");
    problem_with(
        StatusCode::UNPROCESSABLE_ENTITY,
        "Invalid case",
        &detail,
        json!({ "errors": list, "warnings": problems_json(warnings) }),
    )
}

#[derive(Deserialize)]
pub struct ListQuery {
    status: Option<String>,
    limit: Option<u64>,
    offset: Option<u64>,
}

/// Largest page of the job list.
const MAX_LIMIT: u64 = 500;
/// Offsets and event ids are stored as SQLite integers (i64).
const MAX_OFFSET: u64 = i64::MAX as u64;

pub async fn list(State(app): State<Arc<App>>, Query(q): Query<ListQuery>) -> Response {
    let status = match q.status.as_deref() {
        None | Some("") => None,
        Some(s) => match Status::parse(s) {
            Some(st) => Some(st),
            None => {
                return problem(
                    StatusCode::BAD_REQUEST,
                    "Bad status filter",
                    "status is one of queued, running, succeeded, failed, cancelled",
                )
            }
        },
    };
    let (limit, offset) = (q.limit.unwrap_or(50), q.offset.unwrap_or(0));
    if !(1..=MAX_LIMIT).contains(&limit) {
        return problem(StatusCode::BAD_REQUEST, "Bad limit", &format!("limit is from 1 to {MAX_LIMIT} (got {limit})"));
    }
    if offset > MAX_OFFSET {
        return problem(
            StatusCode::BAD_REQUEST,
            "Bad offset",
            &format!("offset is from 0 to {MAX_OFFSET} (got {offset})"),
        );
    }
    let (limit, offset) = (limit as usize, offset as usize);
    match app.store.list(status, limit, offset) {
        Ok((jobs, total)) => {
            let next = (offset + jobs.len() < total).then_some(offset + jobs.len());
            Json(json!({
                "jobs": jobs.iter().map(Job::to_json).collect::<Vec<_>>(),
                "total": total, "limit": limit, "offset": offset, "next_offset": next,
            }))
            .into_response()
        }
        Err(e) => internal(e),
    }
}

/// The job, or the response to send instead (404 / 500); handlers return it as is.
#[allow(clippy::result_large_err)]
pub fn find(app: &App, id: &str) -> Result<Job, Response> {
    if !plausible_id(id) {
        return Err(no_job());
    }
    match app.store.get(id) {
        Ok(Some(j)) => Ok(j),
        Ok(None) => Err(no_job()),
        Err(e) => Err(internal(e)),
    }
}

pub async fn get_one(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    match find(&app, &id) {
        Ok(job) => Json(job.to_json()).into_response(),
        Err(r) => r,
    }
}

/// Cancel: a queued job ends at once; a running one stops at its next chunk boundary.
pub async fn cancel(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    let job = match find(&app, &id) {
        Ok(j) => j,
        Err(r) => return r,
    };
    match job.status {
        Status::Succeeded | Status::Failed => {
            return problem(
                StatusCode::CONFLICT,
                "Job already finished",
                &format!("the job has {}", job.status.as_str()),
            )
        }
        Status::Cancelled => return Json(job.to_json()).into_response(),
        Status::Queued | Status::Running => {}
    }
    // Stored before the answer, so that a cancel survives a server stop.
    let a = app.clone();
    let job_id = id.clone();
    match tokio::task::spawn_blocking(move || a.store.request_cancel(&job_id)).await {
        Ok(Ok(_)) => {}
        Ok(Err(e)) => return internal(e),
        Err(e) => return internal(e.into()),
    }
    cancel_flag(&app, &id).store(true, Ordering::SeqCst);
    if job.status == Status::Queued {
        if let Ok(true) = app.store.finish(&id, Status::Cancelled, Some("cancelled before it started"), &now_rfc3339())
        {
            if let Ok(Some(j)) = app.store.get(&id) {
                app.hub.publish(&id, JobEvent::new("status", None, &j.status_json()));
                app.hub.publish(&id, JobEvent::new("end", None, &j.status_json()));
            }
        }
    }
    match app.store.get(&id) {
        Ok(Some(j)) => (StatusCode::ACCEPTED, Json(j.to_json())).into_response(),
        Ok(None) => no_job(),
        Err(e) => internal(e),
    }
}

#[derive(Deserialize)]
pub struct EventsQuery {
    last_event_id: Option<String>,
}

/// A Last-Event-ID: a snapshot number up to MAX_OFFSET (the next one is then n + 1).
#[allow(clippy::result_large_err)]
fn last_event_id(text: &str) -> Result<u64, Response> {
    match text.trim().parse::<u64>() {
        Ok(n) if n < MAX_OFFSET => Ok(n),
        _ => Err(problem(
            StatusCode::BAD_REQUEST,
            "Bad Last-Event-ID",
            &format!("Last-Event-ID is a snapshot number from 0 to {} (got `{}`)", MAX_OFFSET - 1, text.trim()),
        )),
    }
}

/// Server-sent events; resume with the `Last-Event-ID` header (or `?last_event_id=`).
pub async fn events(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    Query(q): Query<EventsQuery>,
    headers: HeaderMap,
) -> Response {
    if let Err(r) = find(&app, &id) {
        return r;
    }
    let given = headers.get("last-event-id").map(|v| v.to_str().unwrap_or("?").to_string()).or(q.last_event_id);
    let last = match given.as_deref().map(last_event_id) {
        None => None,
        Some(Ok(n)) => Some(n),
        Some(Err(r)) => return r,
    };
    let (tx, rx) = tokio::sync::mpsc::channel::<Event>(32);
    tokio::spawn(pump(app.clone(), id, last, tx));
    let stream =
        futures_util::stream::unfold(rx, |mut rx| async move { rx.recv().await.map(|e| (Ok::<_, Infallible>(e), rx)) });
    Sse::new(stream).keep_alive(KeepAlive::new().interval(Duration::from_secs(15))).into_response()
}
