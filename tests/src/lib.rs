//! Helpers for the end-to-end tests in tests/tests/: a real server on a free loopback port with a
//! real data directory, small cases, and an event-stream reader.

use fluidbed_server::{Config, Server};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use fluidbed::watch::{parse_events, SseEvent};

pub mod fuzz;
pub mod postgres;
pub mod webdriver;

/// A temporary folder removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        let p = std::env::temp_dir().join(format!("fluidbed-e2e-{tag}-{}-{:x}", std::process::id(), rand_u64()));
        std::fs::create_dir_all(&p).expect("create temp dir");
        TempDir(p)
    }
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn rand_u64() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(Instant::now().elapsed().as_nanos() as u64);
    h.finish()
}

/// The configuration `start` uses: 127.0.0.1:0 over `data_dir`, one worker of one thread.
pub fn test_config(data_dir: &Path, token: Option<&str>) -> Config {
    let mut cfg = Config::new(data_dir.to_path_buf());
    cfg.listen = "127.0.0.1:0".parse().expect("addr");
    cfg.token = token.map(str::to_string);
    cfg.workers = 1;
    cfg.threads_per_job = 1;
    cfg.max_body_bytes = 256 * 1024;
    cfg
}

/// Start a server on 127.0.0.1:0 over `data_dir`.
pub fn start(data_dir: &Path, token: Option<&str>) -> Server {
    Server::start(test_config(data_dir, token)).expect("server starts")
}

/// A DEM-only case whose bed is poured from a seed (`settled_height_m` in a 44-mm column): the
/// pour takes thousands of steps before the run's first one.
pub fn poured_case(settled_height_m: f64, end_time_s: f64, snapshot_interval_s: f64) -> Value {
    json!({
        "name": "e2e poured bed",
        "column": { "diameter_m": 0.044, "height_m": 0.12 },
        "particles": { "diameter_m": D },
        "bed": { "generated": { "settled_height_m": settled_height_m, "seed": 7 } },
        "end_time_s": end_time_s,
        "outputs": { "snapshot_interval_s": snapshot_interval_s, "fields": ["voidage"] },
        "voidage": { "method": "direct" }
    })
}

/// A small coupled case that bubbles within milliseconds: 1,600 poured particles in a 16-mm
/// column fluidized at 0.9 m/s (soft particles, E = 10 MPa, DEM step 4 µs), square-grid voidage,
/// voidage and pressure stored. Tests change what they need on the returned value.
pub fn small_bubbling_case(name: &str, end_time_s: f64, snapshot_interval_s: f64) -> Value {
    json!({
        "name": name,
        "column": { "diameter_m": 0.016, "height_m": 0.048 },
        "particles": { "diameter_m": D, "density_kg_m3": 1000.0, "youngs_modulus_pa": 1.0e7,
            "poisson_ratio": 0.33, "sliding_friction": 0.1,
            "normal_damping": { "tsuji_alpha": 0.02 }, "tangential_damping": { "tsuji_alpha": 0.0001 } },
        "bed": { "generated": { "count": 1600, "seed": 4 } },
        "dem": { "time_step_s": 4.0e-6 },
        "gas": { "superficial_velocity_m_s": 0.9, "ramp_time_s": 0.001 },
        "grid": { "dr_m": 0.004, "n0": 3 },
        "voidage": { "method": "square_grid", "split": "cuboid" },
        "end_time_s": end_time_s,
        "outputs": { "snapshot_interval_s": snapshot_interval_s, "fields": ["voidage", "pressure"] }
    })
}

/// Poll a job until `pred` holds for it (or `timeout` passes); the last job document.
pub async fn wait_until(
    http: &reqwest::Client,
    job_url: &str,
    timeout: Duration,
    pred: impl Fn(&Value) -> bool,
) -> Value {
    let t0 = Instant::now();
    loop {
        let j: Value = http.get(job_url).send().await.expect("get job").json().await.expect("job json");
        if pred(&j) || t0.elapsed() > timeout {
            return j;
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Diameter of the test particles.
pub const D: f64 = 0.0012;

/// A DEM-only case: `nx`×`nx`×`layers` particles on a square lattice (spacing 1.5 d) released
/// above the distributor of a 44-mm column; direct voidage, voidage and particles stored.
pub fn lattice_case(nx: usize, layers: usize, end_time_s: f64, snapshot_interval_s: f64) -> Value {
    let mut pos = Vec::new();
    let s = 1.5 * D;
    for k in 0..layers {
        for j in 0..nx {
            for i in 0..nx {
                let x = (i as f64 - (nx as f64 - 1.0) / 2.0) * s + 0.0001 * k as f64;
                let y = (j as f64 - (nx as f64 - 1.0) / 2.0) * s;
                pos.push([x, y, 0.003 + k as f64 * s]);
            }
        }
    }
    json!({
        "name": "e2e lattice",
        "column": { "diameter_m": 0.044, "height_m": 0.044 },
        "particles": { "diameter_m": D, "density_kg_m3": 1000.0 },
        "bed": { "explicit": { "positions_m": pos } },
        "end_time_s": end_time_s,
        "outputs": { "snapshot_interval_s": snapshot_interval_s, "fields": ["voidage", "particles"] },
        "voidage": { "method": "direct" }
    })
}

/// Poll a job until its status is final (or `timeout` passes); the last job document.
pub async fn wait_final(http: &reqwest::Client, job_url: &str, timeout: Duration) -> Value {
    let t0 = Instant::now();
    loop {
        let j: Value = http.get(job_url).send().await.expect("get job").json().await.expect("job json");
        let st = j["status"].as_str().unwrap_or("");
        if matches!(st, "succeeded" | "failed" | "cancelled") || t0.elapsed() > timeout {
            return j;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Poll until the job lists at least `n` snapshots while running; false if it ended first.
pub async fn wait_snapshots(http: &reqwest::Client, job_url: &str, n: usize, timeout: Duration) -> bool {
    let t0 = Instant::now();
    while t0.elapsed() < timeout {
        let l: Value = http.get(format!("{job_url}/snapshots")).send().await.expect("list").json().await.expect("json");
        if l["snapshots"].as_array().map_or(0, Vec::len) >= n {
            return true;
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    false
}

/// Read a job's event stream until it closes (it closes after the `end` event).
pub async fn read_events(http: &reqwest::Client, job_url: &str, last_event_id: Option<&str>) -> Vec<SseEvent> {
    use futures_util::StreamExt;
    let mut req = http.get(format!("{job_url}/events"));
    if let Some(l) = last_event_id {
        req = req.header("Last-Event-ID", l);
    }
    let resp = req.send().await.expect("events");
    assert_eq!(resp.status(), 200);
    assert!(resp.headers()["content-type"].to_str().unwrap_or("").starts_with("text/event-stream"));
    let mut stream = resp.bytes_stream();
    let (mut buf, mut out) = (String::new(), Vec::new());
    while let Some(chunk) = stream.next().await {
        buf.push_str(&String::from_utf8_lossy(&chunk.expect("chunk")));
        out.extend(parse_events(&mut buf));
    }
    out
}

/// Every file under `dir`, relative, sorted.
pub fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                out.push(p.strip_prefix(dir).unwrap_or(&p).to_path_buf());
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap_or(&p).to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// A decoded PNG: width, height and RGB pixels row by row (8-bit RGB or RGBA; alpha dropped).
pub struct Picture {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<[u8; 3]>,
}

impl Picture {
    pub fn decode(bytes: &[u8]) -> Picture {
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().expect("a PNG header");
        let mut buf = vec![0; reader.output_buffer_size().expect("a buffer size")];
        let info = reader.next_frame(&mut buf).expect("a PNG frame");
        assert_eq!(info.bit_depth, png::BitDepth::Eight, "8-bit");
        let channels = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => panic!("colour type {other:?}"),
        };
        let rgb = buf[..info.buffer_size()].chunks_exact(channels).map(|c| [c[0], c[1], c[2]]).collect();
        Picture { width: info.width as usize, height: info.height as usize, rgb }
    }
    pub fn get(&self, x: usize, y: usize) -> [u8; 3] {
        self.rgb[y * self.width + x]
    }
    /// How many different colours it has (a blank picture has one).
    pub fn colours(&self) -> usize {
        let mut c = self.rgb.clone();
        c.sort_unstable();
        c.dedup();
        c.len()
    }
    /// The share of pixels that are not white.
    pub fn inked(&self) -> f64 {
        self.rgb.iter().filter(|p| **p != [255, 255, 255]).count() as f64 / self.rgb.len() as f64
    }
    /// Dark pixels (text, axes) in a band of rows.
    pub fn dark_in_rows(&self, rows: std::ops::Range<usize>) -> usize {
        rows.flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .filter(|&(x, y)| self.get(x, y).iter().all(|&v| v < 110))
            .count()
    }
}
