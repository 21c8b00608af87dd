//! The run's analysis through the service: accumulated while the job runs, read from its last
//! checkpoint. Its samples here fall on the snapshot times, so its ΔP mean and spread must be
//! those of the stored pressure-drop series over the same window (two paths to one number); its
//! figures are PNGs, and an unknown figure is a problem document. `?from=T` takes the time-series
//! statistics from T on.

use fluidbed_tests::*;
use serde_json::{json, Value};
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn analysis_of_a_finished_job_matches_its_pressure_series_and_draws_its_figures() {
    let dir = TempDir::new("analysis");
    let server = start(dir.path(), None);
    let http = reqwest::Client::new();
    let mut case = small_bubbling_case("analysis", 0.04, 0.004);
    case["analysis"] = json!({ "from_s": 0.008, "sample_interval_s": 0.004 });
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&case).send().await.unwrap();
    if r.status() != 201 {
        panic!("submission refused: {} {}", r.status(), r.text().await.unwrap());
    }
    let url = format!("{}{}", server.url(), r.headers()["location"].to_str().unwrap());
    assert_eq!(wait_final(&http, &url, Duration::from_secs(300)).await["status"], "succeeded");

    let a: Value = http.get(format!("{url}/analysis")).send().await.unwrap().json().await.unwrap();
    let series: Value = http.get(format!("{url}/pressure-drop")).send().await.unwrap().json().await.unwrap();
    let dp: Vec<f64> = series["time_s"]
        .as_array()
        .unwrap()
        .iter()
        .zip(series["pressure_drop_pa"].as_array().unwrap())
        .filter(|(t, _)| t.as_f64().unwrap() >= 0.008 - 1e-9)
        .map(|(_, p)| p.as_f64().unwrap())
        .collect();
    assert_eq!(a["samples"], dp.len() as u64, "{a}");
    assert_eq!(dp.len(), 9, "snapshots at 8, 12, … 40 ms");
    assert!((a["from_s"].as_f64().unwrap() - 0.008).abs() < 1e-9 && (a["to_s"].as_f64().unwrap() - 0.04).abs() < 1e-9);
    let mean = dp.iter().sum::<f64>() / dp.len() as f64;
    let got = a["pressure_drop"]["mean_pa"].as_f64().unwrap();
    assert!((got - mean).abs() <= 1e-9 * mean.abs(), "analysis ΔP mean {got} vs the series' {mean}");
    assert!(a["pressure_drop"]["std_pa"].as_f64().unwrap() > 0.0);
    assert!(!a["voidage_map"]["value"].as_array().unwrap().is_empty());

    // From 24 ms: the ΔP statistics of the five snapshots 24 … 40 ms, the maps unchanged.
    let late: Value = http.get(format!("{url}/analysis?from=0.024")).send().await.unwrap().json().await.unwrap();
    let tail = &dp[4..];
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    let got = late["pressure_drop"]["mean_pa"].as_f64().unwrap();
    assert!((got - mean).abs() <= 1e-9 * mean.abs(), "ΔP mean from 24 ms {got} vs the series' {mean}");
    assert_eq!((late["series_samples"].as_u64(), late["samples"].as_u64()), (Some(5), Some(9)), "{late}");
    assert!((late["series_from_s"].as_f64().unwrap() - 0.024).abs() < 1e-9);
    assert_eq!(late["voidage_map"], a["voidage_map"]);
    let r = http.get(format!("{url}/analysis?from=-1")).send().await.unwrap();
    assert_eq!(r.status(), 400);
    assert!(r.text().await.unwrap().contains("`from`"));

    for figure in ["pressure_spectrum.png", "voidage_map.png", "particle_velocity_map.png"] {
        let r = http.get(format!("{url}/analysis/{figure}")).send().await.unwrap();
        assert_eq!(r.status(), 200, "{figure}");
        assert_eq!(r.headers()["content-type"], "image/png");
        let p = Picture::decode(&r.bytes().await.unwrap());
        assert!(p.colours() > 20 && p.dark_in_rows(0..40) > 100, "{figure}: a titled figure");
    }
    // The eruption figure exists exactly when the analysis found eruptions (a problem otherwise).
    let r = http.get(format!("{url}/analysis/eruption_link.png")).send().await.unwrap();
    if a["eruptions"].is_null() {
        assert_eq!(r.status(), 404);
        assert_eq!(r.headers()["content-type"], "application/problem+json");
    } else {
        assert_eq!(r.status(), 200, "{}", a["eruptions"]);
        assert_eq!(r.headers()["content-type"], "image/png");
    }
    let r = http.get(format!("{url}/analysis/bogus.png")).send().await.unwrap();
    assert_eq!(r.status(), 404);
    assert_eq!(r.headers()["content-type"], "application/problem+json");
    let r = http.get(format!("{}/v1/jobs/no-such-job/analysis", server.url())).send().await.unwrap();
    assert_eq!(r.status(), 404);
    server.shutdown();
}
