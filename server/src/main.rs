//! fluidbed-server: serve fluidbed jobs over HTTP until interrupted.

use clap::Parser;
use fluidbed_server::{Config, Server};
use std::net::SocketAddr;
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "fluidbed-server", version, about = "Serve fluidbed DEM-CFD jobs over HTTP")]
struct Args {
    /// Folder for the job database, snapshots and checkpoints (created if missing).
    #[arg(long, default_value = "fluidbed-data")]
    data_dir: PathBuf,
    /// Address to listen on (loopback by default; use 0.0.0.0:PORT deliberately, with --token).
    #[arg(long, default_value = "127.0.0.1:8471")]
    listen: SocketAddr,
    /// Require `Authorization: Bearer TOKEN` on every route but /healthz.
    #[arg(long, env = "FLUIDBED_TOKEN")]
    token: Option<String>,
    /// Jobs run at once.
    #[arg(long, default_value_t = 1)]
    workers: usize,
    /// Threads of each job's rayon pool.
    #[arg(long, default_value_t = default_threads())]
    threads_per_job: usize,
    /// Largest accepted case, in bytes.
    #[arg(long, default_value_t = 16 << 20)]
    max_body_bytes: usize,
    /// Most jobs waiting; more are refused with 429.
    #[arg(long, default_value_t = 64)]
    max_queued: usize,
    /// Sustained job submissions per second (bursts of 4 s worth); 0 = unlimited.
    #[arg(long, default_value_t = 5.0)]
    submissions_per_s: f64,
}

fn default_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

fn main() -> anyhow::Result<()> {
    let a = Args::parse();
    let cfg = Config {
        data_dir: a.data_dir,
        listen: a.listen,
        token: a.token.filter(|t| !t.is_empty()),
        workers: a.workers,
        threads_per_job: a.threads_per_job,
        max_body_bytes: a.max_body_bytes,
        max_queued: a.max_queued,
        submissions_per_s: a.submissions_per_s,
    };
    let dir = cfg.data_dir.clone();
    let server = Server::start(cfg)?;
    eprintln!("fluidbed-server: listening on {} (data in {})", server.url(), dir.display());
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
    eprintln!("fluidbed-server: stopping; running jobs resume from their checkpoints at the next start");
    server.shutdown();
    Ok(())
}
