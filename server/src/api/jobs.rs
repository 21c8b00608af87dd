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
use fluidbed_core::case::Case;
use serde::Deserialize;
use serde_json::json;
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
        Err(e) => return problem(e.status(), "Unreadable request body", &e.body_text()),
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
    let value: serde_json::Value = match serde_json::from_slice(&body) {
        Ok(v) => v,
        Err(e) => {
            return problem(StatusCode::BAD_REQUEST, "Malformed JSON", &format!("the body is not valid JSON: {e}"))
        }
    };
    let (case, report) = match Case::parse_value(&value) {
        Ok(ok) => ok,
        Err(report) => {
            let errors: Vec<_> = report
                .errors
                .iter()
                .map(|p| json!({"pointer": p.path, "value": p.value, "allowed": p.allowed, "message": p.message}))
                .collect();
            let detail = report.errors.iter().map(|p| p.to_string()).collect::<Vec<_>>().join("; ");
            return problem_with(
                StatusCode::UNPROCESSABLE_ENTITY,
                "Invalid case",
                &detail,
                json!({ "errors": errors, "warnings": problems_json(&report.warnings) }),
            );
        }
    };
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

#[derive(Deserialize)]
pub struct ListQuery {
    status: Option<String>,
    limit: Option<usize>,
    offset: Option<usize>,
}

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
    let (limit, offset) = (q.limit.unwrap_or(50).clamp(1, 500), q.offset.unwrap_or(0));
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
    last_event_id: Option<u64>,
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
    let last = headers
        .get("last-event-id")
        .and_then(|v| v.to_str().ok())
        .and_then(|s| s.trim().parse::<u64>().ok())
        .or(q.last_event_id);
    let (tx, rx) = tokio::sync::mpsc::channel::<Event>(32);
    tokio::spawn(pump(app.clone(), id, last, tx));
    let stream =
        futures_util::stream::unfold(rx, |mut rx| async move { rx.recv().await.map(|e| (Ok::<_, Infallible>(e), rx)) });
    Sse::new(stream).keep_alive(KeepAlive::new().interval(Duration::from_secs(15))).into_response()
}
