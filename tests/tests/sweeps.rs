//! Sweeps over real HTTP: a bad request is refused whole with each problem named by its pointer
//! in the request (nothing queued); a sweep queues one job per point, ends when they all have,
//! and summarises each point's pressure drop over the second half of its run; a cancel stops
//! every point; `fluidbed sweep` writes the summary table.

use fluidbed_tests::*;
use serde_json::{json, Value};
use std::time::{Duration, Instant};

const U: &str = "/gas/superficial_velocity_m_s";

async fn post(http: &reqwest::Client, base: &str, body: &Value) -> (u16, Value) {
    let r = http.post(format!("{base}/v1/sweeps")).json(body).send().await.unwrap();
    (r.status().as_u16(), r.json().await.unwrap())
}

async fn get(http: &reqwest::Client, url: &str) -> Value {
    http.get(url).send().await.unwrap().json().await.unwrap()
}

fn pointers(problem: &Value) -> Vec<String> {
    problem["errors"].as_array().unwrap().iter().map(|e| e["pointer"].as_str().unwrap().to_string()).collect()
}

async fn wait_sweep(http: &reqwest::Client, url: &str, timeout: Duration) -> Value {
    let t0 = Instant::now();
    loop {
        let s = get(http, url).await;
        let st = s["status"].as_str().unwrap();
        if !matches!(st, "queued" | "running") || t0.elapsed() > timeout {
            return s;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_sweep_runs_one_job_per_point_and_summarises_each() {
    let dir = TempDir::new("sweeps");
    let server = start(dir.path(), None);
    let base = server.url();
    let http = reqwest::Client::new();
    let case = small_bubbling_case("sweep", 0.008, 0.001);

    // Refused whole, each problem named where the request gave it.
    let (code, p) = post(&http, &base, &json!({"base": case, "grid": [{"pointer": U, "values": [0.3, -1.0]}]})).await;
    assert_eq!(code, 422, "{p}");
    assert!(pointers(&p).contains(&"/grid/0/values/1".to_string()), "{p}");
    let mut bad_base = case.clone();
    bad_base["dem"]["time_step_s"] = json!(-1.0);
    let (code, p) = post(&http, &base, &json!({"base": bad_base, "points": [{U: 0.5}]})).await;
    assert_eq!(code, 422, "{p}");
    assert_eq!(pointers(&p)[0], "/base/dem/time_step_s", "{p}");
    let nine: Vec<f64> = (1..=9).map(|k| k as f64 / 10.0).collect();
    let grid = json!([{"pointer": U, "values": nine}, {"pointer": "/bed/generated/seed", "values": [1, 2, 3, 4, 5, 6, 7, 8, 9]}]);
    let (code, p) = post(&http, &base, &json!({"base": case, "grid": grid})).await;
    assert_eq!((code, pointers(&p)), (422, vec!["/grid".to_string()]), "81 points are more than the queue holds");
    let (code, p) =
        post(&http, &base, &json!({"base": case, "grid": [{"pointer": U, "values": [0.3]}], "points": []})).await;
    assert_eq!((code, pointers(&p)), (422, vec!["/grid".to_string()]), "{p}");
    let (code, p) = post(&http, &base, &json!({"base": case, "gird": []})).await;
    assert_eq!(code, 422, "{p}");
    assert!(p["errors"][0]["message"].as_str().unwrap().contains("gird"), "{p}");
    let jobs = get(&http, &format!("{base}/v1/jobs")).await;
    assert_eq!(jobs["total"], 0, "a refused sweep queues nothing");

    // A cancelled sweep: every point ends cancelled.
    let long = small_bubbling_case("long", 10.0, 0.001);
    let (code, s) =
        post(&http, &base, &json!({"name": "to cancel", "base": long, "grid": [{"pointer": U, "values": [0.5, 0.7]}]}))
            .await;
    assert_eq!(code, 201, "{s}");
    let long_url = format!("{base}/v1/sweeps/{}", s["id"].as_str().unwrap());
    assert_eq!(http.delete(&long_url).send().await.unwrap().status(), 202);
    let s = wait_sweep(&http, &long_url, Duration::from_secs(60)).await;
    assert_eq!(s["status"], "cancelled", "{s}");

    // A sweep of two points runs to its end.
    let body = json!({"name": "U sweep", "base": case, "points": [{U: 0.3}, {U: 0.9}]});
    let r = http.post(format!("{base}/v1/sweeps")).json(&body).send().await.unwrap();
    assert_eq!(r.status(), 201);
    let url = format!("{base}{}", r.headers()["location"].to_str().unwrap());
    let created: Value = r.json().await.unwrap();
    assert_eq!(created["points"].as_array().unwrap().len(), 2);
    assert_eq!(created["status"], "queued");
    let s = wait_sweep(&http, &url, Duration::from_secs(600)).await;
    assert_eq!(s["status"], "succeeded", "{s}");
    for (k, (point, u)) in s["points"].as_array().unwrap().iter().zip([0.3, 0.9]).enumerate() {
        assert_eq!(point["set"][U], json!(u));
        let job = get(&http, &format!("{base}/v1/jobs/{}", point["job"].as_str().unwrap())).await;
        assert_eq!(job["name"], format!("U sweep [{k}: superficial_velocity_m_s={u}]"));
        // The summary against the job's own pressure-drop series over t ≥ end / 2.
        let list = get(&http, &format!("{base}/v1/jobs/{}/snapshots", job["id"].as_str().unwrap())).await;
        let window: Vec<f64> = list["snapshots"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|i| i["time_s"].as_f64().unwrap() >= 0.004)
            .map(|i| i["pressure_drop_pa"].as_f64().unwrap())
            .collect();
        let mean = window.iter().sum::<f64>() / window.len() as f64;
        let sm = &point["summary"];
        assert_eq!(sm["samples"], window.len(), "{sm}");
        assert!(window.len() >= 4, "{sm}");
        assert!(
            (sm["pressure_drop_mean_pa"].as_f64().unwrap() - mean).abs() <= 1e-9 * mean.abs().max(1.0),
            "{sm} vs {mean}"
        );
        assert_eq!(sm["superficial_velocity_m_s"], json!(u));
        assert!(sm["pressure_drop_std_pa"].as_f64().unwrap() >= 0.0);
    }
    let list = get(&http, &format!("{base}/v1/sweeps")).await;
    assert_eq!(list["total"], 2);
    assert_eq!(list["sweeps"][0]["name"], "U sweep", "newest first");
    assert_eq!(http.get(format!("{base}/v1/sweeps/0123456789abcdef")).send().await.unwrap().status(), 404);
}

#[test]
fn the_sweep_command_prints_and_writes_a_summary_table() {
    let dir = TempDir::new("sweep-cli");
    let server = start(dir.path(), None);
    let case = dir.path().join("base.json");
    std::fs::write(&case, small_bubbling_case("cli sweep", 0.006, 0.001).to_string()).unwrap();
    let out = dir.path().join("out");
    let url = server.url();
    let sweep_with = |set: &str, out: &std::path::Path| {
        let args = ["--server", &url, "sweep", case.to_str().unwrap(), "--set", set, "--out", out.to_str().unwrap()];
        fluidbed::cli::main_with(std::iter::once("fluidbed").chain(args))
    };
    assert_eq!(sweep_with("/gas/superficial_velocity_m_s=0.6:0.8:0.2", &out), fluidbed::exit::OK);
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3, "{csv}");
    assert!(lines[0].starts_with("point,/gas/superficial_velocity_m_s,job,status,U_m_s,dp_mean_pa"), "{csv}");
    assert!(lines[1].starts_with("0,0.6,") && lines[1].contains(",succeeded,0.600,"), "{csv}");
    assert!(lines[2].starts_with("1,0.8,") && lines[2].contains(",succeeded,0.800,"), "{csv}");
    let sweep: Value = serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(sweep["status"], "succeeded");
    // A bad --set is a usage error before anything is sent.
    assert_eq!(sweep_with("gas=1", &dir.path().join("bad")), fluidbed::exit::USAGE);
}
