//! Slow and idle clients cannot exhaust the server: half-sent headers, a body that never
//! arrives and idle connections are closed after the timeouts; past the connection limit new
//! clients wait instead of taking file descriptors from the jobs; a job runs to its end while
//! all of that goes on.

use fluidbed_tests::*;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Wait until the server closes `s` (EOF or reset); the time it took, or None by `within`.
fn closed_within(s: &mut TcpStream, within: Duration) -> Option<Duration> {
    let t0 = Instant::now();
    s.set_read_timeout(Some(Duration::from_millis(200))).unwrap();
    let mut buf = [0u8; 4096];
    while t0.elapsed() < within {
        match s.read(&mut buf) {
            Ok(0) => return Some(t0.elapsed()),
            Ok(_) => {}
            Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
            Err(_) => return Some(t0.elapsed()),
        }
    }
    None
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn slow_and_idle_connections_are_closed_and_jobs_never_suffer() {
    let dir = TempDir::new("slow");
    let mut cfg = test_config(dir.path(), None);
    cfg.header_read_timeout = Duration::from_secs(2);
    cfg.body_read_timeout = Duration::from_secs(2);
    cfg.max_connections = 8;
    let server = fluidbed_server::Server::start(cfg).unwrap();
    let addr = server.addr();
    let http = reqwest::Client::new();
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&lattice_case(3, 2, 0.05, 0.01)).send().await.unwrap();
    let job_url = format!("{}{}", server.url(), r.headers()["location"].to_str().unwrap());

    let results = tokio::task::spawn_blocking(move || {
        let mut half_head = TcpStream::connect(addr).unwrap();
        half_head.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n").unwrap();
        let mut half_body = TcpStream::connect(addr).unwrap();
        half_body
            .write_all(b"POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: 1000\r\n\r\n{\"a\"")
            .unwrap();
        let mut idle: Vec<TcpStream> = (0..20).map(|_| TcpStream::connect(addr).unwrap()).collect();
        let within = Duration::from_secs(15);
        let mut out = vec![closed_within(&mut half_head, within), closed_within(&mut half_body, within)];
        out.extend(idle.iter_mut().map(|s| closed_within(s, within)));
        out
    })
    .await
    .unwrap();
    assert!(results.iter().all(Option::is_some), "connections left open: {results:?}");

    // After the slow clients, the server answers at once, and the job ran through all of it.
    let t0 = Instant::now();
    let health = http.get(format!("{}/healthz", server.url())).timeout(Duration::from_secs(5)).send().await.unwrap();
    assert_eq!(health.status(), 200);
    assert!(t0.elapsed() < Duration::from_secs(2));
    let j = wait_final(&http, &job_url, Duration::from_secs(120)).await;
    assert_eq!(j["status"], "succeeded", "{j}");
    server.shutdown();
}
