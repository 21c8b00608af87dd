//! The OpenAPI 3.1 document served at `/openapi.json`, generated: the operations from the
//! handlers' `#[utoipa::path]` (api::routes), the schemas from fluidbed-api's types, the case
//! schema merged in from fluidbed-core, the event stream's schema (fluidbed-api's events), the
//! bearer-token scheme, and a 401 on every operation that needs the token. docs/openapi.json is a copy that a test keeps current.

use axum::http::header;
use axum::response::{IntoResponse, Response};
use fluidbed_api::{ProgressEvent, SnapshotEvent, StatusEvent, BEARER};
use serde_json::{json, Value};
use std::sync::OnceLock;
use utoipa::openapi::security::{HttpAuthScheme, HttpBuilder, SecurityScheme};
use utoipa::{Modify, OpenApi};

#[derive(OpenApi)]
#[openapi(
    info(
        title = "fluidbed",
        description = "DEM-CFD jobs for cylindrical gas-fluidized beds (docs/API.md). Errors are RFC 9457 \
            problem documents. A server started with `--token` needs `Authorization: Bearer <token>` on every \
            route but /healthz and the live page (/, /jobs/{id}, /ui/), and answers 401 without it; a server \
            without a token needs none."
    ),
    modifiers(&BearerToken),
    security(("bearer" = [])),
    components(schemas(StatusEvent, ProgressEvent, SnapshotEvent)),
    tags(
        (name = "jobs", description = "Submit, list, watch and cancel jobs"),
        (name = "sweeps", description = "Submit a base case and a grid of values as one job per point; their summaries"),
        (name = "results", description = "Snapshots and the pressure-drop series"),
        (name = "meta", description = "Schemas, health, metrics"),
        (name = "page", description = "The live page (static files; no token)"),
    )
)]
pub struct ApiDoc;

/// The `bearer` security scheme.
struct BearerToken;

impl Modify for BearerToken {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        let scheme = HttpBuilder::new()
            .scheme(HttpAuthScheme::Bearer)
            .description(Some("The server's --token (or FLUIDBED_TOKEN), when it was started with one"))
            .build();
        doc.components.get_or_insert_with(Default::default).add_security_scheme(BEARER, SecurityScheme::Http(scheme));
    }
}

/// The whole document.
pub fn document() -> Value {
    let mut doc = serde_json::to_value(super::routes().into_openapi()).expect("the document serialises");
    fluidbed_api::case_schema::merge_into(&mut doc);
    // A sweep's base is a case.
    doc["components"]["schemas"]["SweepRequest"]["properties"]["base"] = json!({ "$ref": fluidbed_api::case_schema::CASE_REF, "description": "A case; each point's values are set in a copy of it." });
    doc["components"]["schemas"][fluidbed_api::events::STREAM_EVENT] = fluidbed_api::events::stream_event_schema();
    declare_unauthorized(&mut doc);
    doc
}

/// The document as served (built once).
pub fn text() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| serde_json::to_string_pretty(&document()).expect("the document serialises") + "\n")
}

const METHODS: [&str; 8] = ["get", "put", "post", "delete", "options", "head", "patch", "trace"];

/// Whether an operation needs the token: its own `security`, else the document's, has no empty
/// (anonymous) requirement.
pub fn needs_token(doc: &Value, op: &Value) -> bool {
    let security = op.get("security").or_else(|| doc.get("security"));
    match security.and_then(Value::as_array) {
        Some(reqs) => !reqs.is_empty() && !reqs.iter().any(|r| r.as_object().is_some_and(|o| o.is_empty())),
        None => false,
    }
}

/// Add the 401 answer to every operation that needs the token.
fn declare_unauthorized(doc: &mut Value) {
    let snapshot = doc.clone();
    let unauthorized = json!({
        "description": "No or a wrong bearer token (only when the server was started with --token)",
        "headers": {"WWW-Authenticate": {"schema": {"type": "string"}, "description": "Bearer"}},
        "content": {"application/problem+json": {"schema": {"$ref": "#/components/schemas/Problem"}}},
    });
    let Some(paths) = doc.get_mut("paths").and_then(Value::as_object_mut) else { return };
    for item in paths.values_mut() {
        for m in METHODS {
            if let Some(op) = item.get_mut(m) {
                if needs_token(&snapshot, op) {
                    op["responses"]["401"] = unauthorized.clone();
                }
            }
        }
    }
}

/// This document.
#[utoipa::path(get, path = "/openapi.json", operation_id = "get_openapi", tag = "meta",
    responses((status = 200, description = "The OpenAPI 3.1 document", body = Object)))]
pub async fn serve() -> Response {
    ([(header::CONTENT_TYPE, "application/json")], text()).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_openapi_is_current() {
        // docs/openapi.json is the document the server serves; regenerate with
        // FLUIDBED_WRITE_OPENAPI=1 cargo test -p fluidbed-server published_openapi_is_current
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/openapi.json");
        if std::env::var_os("FLUIDBED_WRITE_OPENAPI").is_some() {
            std::fs::write(path, text()).unwrap();
        }
        let have = std::fs::read_to_string(path).unwrap_or_default();
        assert!(have == text(), "docs/openapi.json is stale: regenerate it (see this test's comment)");
    }

    #[test]
    fn every_reference_resolves_and_the_post_body_is_the_case() {
        let doc = document();
        assert_eq!(doc["openapi"], "3.1.0");
        assert_eq!(fluidbed_api::case_schema::unresolved_refs(&doc), Vec::<String>::new());
        let body = &doc["paths"]["/v1/jobs"]["post"]["requestBody"]["content"]["application/json"]["schema"];
        assert_eq!(body["$ref"], fluidbed_api::case_schema::CASE_REF);
        let case = &doc["components"]["schemas"]["Case"];
        assert_eq!(case["required"], Case::json_schema()["required"]);
        assert!(case["properties"]["particles"].is_object());
    }

    #[test]
    fn the_bearer_scheme_is_declared_and_every_guarded_operation_answers_401() {
        let doc = document();
        assert_eq!(
            doc["components"]["securitySchemes"][BEARER],
            json!({"type": "http", "scheme": "bearer",
            "description": "The server's --token (or FLUIDBED_TOKEN), when it was started with one"})
        );
        let mut guarded = 0;
        for (path, item) in doc["paths"].as_object().unwrap() {
            for (method, op) in item.as_object().unwrap() {
                // the server's own rule (api::auth) decides; the document must say the same
                let open = path == "/healthz" || crate::page::is_page_path(path);
                assert_eq!(needs_token(&doc, op), !open, "{method} {path}");
                assert_eq!(op["responses"].get("401").is_some(), !open, "{method} {path}");
                guarded += usize::from(!open);
            }
        }
        assert!(guarded >= 11, "{guarded} guarded operations");
    }

    #[test]
    fn operation_ids_are_unique() {
        let doc = document();
        let mut ids: Vec<&str> = doc["paths"]
            .as_object()
            .unwrap()
            .values()
            .flat_map(|item| item.as_object().unwrap().values().map(|op| op["operationId"].as_str().unwrap()))
            .collect();
        let n = ids.len();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), n, "{ids:?}");
    }

    #[test]
    fn every_documented_path_is_a_metrics_route() {
        for path in document()["paths"].as_object().unwrap().keys() {
            assert_eq!(crate::metrics::route_of(path), path, "metrics::route_of names {path}");
        }
    }

    use fluidbed_core::case::Case;
}
