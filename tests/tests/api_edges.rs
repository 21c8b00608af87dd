//! The API's edges: query-string errors and 405s are problem documents, offsets and
//! Last-Event-ID beyond range are refused instead of wrapping, `limit=0` is refused, the gas
//! velocity downloads as .npy, and the ETA counts stepping only (not the bed's preparation).

use fluidbed_core::output::npy;
use fluidbed_tests::*;
use serde_json::{json, Value};
use std::time::{Duration, Instant};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn query_errors_and_wrong_methods_are_problem_documents() {
    let dir = TempDir::new("edges");
    let server = start(dir.path(), None);
    let base = server.url();
    let http = reqwest::Client::new();
    for q in ["?offset=18446744073709551615", "?limit=abc", "?limit=-1", "?limit=0", "?limit=501"] {
        let r = http.get(format!("{base}/v1/jobs{q}")).send().await.unwrap();
        assert_eq!(r.status(), 400, "{q}");
        assert_eq!(r.headers()["content-type"], "application/problem+json", "{q}");
        let p: Value = r.json().await.unwrap();
        assert_eq!(p["status"], 400, "{q}: {p}");
        assert!(!p["detail"].as_str().unwrap().is_empty(), "{q}: {p}");
    }
    let r = http.put(format!("{base}/v1/jobs")).send().await.unwrap();
    assert_eq!(r.status(), 405);
    assert_eq!(r.headers()["content-type"], "application/problem+json");
    let r_allow = r.headers()["allow"].to_str().unwrap().to_string();
    let p: Value = r.json().await.unwrap();
    assert_eq!(p["status"], 405, "{p}");
    assert!(r_allow.contains("GET") && r_allow.contains("POST"), "{r_allow}");

    let r = http.post(format!("{base}/v1/jobs")).json(&lattice_case(2, 1, 0.004, 0.002)).send().await.unwrap();
    let url = format!("{base}{}", r.headers()["location"].to_str().unwrap());
    wait_final(&http, &url, Duration::from_secs(60)).await;
    for id in ["18446744073709551615", "9223372036854775807", "abc"] {
        let r = http.get(format!("{url}/events")).header("Last-Event-ID", id).send().await.unwrap();
        assert_eq!(r.status(), 400, "Last-Event-ID {id}");
        assert_eq!(r.headers()["content-type"], "application/problem+json");
    }
    // The last snapshot's id: nothing is replayed, the stream just ends.
    let events = read_events(&http, &url, Some("2")).await;
    assert!(events.iter().all(|e| e.event != "snapshot"), "{events:?}");
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn gas_velocity_downloads_as_npy() {
    let dir = TempDir::new("gas-npy");
    let server = start(dir.path(), None);
    let http = reqwest::Client::new();
    let mut case = lattice_case(3, 1, 0.002, 0.001);
    case["gas"] = json!({ "superficial_velocity_m_s": 0.3, "ramp_time_s": 0.0 });
    case["outputs"]["fields"] = json!(["voidage", "pressure", "gas_velocity"]);
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&case).send().await.unwrap();
    assert_eq!(r.status(), 201, "{}", r.text().await.unwrap());
    let url = format!("{}{}", server.url(), r.headers()["location"].to_str().unwrap());
    assert_eq!(wait_final(&http, &url, Duration::from_secs(120)).await["status"], "succeeded");
    let r = http.get(format!("{url}/snapshots/1?format=npy&field=gas_velocity")).send().await.unwrap();
    assert_eq!(r.status(), 200);
    let (shape, data) = npy::decode_f64(&r.bytes().await.unwrap()).expect("npy");
    let snap: Value = http.get(format!("{url}/snapshots/1?format=json")).send().await.unwrap().json().await.unwrap();
    let cells = snap["grid"]["num_cells"].as_u64().unwrap() as usize;
    assert_eq!(shape.iter().product::<usize>(), 3 * cells);
    assert_eq!((shape.len(), shape[2]), (3, 3));
    let uz: Vec<f64> = data.chunks(3).map(|c| c[2]).collect();
    let mean = uz.iter().sum::<f64>() / uz.len() as f64;
    assert!(mean > 0.0, "gas flows upward: mean U_z = {mean}");
    server.shutdown();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_eta_counts_stepping_only() {
    let dir = TempDir::new("eta");
    let server = start(dir.path(), None);
    let http = reqwest::Client::new();
    let mut case = poured_case(0.01, 0.02, 0.002);
    case["column"] = json!({ "diameter_m": 0.012, "height_m": 0.03 });
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&case).send().await.unwrap();
    let url = format!("{}{}", server.url(), r.headers()["location"].to_str().unwrap());
    let j = wait_until(&http, &url, Duration::from_secs(120), |j| {
        j["eta_s"].is_number() && j["time_s"].as_f64().unwrap_or(0.0) > 0.004
    })
    .await;
    let (eta, seen) = (j["eta_s"].as_f64().expect("an ETA while running"), Instant::now());
    let prepared = j["wall_time_s"].as_f64().unwrap();
    let done = wait_final(&http, &url, Duration::from_secs(300)).await;
    assert_eq!(done["status"], "succeeded", "{done}");
    let actual = seen.elapsed().as_secs_f64();
    assert!(eta < 2.0 * actual + 1.0, "ETA {eta:.1} s, the run took {actual:.1} s more (wall {prepared:.1} s before)");
    server.shutdown();
}
