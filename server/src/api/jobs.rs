//! Job routes: create, list, status, cancel, event stream.

use super::problem::{internal, no_job, problem, respond};
use crate::events::{pump, EventKind, JobEvent};
use crate::job::{case_problems, new_id, now_rfc3339, plausible_id, Job, Status};
use crate::worker::cancel_flag;
use crate::App;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::Json;
use fluidbed_api::query::{MAX_LIMIT, MAX_OFFSET};
use fluidbed_api::{EventsQuery, FieldError, JobList, ListQuery};
use fluidbed_core::case::bounds::CaseSize;
use fluidbed_core::case::strict_json::{self, StrictJsonError};
use fluidbed_core::case::{Case, Problem, Severity};
use serde_json::Value;
use std::convert::Infallible;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

/// Submit a case; it is validated at once.
#[utoipa::path(
    post,
    path = "/v1/jobs",
    operation_id = "create_job",
    tag = "jobs",
    request_body(
        content = ref("#/components/schemas/Case"),
        content_type = "application/json",
        description = "A case (the schema is also served at /v1/schema/case). A key given twice is refused."
    ),
    responses(
        (status = 201, description = "Created", body = fluidbed_api::Job,
            headers(("Location" = String, description = "/v1/jobs/{id}"))),
        (status = 400, description = "Not JSON", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 413, description = "Over --max-body-bytes", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 415, description = "A Content-Type other than JSON", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
        (status = 422, description = "Invalid case: `errors` names every field", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
        (status = 429, description = "Too many submissions or a full queue", body = fluidbed_api::Problem,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "seconds"))),
    )
)]
pub async fn create(State(app): State<Arc<App>>, headers: HeaderMap, body: Result<Bytes, BytesRejection>) -> Response {
    let value = match read_json(&app, &headers, body) {
        Ok(v) => v,
        Err(r) => return r,
    };
    let (case, report) = match Case::parse_value(&value) {
        Ok(ok) => ok,
        Err(report) => return invalid_case(&report.errors, &report.warnings),
    };
    // The server's own limit on what one job may take (the fixed bounds are in `validate`).
    if let Some(p) = CaseSize::of(&case).memory_problem(&case, app.config.max_job_memory) {
        return invalid_case(&[p], &report.warnings);
    }
    if let Err(r) = queue_room(&app, 1) {
        return r;
    }
    let job = new_job(&case, &report.warnings);
    let case_json = match serde_json::to_string(&case) {
        Ok(s) => s,
        Err(e) => return internal(e.into()),
    };
    if let Err(e) = app.store.insert(&job, &case_json) {
        return internal(e);
    }
    app.queue.ring();
    let location = format!("/v1/jobs/{}", job.id);
    (StatusCode::CREATED, [(header::LOCATION, location)], Json(job.to_api())).into_response()
}

/// The request body as JSON, or the answer to send instead: too large (413), stalled, not JSON
/// by its Content-Type (415), over the submission rate (429), not UTF-8 or not JSON (400), a key
/// given twice (422).
#[allow(clippy::result_large_err)]
pub(super) fn read_json(
    app: &App,
    headers: &HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Value, Response> {
    let body = match body {
        Ok(b) => b,
        Err(e) if e.status() == StatusCode::PAYLOAD_TOO_LARGE => {
            // The rest of the body is not read, so the connection cannot carry another request:
            // without `close` a client reuses it and its next request is lost (issue 22's fuzz).
            let d = format!("a request body may be at most {} bytes", app.config.max_body_bytes);
            let mut r = problem(StatusCode::PAYLOAD_TOO_LARGE, "Request body too large", &d);
            r.headers_mut().insert(header::CONNECTION, header::HeaderValue::from_static("close"));
            return Err(r);
        }
        Err(e) => {
            // A body that stalled or broke off: answer and close (the rest is not waited for).
            let mut r = problem(e.status(), "Unreadable request body", &e.body_text());
            r.headers_mut().insert(header::CONNECTION, header::HeaderValue::from_static("close"));
            return Err(r);
        }
    };
    // A body sent as something else (a form, text) is not read as JSON; no header is JSON.
    // (After the body is read whole: an answer before that must close the connection.)
    if let Some(ct) = headers.get(header::CONTENT_TYPE) {
        if !ct.to_str().is_ok_and(is_json_media_type) {
            let d = format!("the body is sent as application/json (got {:?})", String::from_utf8_lossy(ct.as_bytes()));
            return Err(problem(StatusCode::UNSUPPORTED_MEDIA_TYPE, "Unsupported media type", &d));
        }
    }
    if !app.take_submission_token() {
        let mut r = problem(
            StatusCode::TOO_MANY_REQUESTS,
            "Too many submissions",
            "slow down: the server accepts a few submissions per second",
        );
        r.headers_mut().insert(header::RETRY_AFTER, header::HeaderValue::from_static("1"));
        return Err(r);
    }
    let Ok(text) = std::str::from_utf8(&body) else {
        return Err(problem(StatusCode::BAD_REQUEST, "Malformed JSON", "the body is not UTF-8 text"));
    };
    match strict_json::parse(text) {
        Ok(v) => Ok(v),
        Err(StrictJsonError::Syntax(e)) => {
            Err(problem(StatusCode::BAD_REQUEST, "Malformed JSON", &format!("the body is not valid JSON: {e}")))
        }
        Err(StrictJsonError::DuplicateKey { pointer, message }) => {
            let p = Problem {
                path: pointer,
                value: Value::Null,
                allowed: "each key once".into(),
                message,
                severity: Severity::Error,
            };
            Err(invalid_case(&[p], &[]))
        }
    }
}

/// Room in the queue for `n` more jobs, or 429 with the count waiting.
#[allow(clippy::result_large_err)]
pub(super) fn queue_room(app: &App, n: usize) -> Result<(), Response> {
    match app.store.count(Status::Queued) {
        Ok(waiting) if waiting + n > app.config.max_queued => {
            let d = if n == 1 {
                format!("{waiting} jobs are already waiting; try again later")
            } else {
                format!(
                    "{waiting} jobs are already waiting and the queue holds {}: {n} more do not fit; try again later",
                    app.config.max_queued
                )
            };
            let mut r = problem(StatusCode::TOO_MANY_REQUESTS, "Queue full", &d);
            r.headers_mut().insert(header::RETRY_AFTER, header::HeaderValue::from_static("30"));
            Err(r)
        }
        Ok(_) => Ok(()),
        Err(e) => Err(internal(e)),
    }
}

/// A queued job for a valid case.
pub(super) fn new_job(case: &Case, warnings: &[Problem]) -> Job {
    Job {
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
        warnings: case_problems(warnings),
        plan: None,
        stage_seconds: None,
        cancel_requested: false,
        attempts: 0,
    }
}

/// `application/json` or `application/*+json`, with any parameters, in any case.
fn is_json_media_type(ct: &str) -> bool {
    let t = ct.split(';').next().unwrap_or("").trim().to_ascii_lowercase();
    t == "application/json" || (t.starts_with("application/") && t.ends_with("+json"))
}

/// 422 with every problem named by its JSON pointer.
pub(super) fn invalid_case(errors: &[Problem], warnings: &[Problem]) -> Response {
    let detail = errors.iter().map(|p| p.to_string()).collect::<Vec<_>>().join("; ");
    let mut doc = fluidbed_api::Problem::new(422, "Invalid case", &detail);
    doc.errors = Some(errors.iter().map(FieldError::from).collect());
    doc.warnings = Some(case_problems(warnings));
    respond(&doc)
}

/// List jobs, newest first.
#[utoipa::path(
    get,
    path = "/v1/jobs",
    operation_id = "list_jobs",
    tag = "jobs",
    params(ListQuery),
    responses(
        (status = 200, description = "One page of jobs", body = JobList),
        (status = 400, description = "A bad query string", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn list(State(app): State<Arc<App>>, Query(q): Query<ListQuery>) -> Response {
    let (limit, offset) = match page(q.limit, q.offset) {
        Ok(p) => p,
        Err(r) => return r,
    };
    match app.store.list(q.status, limit as usize, offset as usize) {
        Ok((jobs, total)) => {
            let end = offset + jobs.len() as u64;
            let total = total as u64;
            Json(JobList {
                jobs: jobs.iter().map(Job::to_api).collect(),
                total,
                limit,
                offset,
                next_offset: (end < total).then_some(end),
            })
            .into_response()
        }
        Err(e) => internal(e),
    }
}

/// A list page's limit (default 50, 1 to MAX_LIMIT) and offset (default 0, to MAX_OFFSET), or 400.
#[allow(clippy::result_large_err)]
pub(super) fn page(limit: Option<u64>, offset: Option<u64>) -> Result<(u64, u64), Response> {
    let (limit, offset) = (limit.unwrap_or(50), offset.unwrap_or(0));
    if !(1..=MAX_LIMIT).contains(&limit) {
        let d = format!("limit is from 1 to {MAX_LIMIT} (got {limit})");
        return Err(problem(StatusCode::BAD_REQUEST, "Bad limit", &d));
    }
    if offset > MAX_OFFSET {
        let d = format!("offset is from 0 to {MAX_OFFSET} (got {offset})");
        return Err(problem(StatusCode::BAD_REQUEST, "Bad offset", &d));
    }
    Ok((limit, offset))
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

/// One job: status, progress, ETA.
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}",
    operation_id = "get_job",
    tag = "jobs",
    params(("id" = String, Path, description = "The job id")),
    responses(
        (status = 200, description = "The job", body = fluidbed_api::Job),
        (status = 404, description = "No such job", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn get_one(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    match find(&app, &id) {
        Ok(job) => Json(job.to_api()).into_response(),
        Err(r) => r,
    }
}

/// Cancel: a queued job ends at once; a running one stops at its next chunk, a bed being poured
/// at once. The cancel is stored before the answer, so it holds across a server stop.
#[utoipa::path(
    delete,
    path = "/v1/jobs/{id}",
    operation_id = "cancel_job",
    tag = "jobs",
    params(("id" = String, Path, description = "The job id")),
    responses(
        (status = 202, description = "Cancel accepted", body = fluidbed_api::Job),
        (status = 200, description = "Already cancelled", body = fluidbed_api::Job),
        (status = 404, description = "No such job", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 409, description = "The job already succeeded or failed", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
    )
)]
pub async fn cancel(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    let job = match find(&app, &id) {
        Ok(j) => j,
        Err(r) => return r,
    };
    let code = match cancel_job(&app, &job).await {
        Ok(true) => StatusCode::ACCEPTED,
        Ok(false) => StatusCode::OK,
        Err(r) => return r,
    };
    match app.store.get(&id) {
        Ok(Some(j)) => (code, Json(j.to_api())).into_response(),
        Ok(None) => no_job(),
        Err(e) => internal(e),
    }
}

/// Cancel one job (see `cancel`): Ok(true) once the cancel is stored, Ok(false) if the job was
/// already cancelled, or the answer to send instead.
#[allow(clippy::result_large_err)]
pub(super) async fn cancel_job(app: &Arc<App>, job: &Job) -> Result<bool, Response> {
    let id = job.id.clone();
    match job.status {
        Status::Succeeded | Status::Failed => {
            return Err(problem(
                StatusCode::CONFLICT,
                "Job already finished",
                &format!("the job has {}", job.status.as_str()),
            ))
        }
        Status::Cancelled => return Ok(false),
        Status::Queued | Status::Running => {}
    }
    // Stored before the answer, so that a cancel survives a server stop.
    let a = app.clone();
    let job_id = id.clone();
    match tokio::task::spawn_blocking(move || a.store.request_cancel(&job_id)).await {
        Ok(Ok(_)) => {}
        Ok(Err(e)) => return Err(internal(e)),
        Err(e) => return Err(internal(e.into())),
    }
    cancel_flag(app, &id).store(true, Ordering::SeqCst);
    if job.status == Status::Queued {
        if let Ok(true) = app.store.records().cancel_queued(&id, "cancelled before it started", &now_rfc3339()) {
            if let Ok(Some(j)) = app.store.get(&id) {
                app.hub.publish(&id, JobEvent::new(EventKind::Status, None, &j.status_event()));
                app.hub.publish(&id, JobEvent::new(EventKind::End, None, &j.status_event()));
            }
        }
    }
    Ok(true)
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

/// Server-sent events: `status` and `progress` (StatusEvent, ProgressEvent), `snapshot` with
/// `id: n` (SnapshotEvent), and `end` (StatusEvent), after which the stream closes. A late client
/// first gets every stored snapshot; resume with `Last-Event-ID: n` to get only those after n.
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/events",
    operation_id = "job_events",
    tag = "jobs",
    params(
        ("id" = String, Path, description = "The job id"),
        ("Last-Event-ID" = Option<String>, Header, description = "The last snapshot number seen (0 to 2^63 - 2)"),
        EventsQuery,
    ),
    responses(
        (status = 200, description = "The event stream; each event is a JobStreamEvent",
            body = ref("#/components/schemas/JobStreamEvent"), content_type = "text/event-stream"),
        (status = 400, description = "A bad Last-Event-ID", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 404, description = "No such job", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
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
