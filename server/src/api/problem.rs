//! RFC 9457 problem details (`application/problem+json`).

use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use serde_json::{json, Value};

pub fn problem(status: StatusCode, title: &str, detail: &str) -> Response {
    problem_with(status, title, detail, json!({}))
}

/// A problem with extension members (e.g. `errors`), merged into the body.
pub fn problem_with(status: StatusCode, title: &str, detail: &str, extra: Value) -> Response {
    let mut body = json!({
        "type": "about:blank",
        "title": title,
        "status": status.as_u16(),
        "detail": detail,
    });
    if let (Some(b), Value::Object(e)) = (body.as_object_mut(), extra) {
        b.extend(e);
    }
    (status, [(header::CONTENT_TYPE, "application/problem+json")], body.to_string()).into_response()
}

pub fn internal(e: anyhow::Error) -> Response {
    problem(StatusCode::INTERNAL_SERVER_ERROR, "Internal error", &format!("{e:#}"))
}

pub fn no_job() -> Response {
    problem(StatusCode::NOT_FOUND, "Not found", "no such job")
}
