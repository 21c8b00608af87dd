//! The HTTP fuzz of case submissions (issue 22, item 4): seeded mutations of the shipped cases
//! (cases/*.json) posted to a real server on loopback, every answer judged (`judge`), panics
//! anywhere in the process counted. Shared by `tests/tests/http_fuzz.rs` (300 cases) and
//! `examples/http-fuzz.rs` (10,000).

pub mod judge;
pub mod mutate;

use crate::{test_config, TempDir};
use judge::Verdict;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Once;
use std::time::{Duration, Instant};

/// Panics seen by the hook `count_panics` installs (any thread of the process: the server's too).
static PANICS: AtomicUsize = AtomicUsize::new(0);

/// Count every panic from now on (the default hook still prints it).
pub fn count_panics() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            PANICS.fetch_add(1, Ordering::SeqCst);
            previous(info);
        }));
    });
}

/// This process's peak resident memory (VmHWM), in MiB.
pub fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kb = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .unwrap_or(0.0);
    kb / 1024.0
}

/// The shipped cases, parsed.
pub fn shipped_cases() -> Vec<Value> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../cases");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .expect("cases/")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| serde_json::from_str(&std::fs::read_to_string(p).expect("read case")).expect("a shipped case is JSON"))
        .collect()
}

/// The servers' body limit (`test_config`: 256 KiB).
const MAX_BODY: usize = 256 * 1024;

/// A request unanswered after this long is a hang (its timeout, a transport error): validation
/// must not hang on any body. Not a speed bound: the slowest answer is reported, not judged.
pub const HANG_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(60);

/// What a fuzz run found.
#[derive(Debug, Default)]
pub struct Report {
    pub cases: usize,
    pub status_5xx: usize,
    pub panics: usize,
    pub unnamed_4xx: usize,
    /// Answers neither 201 nor an error, and non-JSON content types accepted.
    pub unexpected: usize,
    /// Requests that got no answer (a reset connection, a timeout).
    pub transport_errors: usize,
    pub accepted: usize,
    /// Bodies over the limit whose 413 the client missed while still sending (not a failure).
    pub cut_off_oversize: usize,
    /// The slowest answer, ms (reported only; a request past `HANG_TIMEOUT` is a transport error).
    pub slowest_ms: f64,
    pub by_status: BTreeMap<u16, usize>,
    /// The 10^8-particle case was refused with 422 naming /bed/generated/count.
    pub huge_bed_refused: bool,
    /// Growth of the process's peak memory over the run, MiB.
    pub peak_rss_growth_mib: f64,
    pub seconds: f64,
    /// The first failures: the submission's label and what was wrong.
    pub failures: Vec<String>,
}

impl Report {
    /// Nothing failed.
    pub fn clean(&self) -> bool {
        self.status_5xx + self.panics + self.unnamed_4xx + self.unexpected + self.transport_errors == 0
            && self.huge_bed_refused
    }
    /// The last line of the example.
    pub fn json_line(&self) -> String {
        json!({
            "fuzz": "http", "cases": self.cases, "status_5xx": self.status_5xx, "panics": self.panics,
            "unnamed_4xx": self.unnamed_4xx, "unexpected": self.unexpected,
            "transport_errors": self.transport_errors, "accepted": self.accepted,
            "slowest_ms": self.slowest_ms.round(), "cut_off_oversize": self.cut_off_oversize,
            "huge_bed_refused": self.huge_bed_refused,
            "peak_rss_growth_mib": (self.peak_rss_growth_mib * 10.0).round() / 10.0,
            "seconds": (self.seconds * 10.0).round() / 10.0,
            "by_status": self.by_status.iter().map(|(k, v)| (k.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
        })
        .to_string()
    }
    fn fail(&mut self, label: &str, what: String) {
        if self.failures.len() < 20 {
            self.failures.push(format!("[{label}] {what}"));
        }
    }
}

/// Post `n` fuzzed submissions (seeded by `seed`) to a fresh server with no workers (accepted
/// jobs only queue and are cancelled at once), one after another.
pub async fn run(n: usize, seed: u64) -> Report {
    count_panics();
    let panics0 = PANICS.load(Ordering::SeqCst);
    let rss0 = peak_rss_mib();
    let t0 = Instant::now();
    let dir = TempDir::new("fuzz");
    let mut cfg = test_config(dir.path(), None);
    assert_eq!(cfg.max_body_bytes, MAX_BODY);
    cfg.workers = 0;
    cfg.submissions_per_s = 0.0;
    let server = fluidbed_server::Server::start(cfg).expect("server starts");
    let (base, jobs) = (server.url(), format!("{}/v1/jobs", server.url()));
    let http = reqwest::Client::builder().timeout(Duration::from_secs(60)).build().expect("client");
    let bases = shipped_cases();
    let mut report = Report::default();

    // 10^8 particles: refused by validation, so nothing of that size is ever allocated.
    let huge = mutate::hundred_million_particles(&bases[0]);
    let r = http.post(&jobs).header("content-type", "application/json").body(huge.body).send().await;
    if let Ok(r) = r {
        let p: Value = r.json().await.unwrap_or(Value::Null);
        report.huge_bed_refused = p["status"] == 422
            && p["errors"].as_array().into_iter().flatten().any(|e| e["pointer"] == "/bed/generated/count");
    }

    let mut prev = (0u16, 0usize);
    for i in 0..n {
        let s = mutate::submission(&bases, seed, i as u64);
        report.cases += 1;
        let len = s.body.len();
        let mut req = http.post(&jobs).timeout(HANG_TIMEOUT).body(s.body);
        if let Some(ct) = s.content_type {
            req = req.header("content-type", ct);
        }
        let sent = Instant::now();
        let r = match req.send().await {
            Ok(r) => r,
            // A body over the limit is answered 413 while it is still being sent; the client
            // may see only the closed connection.
            Err(_) if len > MAX_BODY => {
                report.cut_off_oversize += 1;
                continue;
            }
            Err(e) => {
                let mut why = format!("{e}");
                let mut src = std::error::Error::source(&e);
                while let Some(c) = src {
                    why.push_str(&format!(": {c}"));
                    src = c.source();
                }
                report.transport_errors += 1;
                report.fail(&s.label, format!("no answer to {len} bytes (after {prev:?}): {why}"));
                continue;
            }
        };
        let status = r.status().as_u16();
        prev = (status, len);
        *report.by_status.entry(status).or_default() += 1;
        let ct = r.headers().get("content-type").and_then(|v| v.to_str().ok()).map(str::to_string);
        let location = r.headers().get("location").and_then(|v| v.to_str().ok()).map(str::to_string);
        let body = r.bytes().await.unwrap_or_default();
        let ms = sent.elapsed().as_secs_f64() * 1e3;
        report.slowest_ms = report.slowest_ms.max(ms);
        match judge::judge(s.content_type, status, ct.as_deref(), &body, s.value.as_ref()) {
            Verdict::Fine => {}
            Verdict::ServerError(w) => {
                report.status_5xx += 1;
                report.fail(&s.label, w);
            }
            Verdict::Unnamed(w) => {
                report.unnamed_4xx += 1;
                report.fail(&s.label, w);
            }
            Verdict::Unexpected(w) => {
                report.unexpected += 1;
                report.fail(&s.label, w);
            }
        }
        if status == 201 {
            report.accepted += 1;
            let cancelled = match location {
                Some(l) => http.delete(format!("{base}{l}")).send().await.map(|r| r.status().as_u16()).ok(),
                None => None,
            };
            if cancelled != Some(202) {
                report.unexpected += 1;
                report.fail(&s.label, format!("cancel of the accepted job answered {cancelled:?}"));
            }
        }
    }
    let alive = http.get(format!("{base}/healthz")).send().await.map(|r| r.status().as_u16()).ok();
    if alive != Some(200) {
        report.unexpected += 1;
        report.fail("after the run", format!("/healthz answered {alive:?}"));
    }
    server.shutdown();
    report.panics = PANICS.load(Ordering::SeqCst) - panics0;
    report.peak_rss_growth_mib = peak_rss_mib() - rss0;
    report.seconds = t0.elapsed().as_secs_f64();
    report
}
