//! A coupled run stopped and resumed over HTTP ends bit for bit where an uninterrupted run ends:
//! the quickstart's physics (a poured bed, square-grid voidage, gas at its own step, a coupling
//! interval of 3) on two threads per job, once killed after a snapshot (resumed from that
//! snapshot's checkpoint) and once stopped gracefully (resumed from wherever the worker was).

use fluidbed_server::{Config, Server};
use fluidbed_tests::*;
use serde_json::{json, Value};
use std::path::Path;
use std::time::Duration;

const WAIT: Duration = Duration::from_secs(600);

/// The shared small bubbling bed, coupled every 3 DEM steps, the particles stored too.
fn bubbling_case() -> Value {
    let mut c = small_bubbling_case("e2e coupled resume", 0.004008, 0.000668);
    c["coupling"] = json!({ "interval_steps": 3 });
    c["outputs"]["fields"] = json!(["voidage", "pressure", "particles"]);
    c
}

fn start_two_threads(dir: &Path) -> Server {
    let cfg: Config = Config { threads_per_job: 2, ..test_config(dir, None) };
    Server::start(cfg).expect("server starts")
}

/// Every snapshot of a finished job (whole JSON documents) and its pressure-drop series.
async fn results(http: &reqwest::Client, job_url: &str) -> (Vec<Value>, Value) {
    let list: Value = http.get(format!("{job_url}/snapshots")).send().await.unwrap().json().await.unwrap();
    let mut snaps = Vec::new();
    for s in list["snapshots"].as_array().expect("snapshot list") {
        let n = s["n"].as_u64().unwrap();
        let url = format!("{job_url}/snapshots/{n}?format=json");
        snaps.push(http.get(url).send().await.unwrap().json::<Value>().await.unwrap());
    }
    let dp = http.get(format!("{job_url}/pressure-drop?format=json")).send().await.unwrap().json().await.unwrap();
    (snaps, dp)
}

/// Submit the case on a fresh server in `dir`; the job's path.
async fn submit(http: &reqwest::Client, server: &Server) -> String {
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&bubbling_case()).send().await.unwrap();
    assert_eq!(r.status(), 201, "{}", r.text().await.unwrap_or_default());
    r.headers()["location"].to_str().unwrap().to_string()
}

/// Run the case on a server in `dir`, interrupted by `stop` once `after` snapshots are stored,
/// then resumed on a new server over the same folder; the finished job's results.
async fn interrupted(http: &reqwest::Client, tag: &str, after: usize, stop: fn(Server)) -> (Vec<Value>, Value) {
    let dir = TempDir::new(tag);
    let first = start_two_threads(dir.path());
    let loc = submit(http, &first).await;
    let url1 = format!("{}{loc}", first.url());
    assert!(wait_snapshots(http, &url1, after, WAIT).await, "{tag}: job ended before {after} snapshots");
    let before: Value = http.get(&url1).send().await.unwrap().json().await.unwrap();
    stop(first);
    assert_eq!(before["status"], "running", "{tag}: stopped while running: {before}");
    let second = start_two_threads(dir.path());
    let url2 = format!("{}{loc}", second.url());
    let job = wait_final(http, &url2, WAIT).await;
    assert_eq!(job["status"], "succeeded", "{tag}: {job}");
    let out = results(http, &url2).await;
    second.shutdown();
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn coupled_run_resumed_after_kill_or_stop_matches_the_uninterrupted_one_bit_for_bit() {
    let http = reqwest::Client::new();
    let ref_dir = TempDir::new("coupled-reference");
    let reference = start_two_threads(ref_dir.path());
    let ref_url = format!("{}{}", reference.url(), submit(&http, &reference).await);
    let job = wait_final(&http, &ref_url, WAIT).await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(job["plan"]["coupling_interval"], 3, "{job}");
    let (ref_snaps, ref_dp) = results(&http, &ref_url).await;
    reference.shutdown();
    assert_eq!(ref_snaps.len(), 7, "snapshots every 167 steps to 1002");
    let dp = ref_dp.to_string();
    assert!(ref_snaps.last().unwrap()["pressure_drop_pa"].as_f64().unwrap() > 1.0, "the gas carries the bed: {dp}");

    for (tag, stop) in [("coupled-killed", Server::kill as fn(Server)), ("coupled-stopped", Server::shutdown)] {
        let (snaps, dp) = interrupted(&http, tag, 3, stop).await;
        assert_eq!(dp, ref_dp, "{tag}: pressure-drop series differs from the uninterrupted run");
        assert_eq!(snaps.len(), ref_snaps.len(), "{tag}: snapshot count");
        for (a, b) in snaps.iter().zip(&ref_snaps) {
            for field in ["voidage", "pressure_pa", "layer_pressure_drop_pa", "particles"] {
                assert!(a[field] == b[field], "{tag}: {field} of snapshot {} differs after resume", a["index"]);
            }
        }
    }
}
