//! Cancel always wins and stops are safe: a cancel during the bed pour stops the pour at once and
//! survives a crash right after it; a clean shutdown (SIGTERM) stops within seconds, checkpoints
//! the running job where it is, and the job resumes from there; a job that took the server down
//! twice is failed, not resumed a third time.

use fluidbed_tests::*;
use serde_json::Value;
use std::time::{Duration, Instant};

fn status(j: &Value) -> &str {
    j["status"].as_str().unwrap_or("")
}

async fn submit(http: &reqwest::Client, base: &str, case: &Value) -> String {
    let r = http.post(format!("{base}/v1/jobs")).json(case).send().await.unwrap();
    assert_eq!(r.status(), 201);
    r.headers()["location"].to_str().unwrap().to_string()
}

fn preparing(j: &Value) -> bool {
    j["message"].as_str().is_some_and(|m| m.starts_with("preparing the bed"))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_cancel_during_the_pour_stops_it_and_survives_a_crash() {
    let http = reqwest::Client::new();
    // ~30k particles: a pour of minutes on one thread.
    let case = poured_case(0.03, 0.1, 0.01);

    // The pour stops at once.
    let dir = TempDir::new("cancel-pour");
    let server = start(dir.path(), None);
    let loc = submit(&http, &server.url(), &case).await;
    let url = format!("{}{loc}", server.url());
    assert!(preparing(&wait_until(&http, &url, Duration::from_secs(30), preparing).await));
    let t0 = Instant::now();
    assert_eq!(http.delete(&url).send().await.unwrap().status(), 202);
    let j = wait_until(&http, &url, Duration::from_secs(60), |j| status(j) == "cancelled").await;
    assert_eq!(status(&j), "cancelled", "{j}");
    assert!(t0.elapsed() < Duration::from_secs(3), "the pour stopped {:?} after the cancel", t0.elapsed());
    server.shutdown();

    // A crash right after the 202: the next server finds the cancel in the store.
    let dir = TempDir::new("cancel-crash");
    let first = start(dir.path(), None);
    let loc = submit(&http, &first.url(), &case).await;
    let url = format!("{}{loc}", first.url());
    wait_until(&http, &url, Duration::from_secs(30), preparing).await;
    assert_eq!(http.delete(&url).send().await.unwrap().status(), 202);
    first.kill();
    let second = start(dir.path(), None);
    let url = format!("{}{loc}", second.url());
    let j = wait_until(&http, &url, Duration::from_secs(60), |j| status(j) == "cancelled").await;
    assert_eq!(status(&j), "cancelled", "{j}");
    second.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_clean_shutdown_checkpoints_where_the_job_is_and_it_resumes_from_there() {
    let http = reqwest::Client::new();
    let dir = TempDir::new("graceful");
    let mut case = lattice_case(8, 4, 2.0, 0.05);
    case["outputs"]["checkpoint_interval_s"] = serde_json::json!(100.0); // only at the end
    let first = start(dir.path(), None);
    let loc = submit(&http, &first.url(), &case).await;
    let url = format!("{}{loc}", first.url());
    let j = wait_until(&http, &url, Duration::from_secs(120), |j| j["time_s"].as_f64().unwrap_or(0.0) > 0.3).await;
    assert_eq!(status(&j), "running", "{j}");
    let t0 = Instant::now();
    first.shutdown();
    assert!(t0.elapsed() < Duration::from_secs(5), "shutdown took {:?}", t0.elapsed());
    let id = loc.rsplit('/').next().unwrap();
    assert!(dir.path().join("jobs").join(id).join("checkpoint.bin").is_file(), "a checkpoint written at the stop");

    // Resumed from the stop, not from the start: a second later it is past where it stopped.
    let second = start(dir.path(), None);
    let url = format!("{}{loc}", second.url());
    tokio::time::sleep(Duration::from_secs(1)).await;
    let resumed: Value = http.get(&url).send().await.unwrap().json().await.unwrap();
    assert_eq!(status(&resumed), "running", "{resumed}");
    assert!(resumed["steps"].as_u64().unwrap() >= j["steps"].as_u64().unwrap(), "{resumed} after {j}");
    http.delete(&url).send().await.unwrap();
    second.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_that_took_the_server_down_twice_is_not_resumed_a_third_time() {
    let http = reqwest::Client::new();
    let dir = TempDir::new("crashes");
    let case = lattice_case(4, 2, 50.0, 0.01);
    let mut loc = String::new();
    for round in 0..2 {
        let s = start(dir.path(), None);
        if round == 0 {
            loc = submit(&http, &s.url(), &case).await;
        }
        let url = format!("{}{loc}", s.url());
        // Past the steps stored when this server came up (the killed one wrote progress up to its
        // end, after the last read of the previous round): this server has taken the job up (and
        // counted the restart) before it is killed.
        let stored: Value = http.get(&url).send().await.unwrap().json().await.unwrap();
        let before = stored["steps"].as_u64().unwrap_or(0);
        let j = wait_until(&http, &url, Duration::from_secs(60), |j| j["steps"].as_u64().unwrap_or(0) > before).await;
        assert_eq!(status(&j), "running", "round {round}: {j}");
        s.kill();
    }
    let s = start(dir.path(), None);
    let url = format!("{}{loc}", s.url());
    let j = wait_final(&http, &url, Duration::from_secs(30)).await;
    assert_eq!(status(&j), "failed", "{j}");
    assert!(j["message"].as_str().unwrap().contains("stopped unexpectedly 2 times"), "{j}");
    s.shutdown();
}
