//! The API against its own OpenAPI document, over real HTTP: the document a server serves is
//! valid OpenAPI 3.1 (openapi-spec-validator) and a bounded property-based run of schemathesis
//! finds no 5xx, no status, content type or header the document does not declare, no body off its
//! schema (event streams included), and no route that ignores a missing token. Both tools come
//! from PyPI: `.ci/run` installs them into FLUIDBED_PYTOOLS; elsewhere the test says what is
//! missing and passes, except under CI where a missing tool fails it.

use fluidbed_tests::*;
use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

const TOKEN: &str = "contract-token";

/// A tool from FLUIDBED_PYTOOLS/bin, else from PATH.
fn tool(name: &str) -> Option<PathBuf> {
    let mut dirs: Vec<PathBuf> =
        std::env::var_os("FLUIDBED_PYTOOLS").map(|d| PathBuf::from(d).join("bin")).into_iter().collect();
    dirs.extend(std::env::var_os("PATH").map(|p| std::env::split_paths(&p).collect::<Vec<_>>()).unwrap_or_default());
    dirs.into_iter().map(|d| d.join(name)).find(|p| p.is_file())
}

/// The tools, or None (after saying why) when the test cannot run here.
fn tools() -> Option<(PathBuf, PathBuf)> {
    match (tool("openapi-spec-validator"), tool("st")) {
        (Some(v), Some(st)) => Some((v, st)),
        _ => {
            let why = "openapi-spec-validator and schemathesis (`st`) are not installed: \
                       `pip install schemathesis==4.32.5 openapi-spec-validator==0.9.0` (as .ci/run does)";
            assert!(std::env::var_os("CI").is_none(), "{why}");
            eprintln!("skipping the OpenAPI contract test: {why}");
            None
        }
    }
}

fn run(cmd: &mut Command) -> (bool, String) {
    let out = cmd.output().unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    (out.status.success(), text)
}

/// A finished gas run with a few snapshots, for the result routes to serve real data.
async fn finished_job(dir: &std::path::Path) -> String {
    let server = start(dir, Some(TOKEN));
    let http = reqwest::Client::builder()
        .default_headers(
            [(reqwest::header::AUTHORIZATION, format!("Bearer {TOKEN}").parse().unwrap())].into_iter().collect(),
        )
        .build()
        .unwrap();
    let mut case = lattice_case(3, 1, 0.002, 0.001);
    case["gas"] = json!({ "superficial_velocity_m_s": 0.3, "ramp_time_s": 0.0 });
    case["outputs"]["fields"] = json!(["voidage", "pressure", "gas_velocity", "particles"]);
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&case).send().await.unwrap();
    assert_eq!(r.status(), 201);
    let job: Value = r.json().await.unwrap();
    let id = job["id"].as_str().unwrap().to_string();
    let done = wait_final(&http, &format!("{}/v1/jobs/{id}", server.url()), Duration::from_secs(120)).await;
    assert_eq!(done["status"], "succeeded", "{done}");
    server.shutdown();
    id
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_server_keeps_to_its_openapi_document() {
    let Some((validator, st)) = tools() else { return };
    let t0 = Instant::now();
    let dir = TempDir::new("openapi");
    let id = finished_job(dir.path()).await;

    // The same data directory under a server with no workers: submitted jobs only queue, so the
    // run costs no solver time, and every event stream of theirs is short.
    let mut cfg = test_config(dir.path(), Some(TOKEN));
    cfg.workers = 0;
    cfg.submissions_per_s = 0.0;
    let server = fluidbed_server::Server::start(cfg).expect("server starts");
    let base = server.url();

    let doc = reqwest::Client::new()
        .get(format!("{base}/openapi.json"))
        .bearer_auth(TOKEN)
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert_eq!(doc, fluidbed_server::api::openapi::text(), "the served document is the generated one");
    let doc_path = dir.path().join("openapi.json");
    std::fs::write(&doc_path, &doc).unwrap();
    let (ok, out) = run(Command::new(&validator).arg(&doc_path));
    assert!(ok, "openapi-spec-validator: {out}");

    // The finished job's id and snapshot number for the routes that read results; everything else
    // is generated from the document.
    let config = dir.path().join("schemathesis.toml");
    let mut toml = String::from("# written by tests/tests/openapi_contract.rs\nmax-stream-events = 2\n");
    for op in ["get_job", "job_events", "list_snapshots", "get_snapshot", "get_pressure_drop"] {
        toml.push_str(&format!(
            "\n[[operations]]\ninclude-operation-id = \"{op}\"\nparameters = {{ \"path.id\" = \"{id}\", \"path.n\" = \"1\" }}\n"
        ));
    }
    toml.push_str(
        "\n[[operations]]\ninclude-operation-id = \"page_file\"\nparameters = { \"path.file\" = \"style.css\" }\n",
    );
    std::fs::write(&config, toml).unwrap();
    let (ok, out) = run(Command::new(&st)
        .arg("--config-file")
        .arg(&config)
        .arg("--no-color")
        .arg("run")
        .arg(format!("{base}/openapi.json"))
        .args(["-H", &format!("Authorization: Bearer {TOKEN}")])
        .args(["--checks", "all"])
        // A case can pass the schema (types, shapes, enums) and still be refused with 422 for its
        // ranges and cross-field rules, each named by its JSON pointer: that is the design.
        .args(["--exclude-checks", "positive_data_acceptance"])
        .args(["--phases", "examples,coverage,fuzzing"])
        .args(["--max-examples", "25", "--seed", "23", "--workers", "1", "--request-timeout", "20"])
        .args(["--generation-database", "none", "--max-failures", "10"])
        .current_dir(dir.path()));
    eprintln!("{out}");
    assert!(ok, "schemathesis found failures (above)");
    // schemathesis counts the operations it loaded and those it tested: all of them.
    let count = |label: &str| out.lines().find_map(|l| l.trim().strip_prefix(label)).map(str::trim).map(str::to_string);
    let selected = count("Selected:").expect("a summary");
    let tested = count("Tested:").expect("a summary");
    let (chosen, all) = selected.split_once('/').expect("Selected: n/m");
    assert!(chosen == all && tested == all, "{selected} selected, {tested} tested");
    server.shutdown();
    eprintln!("OpenAPI contract checked in {:.1} s", t0.elapsed().as_secs_f64());
}
