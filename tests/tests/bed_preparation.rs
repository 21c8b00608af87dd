//! A case with a generated bed: while the bed is poured and settled (before any step of the run),
//! the running job says so in its message; the message is gone once the run steps.

use fluidbed_tests::*;
use serde_json::{json, Value};
use std::time::{Duration, Instant};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_says_it_is_preparing_its_bed_while_pouring() {
    let dir = TempDir::new("bed-preparation");
    let server = start(dir.path(), None);
    let http = reqwest::Client::new();
    let case = json!({
        "name": "e2e poured bed",
        "column": { "diameter_m": 0.012, "height_m": 0.03 },
        "particles": { "diameter_m": D },
        "bed": { "generated": { "count": 300, "seed": 4 } },
        "end_time_s": 0.002,
        "outputs": { "snapshot_interval_s": 0.001, "fields": ["voidage"] },
        "voidage": { "method": "direct" }
    });
    let resp = http.post(format!("{}/v1/jobs", server.url())).json(&case).send().await.unwrap();
    assert_eq!(resp.status(), 201);
    let job: Value = resp.json().await.unwrap();
    let url = format!("{}/v1/jobs/{}", server.url(), job["id"].as_str().unwrap());
    // Poll: the pour takes thousands of DEM steps, far longer than one poll interval.
    let (t0, mut preparing_seen) = (Instant::now(), false);
    let last = loop {
        let j: Value = http.get(&url).send().await.unwrap().json().await.unwrap();
        if j["status"] == "running" && j["message"].as_str().is_some_and(|m| m.starts_with("preparing the bed")) {
            assert_eq!(j["steps"], 0, "the message belongs to the preparation: {j}");
            preparing_seen = true;
        }
        if matches!(j["status"].as_str(), Some("succeeded" | "failed" | "cancelled"))
            || t0.elapsed() > Duration::from_secs(120)
        {
            break j;
        }
        tokio::time::sleep(Duration::from_millis(10)).await;
    };
    assert_eq!(last["status"], "succeeded", "{last}");
    assert!(preparing_seen, "no 'preparing the bed' message while pouring");
    assert!(last["message"].is_null(), "message cleared: {last}");
}
