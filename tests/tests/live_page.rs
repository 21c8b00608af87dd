//! The live page in a real browser (headless Chromium over WebDriver): a case pasted into the
//! submit form at `/` starts a job that the job list shows with its status and a link; the job's
//! page draws the voidage maps and redraws them as the run's snapshots arrive, then shows the
//! ΔP trace of every snapshot and `succeeded`; an invalid case shows the validator's error at the
//! field it names; and nothing is logged as an error on the console. Skipped, saying so, when
//! chromium or chromedriver is not installed. With FLUIDBED_PAGE_SCREENSHOTS=DIR the pages are
//! saved there as PNGs (docs/img).

use fluidbed_tests::webdriver::Browser;
use fluidbed_tests::*;
use serde_json::{json, Value};
use std::time::Duration;

const WAIT: Duration = Duration::from_secs(300);

/// The shared small bubbling bed (`fluidbed_tests::small_bubbling_case`).
fn bubbling_case() -> Value {
    small_bubbling_case("live page bed", 0.012, 0.0008)
}

/// Console or network entries at error level.
fn errors(log: &[Value]) -> Vec<String> {
    log.iter().filter(|e| e["level"] == "SEVERE").map(|e| e["message"].to_string()).collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn live_page_submits_lists_and_draws_a_job_as_its_snapshots_arrive() {
    let browser = match Browser::start(1280, 1000).await {
        Ok(b) => b,
        Err(why) => {
            println!("SKIPPED live_page test: {why}");
            return;
        }
    };
    let shots = std::env::var_os("FLUIDBED_PAGE_SCREENSHOTS").map(std::path::PathBuf::from);
    let dir = TempDir::new("live-page");
    let server = start(dir.path(), None);
    let base = server.url();

    // Submit through the page's form.
    browser.goto(&format!("{base}/")).await;
    let picker = browser.wait_for("return document.querySelectorAll('#case-pick option').length > 1", WAIT).await;
    assert!(picker.is_some(), "the shipped cases are offered");
    let case = serde_json::to_string_pretty(&bubbling_case()).unwrap();
    let paste = format!(
        "const t = document.getElementById('case-text'); t.value = {}; t.dispatchEvent(new Event('input')); \
         document.getElementById('submit-button').click();",
        serde_json::to_string(&case).unwrap()
    );
    browser.eval(&paste).await;
    let link = browser
        .wait_for("const a = document.querySelector('#submit-result a'); return a && a.getAttribute('href')", WAIT)
        .await;
    let href = link.expect("the form reports the submitted job with a link").as_str().unwrap().to_string();
    let id = href.strip_prefix("/jobs/").expect("a /jobs/{id} link").to_string();

    // The job list shows it, with its status and a link to its page.
    let row = format!("return document.querySelector('#jobs tr[data-job=\"{id}\"] a[href=\"/jobs/{id}\"]') !== null");
    assert!(browser.wait_for(&row, WAIT).await.is_some(), "job {id} is listed with a link to its page");
    let status = format!("return document.querySelector('#jobs tr[data-job=\"{id}\"] .status').textContent");
    let listed = browser.eval(&status).await;
    assert!(["queued", "running"].contains(&listed.as_str().unwrap_or("")), "listed as {listed}");
    if let Some(d) = &shots {
        std::fs::write(d.join("page-jobs.png"), browser.screenshot().await).expect("write screenshot");
    }

    // Its page redraws the map for each snapshot while the job runs.
    browser.goto(&format!("{base}{href}")).await;
    let drawn = "const c = document.getElementById('axial'); \
                 return c.dataset.snapshot === undefined ? null : [+c.dataset.snapshot, c.toDataURL(), document.getElementById('status').textContent]";
    let first = browser.wait_for(drawn, WAIT).await.expect("the voidage map is drawn");
    let later_script = format!(
        "const c = document.getElementById('axial'); return +c.dataset.snapshot > {} ? [+c.dataset.snapshot, c.toDataURL(), document.getElementById('status').textContent] : null",
        first[0]
    );
    let later = browser.wait_for(&later_script, WAIT).await.expect("the map is redrawn for a later snapshot");
    assert_eq!(first[2], "running", "the first map is drawn while the job runs");
    assert_ne!(first[1], later[1], "snapshots {} and {} draw different maps", first[0], later[0]);

    // At the end: every snapshot on the ΔP trace, the slice and the layer profile drawn.
    let done = browser.wait_for("return document.getElementById('status').textContent === 'succeeded'", WAIT).await;
    assert!(done.is_some(), "the page shows the job succeeded");
    let http = reqwest::Client::new();
    let list: Value = http.get(format!("{base}/v1/jobs/{id}/snapshots")).send().await.unwrap().json().await.unwrap();
    let n = list["snapshots"].as_array().unwrap().len();
    assert_eq!(n, 16, "snapshots every 0.8 ms to 12 ms");
    let points =
        browser.wait_for(&format!("return +document.getElementById('trace').dataset.points === {n}"), WAIT).await;
    assert!(points.is_some(), "the ΔP trace holds all {n} snapshots");
    let last = (n - 1).to_string();
    for canvas in ["axial", "slice", "layers"] {
        let v = browser.eval(&format!("return document.getElementById('{canvas}').dataset.snapshot")).await;
        assert_eq!(v, Value::String(last.clone()), "canvas {canvas} shows the last snapshot");
    }
    let links =
        browser.eval("return [...document.querySelectorAll('.downloads a')].map(a => a.getAttribute('href'))").await;
    let links: Vec<&str> = links.as_array().unwrap().iter().filter_map(Value::as_str).collect();
    for want in [
        format!("/v1/jobs/{id}/snapshots/{last}?format=npy&field=voidage"),
        format!("/v1/jobs/{id}/pressure-drop?format=csv"),
    ] {
        assert!(links.contains(&want.as_str()), "download link {want} in {links:?}");
    }
    if let Some(d) = &shots {
        std::fs::write(d.join("page-job.png"), browser.screenshot().await).expect("write screenshot");
    }
    let log = browser.log().await;
    assert!(errors(&log).is_empty(), "console errors: {:?}", errors(&log));

    // An invalid case: the validator's message at the field it names.
    browser.goto(&format!("{base}/")).await;
    let mut bad = bubbling_case();
    bad["particles"]["diameter_m"] = json!(-0.001);
    let paste = format!(
        "const t = document.getElementById('case-text'); t.value = {}; t.dispatchEvent(new Event('input')); \
         document.getElementById('submit-button').click();",
        serde_json::to_string(&bad.to_string()).unwrap()
    );
    browser.eval(&paste).await;
    let at_field = browser
        .wait_for(
            "const e = document.querySelector('[data-pointer=\"/particles/diameter_m\"] > .field-error'); return e && e.textContent",
            WAIT,
        )
        .await;
    let msg = at_field.expect("an error shown at /particles/diameter_m");
    println!("error shown at /particles/diameter_m: {msg}");
    // The 422 itself is the only entry logged (Chromium logs every 4xx answer).
    let log = browser.log().await;
    let unexpected: Vec<String> =
        errors(&log).into_iter().filter(|m| !m.contains("/v1/jobs - ") || !m.contains("422")).collect();
    assert!(unexpected.is_empty(), "console errors: {unexpected:?}");
    println!(
        "live page: job {id} listed, {n} snapshots drawn live (first at snapshot {}, redrawn at {}), no console errors",
        first[0], later[0]
    );
    server.shutdown();
}
