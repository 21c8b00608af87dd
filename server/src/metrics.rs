//! What `GET /metrics` reports, in the Prometheus text format (version 0.0.4): jobs by status,
//! the queue's length, per running job its steps per second and wall time per stage, the bytes of
//! snapshots and checkpoints written, and HTTP requests by route, method and status. Routes are
//! the router's templates (`/v1/jobs/{id}`), any other path is `other`, so that no client can
//! grow the number of series.

use crate::job::Status;
use crate::App;
use axum::extract::{Request, State};
use axum::http::header;
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use tracing::Instrument;

/// The counters the handlers and workers update.
#[derive(Default)]
pub struct Metrics {
    requests: Mutex<BTreeMap<(&'static str, &'static str, u16), u64>>,
    snapshot_bytes: AtomicU64,
    checkpoint_bytes: AtomicU64,
    running: Mutex<BTreeMap<String, JobRate>>,
}

/// A running job's rate since it (re)started and its wall time per stage (seconds).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JobRate {
    pub steps_per_s: f64,
    pub stages: Vec<(&'static str, f64)>,
}

impl Metrics {
    pub fn snapshot_written(&self, bytes: u64) {
        self.snapshot_bytes.fetch_add(bytes, Ordering::Relaxed);
    }
    pub fn checkpoint_written(&self, bytes: u64) {
        self.checkpoint_bytes.fetch_add(bytes, Ordering::Relaxed);
    }
    pub fn job_running(&self, id: &str, rate: JobRate) {
        self.running.lock().unwrap_or_else(|e| e.into_inner()).insert(id.to_string(), rate);
    }
    pub fn job_stopped(&self, id: &str) {
        self.running.lock().unwrap_or_else(|e| e.into_inner()).remove(id);
    }
    fn request(&self, route: &'static str, method: &'static str, status: u16) {
        *self.requests.lock().unwrap_or_else(|e| e.into_inner()).entry((route, method, status)).or_default() += 1;
    }

    /// The text exposition; `jobs` is the count per status.
    pub fn render(&self, jobs: &[(Status, usize)]) -> String {
        let mut out = String::new();
        head(&mut out, "fluidbed_jobs", "gauge", "Jobs in the store by status.");
        for (s, n) in jobs {
            let _ = writeln!(out, "fluidbed_jobs{{status=\"{}\"}} {n}", s.as_str());
        }
        let queued = jobs.iter().find(|(s, _)| *s == Status::Queued).map_or(0, |j| j.1);
        head(&mut out, "fluidbed_queue_length", "gauge", "Jobs waiting for a worker.");
        let _ = writeln!(out, "fluidbed_queue_length {queued}");
        let running = self.running.lock().unwrap_or_else(|e| e.into_inner()).clone();
        head(
            &mut out,
            "fluidbed_job_steps_per_second",
            "gauge",
            "DEM steps per wall second of each running job since it (re)started.",
        );
        for (id, r) in &running {
            let _ = writeln!(out, "fluidbed_job_steps_per_second{{job=\"{id}\"}} {}", r.steps_per_s);
        }
        head(
            &mut out,
            "fluidbed_job_stage_seconds",
            "gauge",
            "Wall time per stage of each running job since it (re)started.",
        );
        for (id, r) in &running {
            for (stage, s) in &r.stages {
                let _ = writeln!(out, "fluidbed_job_stage_seconds{{job=\"{id}\",stage=\"{stage}\"}} {s}");
            }
        }
        head(&mut out, "fluidbed_snapshot_bytes_written_total", "counter", "Bytes of snapshot files written.");
        let _ = writeln!(out, "fluidbed_snapshot_bytes_written_total {}", self.snapshot_bytes.load(Ordering::Relaxed));
        head(&mut out, "fluidbed_checkpoint_bytes_written_total", "counter", "Bytes of checkpoint files written.");
        let _ =
            writeln!(out, "fluidbed_checkpoint_bytes_written_total {}", self.checkpoint_bytes.load(Ordering::Relaxed));
        head(
            &mut out,
            "fluidbed_http_requests_total",
            "counter",
            "HTTP requests answered, by route template, method and status.",
        );
        for ((route, method, status), n) in self.requests.lock().unwrap_or_else(|e| e.into_inner()).iter() {
            let _ = writeln!(
                out,
                "fluidbed_http_requests_total{{route=\"{route}\",method=\"{method}\",status=\"{status}\"}} {n}"
            );
        }
        out
    }
}

fn head(out: &mut String, name: &str, kind: &str, help: &str) {
    let _ = writeln!(out, "# HELP {name} {help}\n# TYPE {name} {kind}");
}

/// The route template a path belongs to (as the router names it), or `other`.
pub fn route_of(path: &str) -> &'static str {
    let segs: Vec<&str> = path.split('/').skip(1).collect();
    match segs[..] {
        [""] => "/",
        ["healthz"] => "/healthz",
        ["metrics"] => "/metrics",
        ["openapi.json"] => "/openapi.json",
        ["v1", "schema", "case"] => "/v1/schema/case",
        ["v1", "jobs"] => "/v1/jobs",
        ["v1", "jobs", _] => "/v1/jobs/{id}",
        ["v1", "jobs", _, "events"] => "/v1/jobs/{id}/events",
        ["v1", "jobs", _, "snapshots"] => "/v1/jobs/{id}/snapshots",
        ["v1", "jobs", _, "snapshots", _] => "/v1/jobs/{id}/snapshots/{n}",
        ["v1", "jobs", _, "pressure-drop"] => "/v1/jobs/{id}/pressure-drop",
        ["v1", "jobs", _, "analysis"] => "/v1/jobs/{id}/analysis",
        ["v1", "jobs", _, "analysis", _] => "/v1/jobs/{id}/analysis/{figure}",
        ["v1", "sweeps"] => "/v1/sweeps",
        ["v1", "sweeps", _] => "/v1/sweeps/{id}",
        ["jobs", _] => "/jobs/{id}",
        ["ui", "cases.json"] => "/ui/cases.json",
        ["ui", _] => "/ui/{file}",
        _ => "other",
    }
}

fn method_of(m: &axum::http::Method) -> &'static str {
    match m.as_str() {
        "GET" => "GET",
        "POST" => "POST",
        "DELETE" => "DELETE",
        "HEAD" => "HEAD",
        "OPTIONS" => "OPTIONS",
        "PUT" => "PUT",
        "PATCH" => "PATCH",
        _ => "other",
    }
}

/// The outermost layer: a span per request (method, route), its answer logged and counted.
pub async fn observe(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    let (route, method) = (route_of(req.uri().path()), method_of(req.method()));
    let span = tracing::info_span!("request", method, route);
    let t0 = Instant::now();
    let resp = next.run(req).instrument(span.clone()).await;
    let status = resp.status().as_u16();
    app.metrics.request(route, method, status);
    span.in_scope(|| tracing::debug!(status, ms = t0.elapsed().as_secs_f64() * 1e3, "answered"));
    resp
}

/// Prometheus metrics (text format 0.0.4): jobs by status, queue length, per running job steps/s
/// and stage times, bytes written, requests by route and status.
#[utoipa::path(get, path = "/metrics", operation_id = "get_metrics", tag = "meta",
    responses((status = 200, description = "Prometheus text format", body = String, content_type = "text/plain")))]
pub async fn handler(State(app): State<Arc<App>>) -> Response {
    let a = app.clone();
    let counts = tokio::task::spawn_blocking(move || {
        Status::ALL.iter().map(|&s| a.store.count(s).map(|n| (s, n))).collect::<anyhow::Result<Vec<_>>>()
    })
    .await;
    match counts {
        Ok(Ok(jobs)) => {
            ([(header::CONTENT_TYPE, "text/plain; version=0.0.4; charset=utf-8")], app.metrics.render(&jobs))
                .into_response()
        }
        Ok(Err(e)) => crate::api::problem::internal(e),
        Err(e) => crate::api::problem::internal(e.into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_router_template_is_its_own_route_and_other_paths_are_other() {
        // (every documented path is checked in api::openapi's tests)
        for t in ["/", "/metrics", "/v1/jobs/{id}/snapshots/{n}", "/ui/cases.json", "/ui/{file}"] {
            assert_eq!(route_of(t), t);
        }
        assert_eq!(route_of("/v1/jobs/8d8b803de9e7b632/snapshots/12"), "/v1/jobs/{id}/snapshots/{n}");
        for p in ["/x", "/v1/jobs/a/b/c/d", "/v1", "/ui/a/b", "//"] {
            assert_eq!(route_of(p), "other", "{p}");
        }
    }

    #[test]
    fn render_gives_each_family_with_help_type_and_labelled_samples() {
        let m = Metrics::default();
        m.snapshot_written(100);
        m.snapshot_written(23);
        m.job_running("abc", JobRate { steps_per_s: 1500.5, stages: vec![("gas", 2.5), ("voidage", 0.25)] });
        m.request("/v1/jobs", "POST", 201);
        m.request("/v1/jobs", "POST", 201);
        let text = m.render(&[(Status::Queued, 2), (Status::Running, 1)]);
        for line in [
            "# TYPE fluidbed_jobs gauge",
            "fluidbed_jobs{status=\"queued\"} 2",
            "fluidbed_queue_length 2",
            "fluidbed_job_steps_per_second{job=\"abc\"} 1500.5",
            "fluidbed_job_stage_seconds{job=\"abc\",stage=\"gas\"} 2.5",
            "fluidbed_snapshot_bytes_written_total 123",
            "fluidbed_http_requests_total{route=\"/v1/jobs\",method=\"POST\",status=\"201\"} 2",
        ] {
            assert!(text.lines().any(|l| l == line), "no line `{line}` in\n{text}");
        }
        m.job_stopped("abc");
        assert!(!m.render(&[]).contains("job=\"abc\""), "a stopped job leaves no series");
    }
}
