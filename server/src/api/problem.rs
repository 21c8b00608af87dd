//! RFC 9457 problem details (`application/problem+json`).

use axum::extract::Request;
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use fluidbed_api::Problem;

pub fn problem(status: StatusCode, title: &str, detail: &str) -> Response {
    respond(&Problem::new(status.as_u16(), title, detail))
}

/// A problem document as the answer, with its own status.
pub fn respond(p: &Problem) -> Response {
    let status = StatusCode::from_u16(p.status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
    let body = serde_json::to_string(p).unwrap_or_default();
    (status, [(header::CONTENT_TYPE, "application/problem+json")], body).into_response()
}

pub fn internal(e: anyhow::Error) -> Response {
    problem(StatusCode::INTERNAL_SERVER_ERROR, "Internal error", &format!("{e:#}"))
}

pub fn no_job() -> Response {
    problem(StatusCode::NOT_FOUND, "Not found", "no such job")
}

/// Middleware: an error answer that is not JSON (axum's own rejections of a query string or a
/// path, a 405, a timeout) becomes a problem document with the same status and headers. A 408
/// also closes the connection (the rest of the body is not waited for).
pub async fn errors_as_problems(req: Request, next: Next) -> Response {
    let res = next.run(req).await;
    let status = res.status();
    let is_json = res
        .headers()
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|ct| ct.contains("json") || ct.starts_with("text/event-stream"));
    if !(status.is_client_error() || status.is_server_error()) || is_json {
        return res;
    }
    let (mut parts, body) = res.into_parts();
    let text = axum::body::to_bytes(body, 64 << 10).await.unwrap_or_default();
    let text = String::from_utf8_lossy(&text);
    let detail = match (text.trim(), status) {
        // axum adds the Allow header outside the layers.
        ("", StatusCode::METHOD_NOT_ALLOWED) => "this method is not allowed here: see the Allow header".to_string(),
        ("", StatusCode::REQUEST_TIMEOUT) => "the request was not received in time".to_string(),
        ("", _) => status.canonical_reason().unwrap_or("error").to_string(),
        (t, _) => t.to_string(),
    };
    let title = status.canonical_reason().unwrap_or("Error");
    let doc = problem(status, title, &detail);
    parts.headers.remove(header::CONTENT_LENGTH);
    parts.headers.insert(header::CONTENT_TYPE, HeaderValue::from_static("application/problem+json"));
    if status == StatusCode::REQUEST_TIMEOUT {
        parts.headers.insert(header::CONNECTION, HeaderValue::from_static("close"));
    }
    let body = doc.into_body();
    Response::from_parts(parts, body)
}
