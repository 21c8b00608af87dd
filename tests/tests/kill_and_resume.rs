//! Kill the server mid-run (no clean shutdown), start a new one on the same data directory: the
//! job resumes from its checkpoint and ends with the same particle state as an uninterrupted run.

use fluidbed_core::output::npy;
use fluidbed_tests::*;
use serde_json::Value;
use std::time::Duration;

async fn final_particles(http: &reqwest::Client, url: &str) -> (usize, Vec<f64>) {
    let list: Value = http.get(format!("{url}/snapshots")).send().await.unwrap().json().await.unwrap();
    let snaps = list["snapshots"].as_array().unwrap();
    let last = snaps.last().unwrap()["n"].as_u64().unwrap();
    let b = http
        .get(format!("{url}/snapshots/{last}?format=npy&field=particles"))
        .send()
        .await
        .unwrap()
        .bytes()
        .await
        .unwrap();
    (snaps.len(), npy::decode_f64(&b).expect("particles npy").1)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn killed_server_resumes_job_to_the_same_final_state() {
    let http = reqwest::Client::new();
    let case = lattice_case(8, 4, 0.3, 0.02);

    // Uninterrupted reference run.
    let ref_dir = TempDir::new("reference");
    let reference = start(ref_dir.path(), None);
    let r = http.post(format!("{}/v1/jobs", reference.url())).json(&case).send().await.unwrap();
    let ref_url = format!("{}{}", reference.url(), r.headers()["location"].to_str().unwrap());
    assert_eq!(wait_final(&http, &ref_url, Duration::from_secs(600)).await["status"], "succeeded");
    let (ref_count, ref_state) = final_particles(&http, &ref_url).await;
    reference.shutdown();

    // The same case, killed after its third snapshot.
    let dir = TempDir::new("killed");
    let first = start(dir.path(), None);
    let r = http.post(format!("{}/v1/jobs", first.url())).json(&case).send().await.unwrap();
    let loc = r.headers()["location"].to_str().unwrap().to_string();
    let url1 = format!("{}{loc}", first.url());
    assert!(wait_snapshots(&http, &url1, 3, Duration::from_secs(600)).await);
    let before: Value = http.get(&url1).send().await.unwrap().json().await.unwrap();
    first.kill();
    assert_eq!(before["status"], "running", "killed while running: {before}");

    let second = start(dir.path(), None);
    let url2 = format!("{}{loc}", second.url());
    let job = wait_final(&http, &url2, Duration::from_secs(600)).await;
    assert_eq!(job["status"], "succeeded", "{job}");
    let (count, state) = final_particles(&http, &url2).await;
    assert_eq!(count, ref_count, "same snapshot list");
    assert_eq!(state.len(), ref_state.len());
    let worst = state.iter().zip(&ref_state).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst <= 1e-12, "resumed run differs from the uninterrupted one by {worst}");
    second.shutdown();
}
