//! A run the stability watchdog stops ends `failed` with its message, keeps what it stored, and
//! `fluidbed watch` exits with code 3.

use fluidbed_tests::*;
use serde_json::{json, Value};
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_unstable_run_fails_with_the_watchdog_message() {
    let dir = TempDir::new("failed");
    let server = start(dir.path(), None);
    let http = reqwest::Client::new();
    // Two soft spheres (E = 100 kPa) thrown head-on at 3 m/s each: validation warns that such an
    // impact overlaps far beyond 10% of d, the run starts, and the watchdog stops it at the impact.
    // (An overlapping bed at t = 0 is refused by validation before it runs.)
    let mut case = lattice_case(1, 1, 0.01, 0.005);
    case["particles"]["youngs_modulus_pa"] = json!(1e5);
    case["bed"] = json!({ "explicit": {
        "positions_m": [[-0.002, 0.0, 0.005], [0.002, 0.0, 0.005]],
        "velocities_m_s": [[3.0, 0.0, 0.0], [-3.0, 0.0, 0.0]] } });
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&case).send().await.unwrap();
    assert_eq!(r.status(), 201);
    let url = format!("{}{}", server.url(), r.headers()["location"].to_str().unwrap());
    let job: Value = wait_final(&http, &url, Duration::from_secs(120)).await;
    assert_eq!(job["status"], "failed", "{job}");
    let message = job["message"].as_str().unwrap_or("");
    for want in ["particle overlap", "DEM step", "particles.youngs_modulus_pa"] {
        assert!(message.contains(want), "the failure says what, when and what to change ({want}): {job}");
    }
    let base = server.url();
    let id = url.rsplit('/').next().unwrap().to_string();
    let code = tokio::task::spawn_blocking(move || {
        fluidbed::cli::main_with(["fluidbed", "--server", base.as_str(), "watch", id.as_str()])
    })
    .await
    .unwrap();
    assert_eq!(code, fluidbed::exit::JOB_FAILED);
    server.shutdown();
}
