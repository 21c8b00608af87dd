//! `GET /metrics` in the Prometheus text format over real HTTP: a running job's steps per second
//! and stage times while it runs (gone once it ends), jobs by status, the queue's length, the
//! snapshot bytes written (the files' sizes on disk), and requests by route template and status.

use fluidbed_tests::*;
use serde_json::Value;
use std::time::Duration;

const WAIT: Duration = Duration::from_secs(300);

/// A sample's value: the line `name{labels} value` (or `name value`).
fn sample(text: &str, series: &str) -> Option<f64> {
    text.lines().find_map(|l| l.strip_prefix(series)?.strip_prefix(' ')?.parse().ok())
}

async fn metrics(http: &reqwest::Client, base: &str) -> String {
    let r = http.get(format!("{base}/metrics")).send().await.unwrap();
    assert_eq!(r.status(), 200);
    let kind = r.headers()["content-type"].to_str().unwrap().to_string();
    assert!(kind.starts_with("text/plain; version=0.0.4"), "{kind}");
    r.text().await.unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn metrics_report_jobs_running_rates_bytes_and_requests() {
    let http = reqwest::Client::new();
    let dir = TempDir::new("metrics");
    let server = start(dir.path(), None);
    let base = server.url();
    let case = small_bubbling_case("metrics bed", 0.012, 0.0008);
    let r = http.post(format!("{base}/v1/jobs")).json(&case).send().await.unwrap();
    assert_eq!(r.status(), 201);
    let id = r.json::<Value>().await.unwrap()["id"].as_str().unwrap().to_string();
    let job_url = format!("{base}/v1/jobs/{id}");

    // While it runs: its rate and its stage times.
    let rate_series = format!("fluidbed_job_steps_per_second{{job=\"{id}\"}}");
    let gas_series = format!("fluidbed_job_stage_seconds{{job=\"{id}\",stage=\"gas\"}}");
    let t0 = std::time::Instant::now();
    let running = loop {
        let text = metrics(&http, &base).await;
        if sample(&text, &rate_series).is_some_and(|v| v > 0.0) || t0.elapsed() > WAIT {
            break text;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    };
    assert!(sample(&running, &rate_series).is_some_and(|v| v > 0.0), "no step rate for job {id}:\n{running}");
    assert!(sample(&running, &gas_series).is_some_and(|v| v > 0.0), "no gas stage time for job {id}:\n{running}");
    assert_eq!(sample(&running, "fluidbed_jobs{status=\"running\"}"), Some(1.0), "{running}");

    assert_eq!(wait_final(&http, &job_url, WAIT).await["status"], "succeeded");
    let _ = http.get(format!("{base}/no/such/path")).send().await.unwrap();
    let text = metrics(&http, &base).await;
    assert!(!text.contains(&format!("job=\"{id}\"")), "an ended job leaves no series:\n{text}");
    for (series, want) in [
        ("fluidbed_jobs{status=\"succeeded\"}", 1.0),
        ("fluidbed_jobs{status=\"running\"}", 0.0),
        ("fluidbed_queue_length", 0.0),
        ("fluidbed_http_requests_total{route=\"/v1/jobs\",method=\"POST\",status=\"201\"}", 1.0),
        ("fluidbed_http_requests_total{route=\"other\",method=\"GET\",status=\"404\"}", 1.0),
    ] {
        assert_eq!(sample(&text, series), Some(want), "{series} in\n{text}");
    }
    let polls = sample(&text, "fluidbed_http_requests_total{route=\"/v1/jobs/{id}\",method=\"GET\",status=\"200\"}");
    assert!(polls.is_some_and(|n| n >= 1.0), "the status polls are counted under their template:\n{text}");
    let on_disk: u64 = std::fs::read_dir(dir.path().join("jobs").join(&id).join("snapshots"))
        .expect("snapshot folder")
        .map(|e| e.unwrap().metadata().unwrap().len())
        .sum();
    assert_eq!(sample(&text, "fluidbed_snapshot_bytes_written_total"), Some(on_disk as f64), "{text}");
    assert!(sample(&text, "fluidbed_checkpoint_bytes_written_total").is_some_and(|b| b > 0.0), "{text}");
    server.shutdown();
}
