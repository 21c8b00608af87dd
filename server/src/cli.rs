//! The `fluidbed-server` command line: flags, logs, serve until interrupted.

use crate::{Config, Server};
use clap::Parser;
use std::net::SocketAddr;
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "fluidbed-server", version, about = "Serve fluidbed DEM-CFD jobs over HTTP")]
struct Args {
    /// Folder for snapshots, checkpoints and (without --database) the job database; created if
    /// missing. The nodes of a cluster share one (NFS, Lustre, …).
    #[arg(long, default_value = "fluidbed-data")]
    data_dir: PathBuf,
    /// Keep the job records in PostgreSQL (postgres://user@host:port/db): every server started
    /// with the same database and --data-dir is a node of one queue. Default: SQLite in --data-dir.
    #[arg(long, env = "FLUIDBED_DATABASE")]
    database: Option<String>,
    /// Seconds a node holds a job without a heartbeat; a node that dies loses its jobs to the
    /// others after this.
    #[arg(long, default_value_t = 30.0, value_parser = parse_lease)]
    lease_s: f64,
    /// Address to listen on (loopback by default; use 0.0.0.0:PORT deliberately, with --token).
    #[arg(long, default_value = "127.0.0.1:8471")]
    listen: SocketAddr,
    /// Require `Authorization: Bearer TOKEN` on every route but /healthz.
    #[arg(long, env = "FLUIDBED_TOKEN")]
    token: Option<String>,
    /// Jobs run at once (0 runs none: jobs are accepted and wait in the queue).
    #[arg(long, default_value_t = 1)]
    workers: usize,
    /// Threads of each job's rayon pool (default: the cores shared among the workers).
    #[arg(long)]
    threads_per_job: Option<usize>,
    /// Largest accepted case, in bytes.
    #[arg(long, default_value_t = 16 << 20)]
    max_body_bytes: usize,
    /// Most jobs waiting; more are refused with 429.
    #[arg(long, default_value_t = 64)]
    max_queued: usize,
    /// Sustained job submissions per second (bursts of 4 s worth); 0 = unlimited.
    #[arg(long, default_value_t = 5.0)]
    submissions_per_s: f64,
    /// Largest estimated peak memory of one job, e.g. 8G, 512M; larger cases are refused (422).
    #[arg(long, default_value = "8G", value_parser = parse_bytes)]
    max_job_memory: u64,
    /// Most client connections at once (kept below the open-file limit).
    #[arg(long, default_value_t = 512)]
    max_connections: usize,
    /// Seconds a client has to send a request's head; an idle connection is closed after this.
    #[arg(long, default_value_t = 20)]
    header_timeout_s: u64,
    /// Seconds a request body may pause between chunks.
    #[arg(long, default_value_t = 20)]
    body_timeout_s: u64,
    /// Log lines on stderr as text or as one JSON object each (levels from RUST_LOG, default info).
    #[arg(long, value_enum, default_value_t = LogFormat::Text)]
    log_format: LogFormat,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum LogFormat {
    Text,
    Json,
}

/// Logs through `tracing`: spans per request (method, route) and per job (id) on every line.
fn init_logs(format: LogFormat) {
    use tracing_subscriber::EnvFilter;
    let filter = EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new("info"));
    let logs = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr);
    match format {
        LogFormat::Text => logs.init(),
        LogFormat::Json => logs.json().init(),
    }
}

/// A byte count with an optional K, M, G or T suffix (powers of 1024).
fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, shift) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let shift = match c.to_ascii_uppercase() {
                'K' => 10,
                'M' => 20,
                'G' => 30,
                'T' => 40,
                _ => return Err(format!("unknown size suffix `{c}` (K, M, G, T)")),
            };
            (&t[..i], shift)
        }
        _ => (t, 0),
    };
    let n: f64 = num.trim().parse().map_err(|_| format!("`{s}` is not a size such as 8G or 512M"))?;
    let bytes = n * (1u64 << shift) as f64;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("`{s}` is out of range"));
    }
    Ok(bytes as u64)
}

fn parse_lease(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.5..=3600.0).contains(&v) => Ok(v),
        _ => Err(format!("`{s}` is not a lease from 0.5 to 3600 seconds")),
    }
}

fn cores() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

/// Threads per job: as asked, or the cores shared evenly among the jobs that run at once (a
/// job's threads step as one team; two coupled jobs of 2 threads each on 2 cores took 12–20% longer
/// per step than two of 1 thread, docs/BENCHMARKS.md "Jobs side by side").
fn threads_per_job(asked: Option<usize>, workers: usize, cores: usize) -> usize {
    asked.unwrap_or(cores / workers.max(1)).max(1)
}

/// Parse the flags, serve, stop cleanly on SIGINT or SIGTERM.
pub fn main() -> anyhow::Result<()> {
    let a = Args::parse();
    init_logs(a.log_format);
    let cores = cores();
    let threads_per_job = threads_per_job(a.threads_per_job, a.workers, cores);
    if a.workers * threads_per_job > cores {
        tracing::warn!(
            workers = a.workers,
            threads_per_job,
            cores,
            "more job threads than cores: concurrent jobs will contend (--threads-per-job {} would not)",
            self::threads_per_job(None, a.workers, cores)
        );
    }
    let cfg = Config {
        data_dir: a.data_dir,
        database: a.database.filter(|d| !d.is_empty()),
        lease: std::time::Duration::from_secs_f64(a.lease_s),
        listen: a.listen,
        token: a.token.filter(|t| !t.is_empty()),
        workers: a.workers,
        threads_per_job,
        max_body_bytes: a.max_body_bytes,
        max_queued: a.max_queued,
        submissions_per_s: a.submissions_per_s,
        max_job_memory: a.max_job_memory,
        max_connections: a.max_connections,
        header_read_timeout: std::time::Duration::from_secs(a.header_timeout_s.max(1)),
        body_read_timeout: std::time::Duration::from_secs(a.body_timeout_s.max(1)),
        request_timeout: std::time::Duration::from_secs(60.max(3 * a.body_timeout_s)),
    };
    let dir = cfg.data_dir.clone();
    let server = match Server::start(cfg) {
        Ok(s) => s,
        Err(e) => {
            tracing::error!("cannot start: {e:#}");
            std::process::exit(1);
        }
    };
    tracing::info!("listening on {} (data in {})", server.url(), dir.display());
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    rt.block_on(async {
        #[cfg(unix)]
        {
            let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
            tokio::select! { _ = tokio::signal::ctrl_c() => {}, _ = term.recv() => {} }
        }
        #[cfg(not(unix))]
        tokio::signal::ctrl_c().await?;
        Ok::<_, std::io::Error>(())
    })?;
    tracing::info!("stopping; running jobs resume from their checkpoints at the next start");
    server.shutdown();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::threads_per_job;

    #[test]
    fn the_cores_are_shared_among_the_workers_unless_asked() {
        assert_eq!(threads_per_job(None, 1, 8), 8);
        assert_eq!(threads_per_job(None, 2, 8), 4);
        assert_eq!(threads_per_job(None, 3, 8), 2);
        assert_eq!(threads_per_job(None, 4, 2), 1, "at least one thread");
        assert_eq!(threads_per_job(None, 0, 2), 2, "no workers: as one");
        assert_eq!(threads_per_job(Some(3), 2, 2), 3, "as asked");
        assert_eq!(threads_per_job(Some(0), 1, 2), 1);
    }
}
