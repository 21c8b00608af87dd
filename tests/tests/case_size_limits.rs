//! A case that implies absurd sizes is refused before anything is allocated (422 naming the
//! field), the server stays up, and `fluidbed run` exits 2; the server's own memory limit
//! (`--max-job-memory`) refuses cases beyond it; long names and duplicate keys are refused too.

use fluidbed_tests::*;
use serde_json::{json, Value};

async fn post(http: &reqwest::Client, url: &str, body: String) -> (u16, Value) {
    let r = http.post(url).header("content-type", "application/json").body(body).send().await.unwrap();
    (r.status().as_u16(), r.json().await.unwrap_or(Value::Null))
}

fn pointers(p: &Value) -> Vec<String> {
    p["errors"].as_array().into_iter().flatten().map(|e| e["pointer"].as_str().unwrap_or("").to_string()).collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn absurd_cases_are_refused_naming_the_field_and_the_server_stays_up() {
    let dir = TempDir::new("sizes");
    let mut cfg = test_config(dir.path(), None);
    cfg.max_job_memory = 64 << 20;
    let server = fluidbed_server::Server::start(cfg).unwrap();
    let http = reqwest::Client::new();
    let jobs = format!("{}/v1/jobs", server.url());

    // ~1e11 particles poured into a 5 m × 50 m column (DEM only: no grid checks of the gas).
    let mut tall = poured_case(10.0, 0.01, 0.005);
    tall["column"] = json!({ "diameter_m": 5.0, "height_m": 50.0 });
    let (s, p) = post(&http, &jobs, tall.to_string()).await;
    assert_eq!(s, 422, "{p}");
    assert!(pointers(&p).contains(&"/bed/generated/settled_height_m".to_string()), "{p}");

    // ~1e12 cells: dr 2.5 mm with n0 = 64 in that column.
    let mut fine = lattice_case(2, 1, 0.01, 0.005);
    fine["column"] = json!({ "diameter_m": 5.0, "height_m": 50.0 });
    fine["gas"] = json!({ "superficial_velocity_m_s": 0.5 });
    fine["grid"] = json!({ "dr_m": 0.0025, "n0": 64 });
    let (s, p) = post(&http, &jobs, fine.to_string()).await;
    assert_eq!(s, 422, "{p}");
    let e = p["errors"].as_array().unwrap().iter().find(|e| e["pointer"] == "/grid/dr_m").expect("/grid/dr_m named");
    assert!(e["allowed"].as_str().unwrap().contains("cells"), "{e}");

    // Within the fixed bounds but beyond this server's 64 MiB per job: ~1e5 particles.
    let big = poured_case(0.1, 0.01, 0.005);
    let (s, p) = post(&http, &jobs, big.to_string()).await;
    assert_eq!(s, 422, "{p}");
    assert!(p["detail"].as_str().unwrap().contains("max-job-memory"), "{p}");
    assert_eq!(pointers(&p), vec!["/bed/generated/settled_height_m".to_string()]);

    // A 1 MB name, and a key given twice (the last would win: 0.01 s becoming 7 s).
    let mut named = lattice_case(2, 1, 0.01, 0.005);
    named["name"] = json!("x".repeat(200_000));
    let (s, p) = post(&http, &jobs, named.to_string()).await;
    assert_eq!((s, pointers(&p)), (422, vec!["/name".to_string()]), "{p}");
    let text = lattice_case(2, 1, 0.01, 0.005).to_string();
    let dup = format!("{}, \"end_time_s\": 7}}", &text[..text.len() - 1]);
    let (s, p) = post(&http, &jobs, dup).await;
    assert_eq!((s, pointers(&p)), (422, vec!["/end_time_s".to_string()]), "{p}");

    let listed: Value = http.get(&jobs).send().await.unwrap().json().await.unwrap();
    assert_eq!(listed["total"], 0, "nothing refused became a job");
    assert_eq!(http.get(format!("{}/healthz", server.url())).send().await.unwrap().status(), 200);
    server.shutdown();

    // The CLI refuses the same case locally: exit 2 with the field, never an abort.
    let case = dir.path().join("tall.json");
    std::fs::write(&case, tall.to_string()).unwrap();
    let out = dir.path().join("out");
    let args: Vec<String> =
        vec!["fluidbed".into(), "run".into(), case.display().to_string(), "--out".into(), out.display().to_string()];
    let code = tokio::task::spawn_blocking(move || fluidbed::cli::main_with(args)).await.unwrap();
    assert_eq!(code, fluidbed::exit::INVALID_CASE);
}
