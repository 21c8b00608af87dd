//! The HTTP API, versioned under /v1 (see docs/API.md and GET /openapi.json). Every route is
//! registered through utoipa-axum from its handler's `#[utoipa::path]`, so the OpenAPI document
//! (openapi.rs) lists exactly what is routed.

mod analysis;
mod downloads;
mod jobs;
pub mod openapi;
pub mod problem;
mod sweeps;

use crate::App;
use axum::extract::{DefaultBodyLimit, Request, State};
use axum::http::{header, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::{Json, Router};
use fluidbed_api::{Health, HealthStatus};
use problem::problem;
use std::sync::Arc;
use tower_http::timeout::{RequestBodyTimeoutLayer, TimeoutLayer};
use utoipa::OpenApi;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

/// Every route with its OpenAPI operation (the page's included).
pub fn routes() -> OpenApiRouter<Arc<App>> {
    OpenApiRouter::with_openapi(openapi::ApiDoc::openapi())
        .routes(routes!(jobs::list, jobs::create))
        .routes(routes!(jobs::get_one, jobs::cancel))
        .routes(routes!(jobs::events))
        .routes(routes!(downloads::list))
        .routes(routes!(downloads::one))
        .routes(routes!(downloads::pressure_drop))
        .routes(routes!(sweeps::list, sweeps::create))
        .routes(routes!(sweeps::get_one, sweeps::cancel))
        .routes(routes!(analysis::get))
        .routes(routes!(analysis::figure))
        .routes(routes!(schema))
        .routes(routes!(openapi::serve))
        .routes(routes!(healthz))
        .routes(routes!(crate::metrics::handler))
        .merge(crate::page::routes())
}

pub fn router(app: Arc<App>) -> Router {
    let limit = app.config.max_body_bytes;
    let (routes, _) = routes().split_for_parts();
    routes
        .fallback(not_found)
        .layer(axum::middleware::from_fn_with_state(app.clone(), auth))
        .layer(DefaultBodyLimit::max(limit))
        .layer(RequestBodyTimeoutLayer::new(app.config.body_read_timeout))
        .layer(TimeoutLayer::with_status_code(StatusCode::REQUEST_TIMEOUT, app.config.request_timeout))
        .layer(axum::middleware::from_fn(problem::errors_as_problems))
        .layer(axum::middleware::from_fn_with_state(app.clone(), crate::metrics::observe))
        .with_state(app)
}

/// Liveness: 200 while the data directory takes writes; 503 with the cause (a full or read-only
/// disk). Never needs the token.
#[utoipa::path(get, path = "/healthz", operation_id = "health", tag = "meta", security(()),
    responses(
        (status = 200, description = "Healthy", body = Health),
        (status = 503, description = "The data directory takes no writes", body = Health),
    ))]
async fn healthz(State(app): State<Arc<App>>) -> Response {
    let a = app.clone();
    let (ok, data_dir) = match tokio::task::spawn_blocking(move || a.health.check(&a.store)).await {
        Ok(r) => r,
        Err(e) => return problem::internal(e.into()),
    };
    let body = Health {
        status: if ok { HealthStatus::Ok } else { HealthStatus::Degraded },
        version: env!("CARGO_PKG_VERSION").to_string(),
        data_dir,
    };
    let code = if ok { StatusCode::OK } else { StatusCode::SERVICE_UNAVAILABLE };
    (code, Json(body)).into_response()
}

/// The case JSON Schema (draft 7, also docs/case.schema.json; the same schema is the
/// `Case` component of this document).
#[utoipa::path(get, path = "/v1/schema/case", operation_id = "get_case_schema", tag = "meta",
    responses((status = 200, description = "A JSON Schema", body = Object)))]
async fn schema() -> Json<serde_json::Value> {
    Json(fluidbed_core::case::Case::json_schema())
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
