//! The HTTP listener: hyper's HTTP/1.1 server under the axum router, with the limits that keep
//! slow and idle clients from exhausting the server: a header read timeout (hyper runs it from
//! the moment it waits for a request head, so it also closes idle keep-alive connections), and a
//! connection limit kept below the process's open-file limit so that jobs can always open their
//! files. Body and request timeouts are tower-http layers (api::router).

use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::{oneshot, Semaphore};

/// File descriptors never handed to connections: the database, snapshot and checkpoint files,
/// the job threads' files, the bed cache.
const RESERVED_FDS: usize = 128;

/// Accept connections until `shutdown` fires; at most `max_connections` at once (further
/// clients wait in the listen backlog).
pub async fn serve(
    listener: tokio::net::TcpListener,
    router: Router,
    header_read_timeout: Duration,
    max_connections: usize,
    shutdown: oneshot::Receiver<()>,
) {
    let permits = Arc::new(Semaphore::new(max_connections.max(1)));
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new()).header_read_timeout(header_read_timeout);
    let http = Arc::new(http);
    tokio::pin!(shutdown);
    loop {
        let permit = tokio::select! {
            p = permits.clone().acquire_owned() => match p { Ok(p) => p, Err(_) => return },
            _ = &mut shutdown => return,
        };
        let tcp = tokio::select! {
            r = listener.accept() => match r {
                Ok((tcp, _)) => tcp,
                Err(e) => {
                    // EMFILE and the like: back off instead of spinning; the permit is returned.
                    tracing::warn!(error = %e, "accept failed");
                    tokio::time::sleep(Duration::from_millis(100)).await;
                    continue;
                }
            },
            _ = &mut shutdown => return,
        };
        let _ = tcp.set_nodelay(true);
        let svc = TowerToHyperService::new(router.clone());
        let http = http.clone();
        tokio::spawn(async move {
            let _ = http.serve_connection(TokioIo::new(tcp), svc).await;
            drop(permit);
        });
    }
}

/// Raise the soft open-file limit to the hard one, and return how many connections fit under it
/// with RESERVED_FDS left for the jobs (at most `wanted`).
pub fn connection_budget(wanted: usize) -> usize {
    #[cfg(unix)]
    {
        let mut lim = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        // SAFETY: getrlimit/setrlimit only read and write the struct passed.
        unsafe {
            if libc::getrlimit(libc::RLIMIT_NOFILE, &mut lim) == 0 {
                if lim.rlim_cur < lim.rlim_max {
                    let raised = libc::rlimit { rlim_cur: lim.rlim_max, rlim_max: lim.rlim_max };
                    if libc::setrlimit(libc::RLIMIT_NOFILE, &raised) == 0 {
                        lim = raised;
                    }
                }
                let files = usize::try_from(lim.rlim_cur).unwrap_or(usize::MAX);
                return wanted.min(files.saturating_sub(RESERVED_FDS).max(16));
            }
        }
    }
    wanted
}
