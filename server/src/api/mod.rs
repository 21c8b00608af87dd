//! The HTTP API, versioned under /v1 (see docs/API.md and GET /openapi.json).

mod downloads;
mod jobs;
pub mod problem;

use crate::App;
use axum::extract::{DefaultBodyLimit, Request, State};
use axum::http::{header, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::{Json, Router};
use problem::problem;
use std::sync::Arc;
use tower_http::timeout::{RequestBodyTimeoutLayer, TimeoutLayer};

pub const OPENAPI: &str = include_str!("openapi.json");

pub fn router(app: Arc<App>) -> Router {
    let limit = app.config.max_body_bytes;
    Router::new()
        .route("/v1/jobs", get(jobs::list).post(jobs::create))
        .route("/v1/jobs/{id}", get(jobs::get_one).delete(jobs::cancel))
        .route("/v1/jobs/{id}/events", get(jobs::events))
        .route("/v1/jobs/{id}/snapshots", get(downloads::list))
        .route("/v1/jobs/{id}/snapshots/{n}", get(downloads::one))
        .route("/v1/jobs/{id}/pressure-drop", get(downloads::pressure_drop))
        .route("/v1/schema/case", get(schema))
        .route("/openapi.json", get(openapi))
        .route("/healthz", get(healthz))
        .route("/metrics", get(crate::metrics::handler))
        .merge(crate::page::routes())
        .fallback(not_found)
        .layer(axum::middleware::from_fn_with_state(app.clone(), auth))
        .layer(DefaultBodyLimit::max(limit))
        .layer(RequestBodyTimeoutLayer::new(app.config.body_read_timeout))
        .layer(TimeoutLayer::with_status_code(StatusCode::REQUEST_TIMEOUT, app.config.request_timeout))
        .layer(axum::middleware::from_fn(problem::errors_as_problems))
        .layer(axum::middleware::from_fn_with_state(app.clone(), crate::metrics::observe))
        .with_state(app)
}

/// 200 while the data directory takes writes; 503 with the cause (a full or read-only disk).
async fn healthz(State(app): State<Arc<App>>) -> Response {
    let a = app.clone();
    let (ok, data_dir) = match tokio::task::spawn_blocking(move || a.health.check(&a.store)).await {
        Ok(r) => r,
        Err(e) => return problem::internal(e.into()),
    };
    let body = serde_json::json!({
        "status": if ok { "ok" } else { "degraded" },
        "version": env!("CARGO_PKG_VERSION"),
        "data_dir": data_dir,
    });
    let code = if ok { StatusCode::OK } else { StatusCode::SERVICE_UNAVAILABLE };
    (code, Json(body)).into_response()
}

async fn schema() -> Json<serde_json::Value> {
    Json(fluidbed_core::case::Case::json_schema())
}

async fn openapi() -> Response {
    ([(header::CONTENT_TYPE, "application/json")], OPENAPI).into_response()
}

async fn not_found() -> Response {
    problem(StatusCode::NOT_FOUND, "Not found", "no such resource")
}

/// With a token configured, every route but /healthz and the page's static files needs
/// `Authorization: Bearer <token>`.
async fn auth(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    if let Some(token) = &app.config.token {
        let path = req.uri().path();
        if path != "/healthz" && !crate::page::is_page_path(path) {
            let given = req
                .headers()
                .get(header::AUTHORIZATION)
                .and_then(|v| v.to_str().ok())
                .and_then(|v| v.strip_prefix("Bearer "));
            if !given.is_some_and(|g| constant_time_eq(g.trim().as_bytes(), token.as_bytes())) {
                let mut r = problem(
                    StatusCode::UNAUTHORIZED,
                    "Unauthorized",
                    "this server needs `Authorization: Bearer <token>`",
                );
                r.headers_mut().insert(header::WWW_AUTHENTICATE, header::HeaderValue::from_static("Bearer"));
                return r;
            }
        }
    }
    next.run(req).await
}

fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}
