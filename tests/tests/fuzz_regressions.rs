//! What the HTTP fuzz (issue 22, item 4) found, each kept as a case of its own: a null field
//! named by its pointer, a deeply nested value echoed in a readable 422, a refused body that
//! does not break the client's next request, and cases whose checks were quadratic or allocated
//! a grid beyond the bounds before refusing it.

use fluidbed_tests::*;
use serde_json::{json, Value};
use std::time::{Duration, Instant};

async fn post(http: &reqwest::Client, url: &str, ct: &str, body: String) -> (u16, Value) {
    let r = http.post(url).header("content-type", ct).body(body).send().await.expect("an answer");
    (r.status().as_u16(), r.json().await.expect("a problem document serde_json reads"))
}

fn pointers(p: &Value) -> Vec<&str> {
    p["errors"].as_array().into_iter().flatten().filter_map(|e| e["pointer"].as_str()).collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn what_the_fuzz_found_stays_fixed() {
    let dir = TempDir::new("fuzz-regressions");
    let mut cfg = test_config(dir.path(), None);
    cfg.workers = 0;
    cfg.submissions_per_s = 0.0;
    cfg.max_body_bytes = 16 << 20;
    let server = fluidbed_server::Server::start(cfg).expect("server starts");
    let jobs = format!("{}/v1/jobs", server.url());
    let http = reqwest::Client::new();
    let json_ct = "application/json";

    // `"end_time_s": null` passed the per-section check and was refused at pointer "".
    let mut null_end = lattice_case(2, 1, 0.01, 0.005);
    null_end["end_time_s"] = Value::Null;
    let (s, p) = post(&http, &jobs, json_ct, null_end.to_string()).await;
    assert_eq!((s, pointers(&p)), (422, vec!["/end_time_s"]), "{p}");

    // A value nested 200 deep was echoed whole: the 422 was past serde_json's depth limit.
    let mut deep = json!(1);
    for _ in 0..125 {
        deep = json!([deep]);
    }
    let mut nested = lattice_case(2, 1, 0.01, 0.005);
    nested["gas"] = json!({ "a": deep });
    let (s, p) = post(&http, &jobs, json_ct, nested.to_string()).await;
    assert_eq!((s, pointers(&p)), (422, vec!["/gas/a"]), "{p}");

    // A 415 for an unread body over the limit left the connection open: the next request on it
    // was lost. Now the body limit answers first and closes it.
    let r = http.post(&jobs).header("content-type", "text/plain").body("x".repeat(17 << 20)).send().await;
    if let Ok(r) = r {
        assert_eq!(r.status(), 413);
    }
    for _ in 0..5 {
        let (s, _) = post(&http, &jobs, "text/plain", lattice_case(2, 1, 0.01, 0.005).to_string()).await;
        assert_eq!(s, 415);
    }

    // 300,000 particles at one point: the overlap check was quadratic (minutes).
    let mut one_point = lattice_case(2, 1, 0.01, 0.005);
    one_point["bed"] = json!({ "explicit": { "positions_m": vec![[0.0, 0.0, 0.01]; 300_000] } });
    let t0 = Instant::now();
    let (s, p) = post(&http, &jobs, json_ct, one_point.to_string()).await;
    assert_eq!(s, 422, "{p}");
    assert!(t0.elapsed() < Duration::from_secs(20), "refused in {:?}", t0.elapsed());
    assert!(p["errors"].as_array().unwrap().len() <= 10, "a few problems, not one per pair");

    // A gas step with 10^4 annuli of 64 cells: the stable-step check built ~50 GB of face
    // geometry before the bounds refused the grid.
    let mut fine = lattice_case(2, 1, 0.01, 0.005);
    fine["column"] = json!({ "diameter_m": 5.0, "height_m": 50.0 });
    fine["gas"] = json!({ "superficial_velocity_m_s": 0.5, "time_step_s": 1e-6 });
    fine["grid"] = json!({ "dr_m": 2.5 / 9_999.0, "n0": 64 });
    let rss0 = fuzz::peak_rss_mib();
    let (s, p) = post(&http, &jobs, json_ct, fine.to_string()).await;
    assert_eq!(s, 422, "{p}");
    assert!(pointers(&p).contains(&"/grid/dr_m"), "{p}");
    assert!(fuzz::peak_rss_mib() - rss0 < 256.0, "no grid was built");

    let listed: Value = http.get(&jobs).send().await.unwrap().json().await.unwrap();
    assert_eq!(listed["total"], 0, "nothing refused became a job");
    server.shutdown();
}
