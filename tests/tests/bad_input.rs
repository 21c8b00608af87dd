//! Bad requests get RFC 9457 answers with the right status, and leave nothing behind.

use fluidbed_tests::*;
use serde_json::{json, Value};

async fn post(http: &reqwest::Client, url: &str, body: impl Into<reqwest::Body>) -> (u16, Value) {
    let r = http.post(url).header("content-type", "application/json").body(body).send().await.unwrap();
    let status = r.status().as_u16();
    assert_eq!(r.headers().get("content-type").map(|v| v.to_str().unwrap()), Some("application/problem+json"));
    (status, r.json().await.unwrap_or(Value::Null))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_requests_are_refused_with_problem_details_and_leave_nothing_behind() {
    let dir = TempDir::new("bad");
    let server = start(dir.path(), None);
    let before = files_under(dir.path());
    let base = server.url();
    let http = reqwest::Client::new();
    let jobs = format!("{base}/v1/jobs");

    let (s, p) = post(&http, &jobs, r#"{"column": "#).await;
    assert_eq!((s, p["status"].as_u64()), (400, Some(400)));

    // Missing sections and an out-of-range value: each named by its JSON pointer.
    let (s, p) = post(&http, &jobs, json!({"particles": {"diameter_m": 0.0012}}).to_string()).await;
    assert_eq!(s, 422);
    let pointers: Vec<&str> = p["errors"].as_array().unwrap().iter().map(|e| e["pointer"].as_str().unwrap()).collect();
    assert!(pointers.contains(&"/column") && pointers.contains(&"/bed"), "{pointers:?}");
    let mut bad = lattice_case(2, 1, 0.01, 0.005);
    bad["particles"]["diameter_m"] = json!(-1.0);
    bad["end_time_s"] = json!(-5.0);
    let (s, p) = post(&http, &jobs, bad.to_string()).await;
    assert_eq!(s, 422);
    let errs = p["errors"].as_array().unwrap();
    for path in ["/particles/diameter_m", "/end_time_s"] {
        let e = errs.iter().find(|e| e["pointer"] == path).unwrap_or_else(|| panic!("{path} named in {p}"));
        assert!(!e["allowed"].as_str().unwrap().is_empty(), "allowed range given for {path}");
    }

    // Over the size limit (256 KiB in these tests).
    let (s, _) = post(&http, &jobs, " ".repeat(300 * 1024)).await;
    assert_eq!(s, 413);

    for path in ["/v1/jobs/does-not-exist", "/v1/jobs/0123456789abcdef/snapshots", "/v1/nothing-here"] {
        assert_eq!(http.get(format!("{base}{path}")).send().await.unwrap().status(), 404, "{path}");
    }
    // A real job, then snapshot names that try to leave its folder.
    let r = http.post(&jobs).json(&lattice_case(2, 1, 0.004, 0.002)).send().await.unwrap();
    let url = format!("{base}{}", r.headers()["location"].to_str().unwrap());
    wait_final(&http, &url, std::time::Duration::from_secs(120)).await;
    for name in ["..%2F..%2Ffluidbed.sqlite", "..", "0%2F..%2F1", "-1", "1e3"] {
        assert_eq!(
            http.get(format!("{url}/snapshots/{name}?format=npy")).send().await.unwrap().status(),
            404,
            "{name}"
        );
    }
    server.shutdown();
    // Only the accepted job added files: no folder or file from the refused requests.
    let id = url.rsplit('/').next().unwrap();
    let added: Vec<_> = files_under(dir.path()).into_iter().filter(|p| !before.contains(p)).collect();
    assert!(
        added.iter().all(|p| p.starts_with(format!("jobs/{id}"))
            || p.starts_with("cache")
            || p.to_string_lossy().starts_with("fluidbed.sqlite")),
        "{added:?}"
    );
    let jobs_dirs: Vec<_> =
        std::fs::read_dir(dir.path().join("jobs")).unwrap().flatten().map(|e| e.file_name()).collect();
    assert_eq!(jobs_dirs.len(), 1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_token_guards_every_route_but_healthz() {
    let dir = TempDir::new("token");
    let server = start(dir.path(), Some("s3cret"));
    let base = server.url();
    let http = reqwest::Client::new();
    assert_eq!(http.get(format!("{base}/healthz")).send().await.unwrap().status(), 200);
    for path in ["/v1/jobs", "/openapi.json", "/v1/schema/case", "/v1/jobs/abc"] {
        assert_eq!(http.get(format!("{base}{path}")).send().await.unwrap().status(), 401, "{path} without token");
        let wrong = http.get(format!("{base}{path}")).bearer_auth("nope").send().await.unwrap();
        assert_eq!(wrong.status(), 401, "{path} with a wrong token");
    }
    let r = http.post(format!("{base}/v1/jobs")).json(&lattice_case(2, 1, 0.004, 0.002)).send().await.unwrap();
    assert_eq!(r.status(), 401);
    assert_eq!(http.get(format!("{base}/v1/jobs")).bearer_auth("s3cret").send().await.unwrap().status(), 200);
    let listed: Value =
        http.get(format!("{base}/v1/jobs")).bearer_auth("s3cret").send().await.unwrap().json().await.unwrap();
    assert_eq!(listed["total"], 0, "the refused POST created no job");
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_full_queue_answers_429_with_retry_after() {
    let dir = TempDir::new("queue");
    let mut cfg = fluidbed_server::Config::new(dir.path().to_path_buf());
    cfg.listen = "127.0.0.1:0".parse().unwrap();
    cfg.max_queued = 1;
    let server = fluidbed_server::Server::start(cfg).unwrap();
    let http = reqwest::Client::new();
    let long = lattice_case(2, 1, 50.0, 0.01);
    let mut codes = Vec::new();
    for _ in 0..3 {
        let r = http.post(format!("{}/v1/jobs", server.url())).json(&long).send().await.unwrap();
        if r.status() == 429 {
            assert!(r.headers().contains_key("retry-after"));
        }
        codes.push(r.status().as_u16());
    }
    assert_eq!(codes[0], 201);
    assert!(codes.contains(&429), "{codes:?}");
    let listed: Value = http.get(format!("{}/v1/jobs", server.url())).send().await.unwrap().json().await.unwrap();
    for j in listed["jobs"].as_array().unwrap() {
        http.delete(format!("{}/v1/jobs/{}", server.url(), j["id"].as_str().unwrap())).send().await.unwrap();
    }
    server.shutdown();
}
