//! Three fluidbed server processes on one PostgreSQL and one shared data directory: twenty short
//! jobs submitted through two of them, one node killed with SIGKILL mid-run. Every job ends
//! succeeded exactly once (the killed node's resumed elsewhere from their checkpoints, to a final
//! state bit-identical to the jobs that ran uninterrupted), the event streams read through the
//! third node are complete and in order, a resumed stream through another node starts right after
//! its Last-Event-ID, a sweep submitted to one node is followed to its summary through another,
//! and a cancel sent to a node that does not run the job stops it.

use fluidbed_tests::postgres::PgCluster;
use fluidbed_tests::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Short enough that a takeover comes soon after a kill.
const LEASE_S: &str = "2";
const JOBS: usize = 20;

struct Node {
    child: Child,
    url: String,
    log: PathBuf,
}

impl Node {
    fn start(db: &str, shared: &Path, log: PathBuf) -> Node {
        let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
        let err = std::fs::File::create(&log).expect("node log");
        let child = Command::new(env!("CARGO_BIN_EXE_fluidbed-node"))
            .args(["--database", db, "--data-dir"])
            .arg(shared)
            .args(["--listen", &format!("127.0.0.1:{port}"), "--workers", "1", "--threads-per-job", "1"])
            .args(["--lease-s", LEASE_S, "--submissions-per-s", "0", "--log-format", "json"])
            .stdout(Stdio::null())
            .stderr(err)
            .spawn()
            .expect("start a node");
        Node { child, url: format!("http://127.0.0.1:{port}"), log }
    }

    /// What this node logged about `job`: (message, fields) per line of its span.
    fn lines_of(&self, job: &str) -> Vec<(String, Value)> {
        let text = std::fs::read_to_string(&self.log).unwrap_or_default();
        text.lines()
            .filter_map(|l| serde_json::from_str::<Value>(l).ok())
            .filter(|v| v["span"]["id"] == job)
            .map(|v| (v["fields"]["message"].as_str().unwrap_or("").to_string(), v["fields"].clone()))
            .collect()
    }
    fn started(&self, job: &str) -> Vec<Value> {
        self.lines_of(job).into_iter().filter(|(m, _)| m == "job started").map(|(_, f)| f).collect()
    }
    fn ended(&self, job: &str, status: &str) -> usize {
        self.lines_of(job).iter().filter(|(m, f)| m == "job ended" && f["status"] == status).count()
    }
}

impl Drop for Node {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

async fn up(http: &reqwest::Client, node: &Node) {
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(60) {
        if http.get(format!("{}/healthz", node.url)).send().await.is_ok_and(|r| r.status().is_success()) {
            return;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!("node {} did not come up: {}", node.url, std::fs::read_to_string(&node.log).unwrap_or_default());
}

async fn get(http: &reqwest::Client, url: &str) -> Value {
    http.get(url).send().await.expect("get").json().await.expect("json")
}

/// The whole event stream of a job (the server closes it after `end`).
async fn stream(http: reqwest::Client, url: String, last_event_id: Option<u64>) -> Vec<SseEvent> {
    let mut req = http.get(url);
    if let Some(n) = last_event_id {
        req = req.header("last-event-id", n.to_string());
    }
    let mut text = req.send().await.expect("events").text().await.expect("event stream");
    text.push_str("\n\n");
    parse_events(&mut text)
}

fn snapshot_ids(events: &[SseEvent]) -> Vec<u64> {
    events.iter().filter(|e| e.event == "snapshot").map(|e| e.id.as_deref().unwrap().parse().unwrap()).collect()
}

fn largest_difference(a: &Value, b: &Value) -> f64 {
    let (a, b) = (a.as_array().unwrap(), b.as_array().unwrap());
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x.as_f64().unwrap() - y.as_f64().unwrap()).abs()).fold(0.0, f64::max)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn three_nodes_share_one_queue_and_survive_a_kill() {
    let pg = match PgCluster::start() {
        Ok(pg) => pg,
        Err(why) if std::env::var_os("CI").is_none() => {
            eprintln!("SKIPPED three_nodes_share_one_queue_and_survive_a_kill: no PostgreSQL here ({why})");
            return;
        }
        Err(why) => panic!("CI must have PostgreSQL (.ci/run installs it): {why}"),
    };
    let http = reqwest::Client::new();
    let dir = TempDir::new("cluster");
    let shared = dir.path().join("shared");
    let (a, b, c) = (
        Node::start(&pg.url(), &shared, dir.path().join("a.log")),
        Node::start(&pg.url(), &shared, dir.path().join("b.log")),
        Node::start(&pg.url(), &shared, dir.path().join("c.log")),
    );
    for n in [&a, &b, &c] {
        up(&http, n).await;
    }

    let mut case = small_bubbling_case("cluster", 0.012, 0.001);
    case["outputs"]["fields"] = serde_json::json!(["voidage", "pressure"]);
    let mut ids = Vec::new();
    for k in 0..JOBS {
        let via = if k % 2 == 0 { &a } else { &b };
        case["name"] = format!("cluster {k}").into();
        let r = http.post(format!("{}/v1/jobs", via.url)).json(&case).send().await.unwrap();
        assert_eq!(r.status(), 201, "{}", r.text().await.unwrap());
        ids.push(r.json::<Value>().await.unwrap()["id"].as_str().unwrap().to_string());
    }
    let streams: Vec<_> = ids
        .iter()
        .map(|id| tokio::spawn(stream(http.clone(), format!("{}/v1/jobs/{id}/events", c.url), None)))
        .collect();

    // Kill A while every node runs a job midway.
    let t0 = Instant::now();
    loop {
        let running = get(&http, &format!("{}/v1/jobs?status=running", c.url)).await;
        let jobs = running["jobs"].as_array().unwrap();
        // Checkpointed, and far enough from the end that A cannot finish before the kill. The
        // window is wider than 2/3 of a job: three jobs at any phases then all lie in it at some
        // moment of each job's run (the widest gap between three points on a circle is ≥ 1/3),
        // so nodes that start their jobs staggered still meet it.
        let midway = |j: &Value| (0.2..0.9).contains(&j["progress"].as_f64().unwrap());
        if jobs.len() >= 3 && jobs.iter().all(midway) {
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(240), "three jobs never ran at once: {running}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let mut a = a;
    a.child.kill().expect("SIGKILL node A");
    a.child.wait().unwrap();

    for id in &ids {
        let j = wait_until(&http, &format!("{}/v1/jobs/{id}", b.url), Duration::from_secs(300), |j| {
            j["status"] != "queued" && j["status"] != "running"
        })
        .await;
        assert_eq!(j["status"], "succeeded", "through the surviving node B: {j}");
    }
    assert_eq!(get(&http, &format!("{}/v1/jobs?limit=100", c.url)).await["total"], JOBS);

    // Each job succeeded exactly once; A's unfinished jobs resumed on B or C.
    let mut resumed = 0;
    for id in &ids {
        let once: usize = [&a, &b, &c].iter().map(|n| n.ended(id, "succeeded")).sum();
        assert_eq!(once, 1, "job {id} ended succeeded {once} times");
        if !a.started(id).is_empty() && a.ended(id, "succeeded") == 0 {
            let elsewhere: Vec<Value> = [&b, &c].iter().flat_map(|n| n.started(id)).collect();
            assert!(elsewhere.iter().any(|f| f["resumed"] == true), "A's job {id} was not resumed: {elsewhere:?}");
            resumed += 1;
        }
    }
    assert!(resumed >= 1, "node A was killed while running no job");

    // The streams through C: every snapshot once and in order, then `end`; the same final state,
    // bit for bit, for every job (the resumed ones included: one case, one thread each).
    let mut last_snapshots = Vec::new();
    for (id, s) in ids.iter().zip(streams) {
        let events = tokio::time::timeout(Duration::from_secs(60), s).await.expect("stream ended").unwrap();
        let listed = get(&http, &format!("{}/v1/jobs/{id}/snapshots", c.url)).await;
        let count = listed["snapshots"].as_array().unwrap().len() as u64;
        assert_eq!(snapshot_ids(&events), (0..count).collect::<Vec<_>>(), "job {id}'s snapshots through C");
        let end = events.last().expect("events");
        assert_eq!(end.event, "end", "job {id}'s stream ends with `end`");
        assert!(end.data.contains("succeeded"), "{}", end.data);
        assert!(events.iter().any(|e| e.event == "progress"));
        let last = events.iter().rev().find(|e| e.event == "snapshot").unwrap();
        last_snapshots.push(serde_json::from_str::<Value>(&last.data).unwrap());
    }
    for (k, s) in last_snapshots.iter().enumerate().skip(1) {
        for field in ["voidage", "pressure_pa"] {
            let d = largest_difference(&s[field], &last_snapshots[0][field]);
            assert_eq!(d, 0.0, "job {k}'s final {field} differs from job 0's by {d}");
        }
    }

    // A stream resumed through B starts right after its Last-Event-ID.
    let again = stream(http.clone(), format!("{}/v1/jobs/{}/events", b.url, ids[0]), Some(4)).await;
    let ids_after = snapshot_ids(&again);
    assert_eq!(ids_after.first(), Some(&5), "resumed after 4: {ids_after:?}");
    assert_eq!(again.last().map(|e| e.event.as_str()), Some("end"));

    // A sweep submitted to B, followed through C to every point's summary.
    let sweep_case = small_bubbling_case("cluster sweep", 0.006, 0.001);
    let body = serde_json::json!({"base": sweep_case, "grid": [{"pointer": "/gas/superficial_velocity_m_s", "values": [0.6, 0.9]}]});
    let r = http.post(format!("{}/v1/sweeps", b.url)).json(&body).send().await.unwrap();
    assert_eq!(r.status(), 201);
    let sweep_id = r.json::<Value>().await.unwrap()["id"].as_str().unwrap().to_string();
    // Followed until it ends (the last answer after 120 s if it does not: the assert names it).
    let sweep_url = format!("{}/v1/sweeps/{sweep_id}", c.url);
    let mut sweep = get(&http, &sweep_url).await;
    for _ in 0..1200 {
        if sweep["status"] != "queued" && sweep["status"] != "running" {
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
        sweep = get(&http, &sweep_url).await;
    }
    assert_eq!(sweep["status"], "succeeded", "{sweep}");
    for p in sweep["points"].as_array().unwrap() {
        assert!(p["summary"]["samples"].as_u64().unwrap() >= 3, "{p}");
        assert_eq!(p["summary"]["superficial_velocity_m_s"], p["set"]["/gas/superficial_velocity_m_s"]);
    }

    // A cancel through the node that does not run the job stops it.
    let mut long = small_bubbling_case("cluster cancel", 10.0, 0.001);
    long["outputs"]["fields"] = serde_json::json!(["voidage"]);
    let r = http.post(format!("{}/v1/jobs", b.url)).json(&long).send().await.unwrap();
    let id = r.json::<Value>().await.unwrap()["id"].as_str().unwrap().to_string();
    let job_url = format!("{}/v1/jobs/{id}", b.url);
    let j = wait_until(&http, &job_url, Duration::from_secs(120), |j| {
        j["status"] == "running" && j["steps"].as_u64() > Some(0)
    })
    .await;
    assert_eq!(j["status"], "running", "{j}");
    let t1 = Instant::now();
    let (runner, other) = loop {
        if !b.started(&id).is_empty() {
            break (&b, &c);
        }
        if !c.started(&id).is_empty() {
            break (&c, &b);
        }
        assert!(t1.elapsed() < Duration::from_secs(10), "no node logged starting job {id}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    };
    let r = http.delete(format!("{}/v1/jobs/{id}", other.url)).send().await.unwrap();
    assert_eq!(r.status(), 202);
    let j = wait_until(&http, &job_url, Duration::from_secs(30), |j| j["status"] == "cancelled").await;
    assert_eq!(j["status"], "cancelled", "{j}");
    assert_eq!(j["message"], "cancelled by request");
    assert!(j["time_s"].as_f64().unwrap() < 10.0);
    // The runner records the status before it logs "job ended": on a loaded machine the log line
    // can trail the status a moment.
    let t2 = Instant::now();
    while runner.ended(&id, "cancelled") == 0 && t2.elapsed() < Duration::from_secs(10) {
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert_eq!(runner.ended(&id, "cancelled"), 1, "the running node stopped the job");
    drop(pg);
}
