//! Cancel a running job (it stops well before its end); list newest first, filter, paginate.

use fluidbed_tests::*;
use serde_json::Value;
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancelled_job_stops_early_and_listing_filters_and_pages() {
    let dir = TempDir::new("cancel");
    let server = start(dir.path(), None);
    let base = server.url();
    let http = reqwest::Client::new();
    // Long enough that it cannot end on its own during the test.
    let long = lattice_case(6, 4, 50.0, 0.002);
    let r = http.post(format!("{base}/v1/jobs")).json(&long).send().await.unwrap();
    assert_eq!(r.status(), 201);
    let url = format!("{base}{}", r.headers()["location"].to_str().unwrap());
    // A second job waits in the queue behind it (one worker).
    let r2 = http.post(format!("{base}/v1/jobs")).json(&lattice_case(2, 1, 0.004, 0.002)).send().await.unwrap();
    let url2 = format!("{base}{}", r2.headers()["location"].to_str().unwrap());
    assert!(wait_snapshots(&http, &url, 2, Duration::from_secs(120)).await, "the long job produced snapshots");

    let running: Value = http.get(format!("{base}/v1/jobs?status=running")).send().await.unwrap().json().await.unwrap();
    assert_eq!(running["total"], 1);
    let queued: Value = http.get(format!("{base}/v1/jobs?status=queued")).send().await.unwrap().json().await.unwrap();
    assert_eq!(queued["jobs"][0]["id"], url2.rsplit('/').next().unwrap());

    let c = http.delete(&url).send().await.unwrap();
    assert_eq!(c.status(), 202);
    let job = wait_final(&http, &url, Duration::from_secs(60)).await;
    assert_eq!(job["status"], "cancelled");
    assert!(job["time_s"].as_f64().unwrap() < 50.0, "stopped before the end");
    // The stream of a cancelled job replays and ends.
    let ev = read_events(&http, &url, None).await;
    let end: Value = serde_json::from_str(&ev.last().unwrap().data).unwrap();
    assert_eq!(end["status"], "cancelled");
    // Cancelling again is harmless; the queued job then runs to success.
    assert_eq!(http.delete(&url).send().await.unwrap().status(), 200);
    assert_eq!(wait_final(&http, &url2, Duration::from_secs(120)).await["status"], "succeeded");
    assert_eq!(http.delete(&url2).send().await.unwrap().status(), 409, "a finished job cannot be cancelled");

    // Newest first, filtered, paginated.
    let all: Value = http.get(format!("{base}/v1/jobs")).send().await.unwrap().json().await.unwrap();
    let ids: Vec<&str> = all["jobs"].as_array().unwrap().iter().map(|j| j["id"].as_str().unwrap()).collect();
    assert_eq!(ids, [url2.rsplit('/').next().unwrap(), url.rsplit('/').next().unwrap()]);
    let page: Value = http.get(format!("{base}/v1/jobs?limit=1")).send().await.unwrap().json().await.unwrap();
    assert_eq!(
        (page["jobs"].as_array().unwrap().len(), page["total"].as_u64(), page["next_offset"].as_u64()),
        (1, Some(2), Some(1))
    );
    let cancelled: Value =
        http.get(format!("{base}/v1/jobs?status=cancelled")).send().await.unwrap().json().await.unwrap();
    assert_eq!(cancelled["total"], 1);
    assert_eq!(cancelled["jobs"][0]["status"], "cancelled");
    assert_eq!(http.get(format!("{base}/v1/jobs?status=bogus")).send().await.unwrap().status(), 400);
    server.shutdown();
}
