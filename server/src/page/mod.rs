//! The live page: static HTML, CSS and JavaScript embedded in the binary (no build step), served
//! at `/` (the job list and the submit form) and `/jobs/{id}` (one job, live from its event
//! stream). The page reads the same `/v1` API as the CLI and has no API of its own; the shipped
//! example cases come with it as one static JSON file.

use axum::extract::Path;
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

/// Files under `/ui/`: name, content type, content.
const ASSETS: &[(&str, &str, &str)] = &[
    ("style.css", "text/css; charset=utf-8", include_str!("assets/style.css")),
    ("common.js", "text/javascript; charset=utf-8", include_str!("assets/common.js")),
    ("index.js", "text/javascript; charset=utf-8", include_str!("assets/index.js")),
    ("job.js", "text/javascript; charset=utf-8", include_str!("assets/job.js")),
    ("draw.js", "text/javascript; charset=utf-8", include_str!("assets/draw.js")),
];

/// The shipped cases (`cases/`), offered by the submit form.
const CASES: &[(&str, &str)] = &[
    ("quickstart.json", include_str!("../../../cases/quickstart.json")),
    ("dem-pour.json", include_str!("../../../cases/dem-pour.json")),
    ("packed-bed.json", include_str!("../../../cases/packed-bed.json")),
    ("bubbling-44mm.json", include_str!("../../../cases/bubbling-44mm.json")),
    ("bubbling-44mm-paper-cells.json", include_str!("../../../cases/bubbling-44mm-paper-cells.json")),
    ("pressure-oscillation-50mm.json", include_str!("../../../cases/pressure-oscillation-50mm.json")),
    ("slugging-50mm-U0.37.json", include_str!("../../../cases/slugging-50mm-U0.37.json")),
    ("slugging-50mm-U0.425.json", include_str!("../../../cases/slugging-50mm-U0.425.json")),
    ("slugging-50mm-U0.54.json", include_str!("../../../cases/slugging-50mm-U0.54.json")),
    ("slugging-50mm-U0.60.json", include_str!("../../../cases/slugging-50mm-U0.60.json")),
];

const INDEX_HTML: &str = include_str!("assets/index.html");
const JOB_HTML: &str = include_str!("assets/job.html");

/// The page's routes; none needs the bearer token (the files hold no data: the scripts ask for
/// the token when the API answers 401).
pub fn routes<S: Clone + Send + Sync + 'static>() -> OpenApiRouter<S> {
    OpenApiRouter::new().routes(routes!(index)).routes(routes!(job_page)).routes(routes!(cases)).routes(routes!(asset))
}

/// The live page: the job list and the submit form.
#[utoipa::path(get, path = "/", operation_id = "page_jobs", tag = "page", security(()),
    responses((status = 200, description = "HTML", body = String, content_type = "text/html")))]
async fn index() -> Response {
    html(INDEX_HTML)
}

/// The live page of one job (the page itself reads the job through the API).
#[utoipa::path(get, path = "/jobs/{id}", operation_id = "page_job", tag = "page", security(()),
    params(("id" = String, Path, description = "The job id")),
    responses((status = 200, description = "HTML", body = String, content_type = "text/html")))]
async fn job_page(Path(_id): Path<String>) -> Response {
    html(JOB_HTML)
}

/// Whether a path is one of the page's (served without the token).
pub fn is_page_path(path: &str) -> bool {
    path == "/" || path.starts_with("/ui/") || path.strip_prefix("/jobs/").is_some_and(|id| !id.contains('/'))
}

fn html(body: &'static str) -> Response {
    ([(header::CONTENT_TYPE, "text/html; charset=utf-8"), (header::CACHE_CONTROL, "no-cache")], body).into_response()
}

/// The page's scripts and stylesheet.
#[utoipa::path(get, path = "/ui/{file}", operation_id = "page_file", tag = "page", security(()),
    params(("file" = String, Path, description = "style.css, common.js, index.js, job.js, draw.js")),
    responses(
        (status = 200, description = "The file", content((String = "text/css"), (String = "text/javascript"))),
        (status = 404, description = "No such file", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    ))]
async fn asset(Path(file): Path<String>) -> Response {
    match ASSETS.iter().find(|(name, _, _)| *name == file) {
        Some((_, kind, body)) => {
            ([(header::CONTENT_TYPE, *kind), (header::CACHE_CONTROL, "no-cache")], *body).into_response()
        }
        None => {
            crate::api::problem::problem(StatusCode::NOT_FOUND, "Not found", &format!("the page has no file {file}"))
        }
    }
}

/// `{"cases": [{"file", "text"}…]}`: the shipped cases as their files read.
#[utoipa::path(get, path = "/ui/cases.json", operation_id = "page_cases", tag = "page", security(()),
    responses((status = 200, description = "The shipped cases", body = Object)))]
async fn cases() -> Response {
    let list: Vec<serde_json::Value> =
        CASES.iter().map(|(file, text)| serde_json::json!({ "file": file, "text": text })).collect();
    axum::Json(serde_json::json!({ "cases": list })).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_case_is_embedded_and_parses() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../cases");
        let mut shipped: Vec<String> = std::fs::read_dir(dir)
            .expect("cases folder")
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".json"))
            .collect();
        shipped.sort();
        let mut embedded: Vec<String> = CASES.iter().map(|(f, _)| f.to_string()).collect();
        embedded.sort();
        assert_eq!(embedded, shipped, "page::CASES lists every file of cases/");
        for (file, text) in CASES {
            let v: serde_json::Value = serde_json::from_str(text).unwrap_or_else(|e| panic!("{file}: {e}"));
            assert!(v["name"].is_string(), "{file} has a name for the picker");
        }
    }

    #[test]
    fn page_paths_are_the_page_and_its_files_only() {
        for p in ["/", "/ui/job.js", "/jobs/8d8b803de9e7b632"] {
            assert!(is_page_path(p), "{p}");
        }
        for p in ["/v1/jobs", "/jobs/x/events", "/openapi.json", "/healthz"] {
            assert!(!is_page_path(p), "{p}");
        }
    }
}
