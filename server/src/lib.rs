//! fluidbed-server: the HTTP service. Jobs are stored in SQLite under a data directory (or in
//! PostgreSQL shared by many servers, the nodes of one queue), run on worker threads (each on its
//! own rayon pool) and streamed to clients as server-sent events.
//!
//! ```no_run
//! let cfg = fluidbed_server::Config::new("data".into());
//! let server = fluidbed_server::Server::start(cfg).unwrap();
//! println!("listening on http://{}", server.addr());
//! server.shutdown();
//! ```

pub mod api;
pub mod cli;
pub mod events;
pub mod health;
pub mod heartbeat;
pub mod job;
pub mod listener;
pub mod metrics;
pub mod page;
pub mod relay;
pub mod store;
pub mod sweep;
pub mod worker;

use anyhow::{Context, Result};
use std::collections::HashMap;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How a server is started (the binary's flags).
#[derive(Clone, Debug)]
pub struct Config {
    /// Snapshots, checkpoints, the bed cache and (without `database`) the SQLite job records;
    /// shared by all nodes of a cluster.
    pub data_dir: PathBuf,
    /// A `postgres://` URL: job records there, one queue for every server that names it.
    pub database: Option<String>,
    /// How long a claimed job stays this node's without a heartbeat; then another node may
    /// take it over from its last checkpoint.
    pub lease: Duration,
    /// Address to bind; loopback by default.
    pub listen: SocketAddr,
    /// When set, every route but /healthz needs `Authorization: Bearer <token>`.
    pub token: Option<String>,
    pub workers: usize,
    pub threads_per_job: usize,
    /// Largest accepted request body.
    pub max_body_bytes: usize,
    /// Most jobs waiting in the queue; more are answered 429.
    pub max_queued: usize,
    /// Sustained job submissions per second (token bucket, burst of 4 seconds' worth); more are 429.
    pub submissions_per_s: f64,
    /// Largest estimated peak memory of one job (`case::bounds`); larger cases are refused (422).
    pub max_job_memory: u64,
    /// Most client connections at once (also kept below the open-file limit).
    pub max_connections: usize,
    /// A request head must arrive within this; also how long an idle connection stays open.
    pub header_read_timeout: Duration,
    /// A request body may pause this long between chunks.
    pub body_read_timeout: Duration,
    /// A request (not a streamed response) must be read and answered within this.
    pub request_timeout: Duration,
}

impl Config {
    pub fn new(data_dir: PathBuf) -> Config {
        Config {
            data_dir,
            database: None,
            lease: Duration::from_secs(30),
            listen: SocketAddr::from(([127, 0, 0, 1], 8471)),
            token: None,
            workers: 1,
            threads_per_job: 1,
            max_body_bytes: 16 << 20,
            max_queued: 64,
            submissions_per_s: 5.0,
            max_job_memory: 8 << 30,
            max_connections: 512,
            header_read_timeout: Duration::from_secs(20),
            body_read_timeout: Duration::from_secs(20),
            request_timeout: Duration::from_secs(60),
        }
    }
}

/// What handlers and workers share.
pub struct App {
    pub config: Config,
    /// This server's name in the job records (the holder of its leases).
    pub node: String,
    pub store: store::Store,
    pub hub: events::Hub,
    pub queue: worker::Queue,
    pub cancels: Mutex<HashMap<String, Arc<AtomicBool>>>,
    pub health: health::Health,
    pub metrics: metrics::Metrics,
    /// Submission token bucket: (tokens, last refill).
    submit_bucket: Mutex<(f64, Instant)>,
    stopping: AtomicBool,
    /// Set with `stopping` by a clean shutdown (SIGTERM): running jobs checkpoint first.
    graceful: AtomicBool,
}

impl App {
    /// Set when the server stops: workers then write nothing more and leave running jobs to be
    /// resumed from their checkpoint by the next server on this data directory.
    pub fn stopping(&self) -> bool {
        self.stopping.load(Ordering::SeqCst)
    }
    /// Whether the stop is a clean shutdown (not `Server::kill`).
    pub fn graceful(&self) -> bool {
        self.graceful.load(Ordering::SeqCst)
    }
    /// Take one submission token; false when the client must slow down.
    pub fn take_submission_token(&self) -> bool {
        let rate = self.config.submissions_per_s;
        if rate <= 0.0 {
            return true;
        }
        let mut b = self.submit_bucket.lock().unwrap_or_else(|e| e.into_inner());
        let now = Instant::now();
        b.0 = (b.0 + rate * now.duration_since(b.1).as_secs_f64()).min(4.0 * rate);
        b.1 = now;
        if b.0 >= 1.0 {
            b.0 -= 1.0;
            true
        } else {
            false
        }
    }
}

/// A running server.
pub struct Server {
    addr: SocketAddr,
    app: Arc<App>,
    runtime: Option<tokio::runtime::Runtime>,
    shutdown_tx: Option<tokio::sync::oneshot::Sender<()>>,
    workers: Vec<std::thread::JoinHandle<()>>,
}

impl Server {
    /// Open the store, start the workers (they claim queued jobs and resume unfinished ones),
    /// the relay of other nodes' events and the HTTP listener.
    pub fn start(config: Config) -> Result<Server> {
        let store = store::Store::open(&config.data_dir, config.database.as_deref())?;
        let app = Arc::new(App {
            node: job::new_id(),
            store,
            hub: events::Hub::default(),
            queue: worker::Queue::default(),
            cancels: Mutex::new(HashMap::new()),
            health: health::Health::default(),
            metrics: metrics::Metrics::default(),
            submit_bucket: Mutex::new((4.0 * config.submissions_per_s, Instant::now())),
            stopping: AtomicBool::new(false),
            graceful: AtomicBool::new(false),
            config,
        });
        relay::start(&app)?;
        let listener =
            std::net::TcpListener::bind(app.config.listen).with_context(|| format!("bind {}", app.config.listen))?;
        listener.set_nonblocking(true)?;
        let addr = listener.local_addr()?;
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .thread_name("fluidbed-http")
            .enable_all()
            .build()?;
        let (shutdown_tx, shutdown_rx) = tokio::sync::oneshot::channel::<()>();
        let router = api::router(app.clone());
        let (header_timeout, connections) =
            (app.config.header_read_timeout, listener::connection_budget(app.config.max_connections));
        let listener = {
            let _guard = runtime.enter();
            tokio::net::TcpListener::from_std(listener)?
        };
        runtime.spawn(listener::serve(listener, router, header_timeout, connections, shutdown_rx));
        let workers = worker::spawn(&app, app.config.workers);
        tracing::info!(node = %app.node, shared = app.store.records().shared(), "node started");
        Ok(Server { addr, app, runtime: Some(runtime), shutdown_tx: Some(shutdown_tx), workers })
    }

    pub fn addr(&self) -> SocketAddr {
        self.addr
    }
    pub fn url(&self) -> String {
        format!("http://{}", self.addr)
    }

    /// Stop: no new requests; workers checkpoint at their next chunk (a pour stops at once);
    /// running jobs stay `running` in the store and resume from there on the next start. The
    /// database's WAL is folded in and closed.
    pub fn shutdown(mut self) {
        if let Some(tx) = self.shutdown_tx.take() {
            let _ = tx.send(());
        }
        self.app.graceful.store(true, Ordering::SeqCst);
        self.stop(Duration::from_secs(30));
        if let Err(e) = self.app.store.close() {
            tracing::error!("closing the job database: {e:#}");
        }
    }

    /// Drop the server as a crash would: the HTTP runtime is torn down at once and the workers
    /// abandon their jobs mid-run without writing anything more.
    pub fn kill(mut self) {
        self.stop(Duration::from_secs(5));
    }

    fn stop(&mut self, wait: Duration) {
        self.app.stopping.store(true, Ordering::SeqCst);
        self.app.queue.wake_all();
        if let Some(rt) = self.runtime.take() {
            rt.shutdown_background();
        }
        let t0 = Instant::now();
        for w in self.workers.drain(..) {
            while !w.is_finished() && t0.elapsed() < wait {
                std::thread::sleep(Duration::from_millis(10));
            }
            if w.is_finished() {
                let _ = w.join();
            }
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        if self.runtime.is_some() {
            self.stop(Duration::from_secs(5));
        }
    }
}
