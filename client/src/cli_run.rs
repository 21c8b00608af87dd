//! `fluidbed run`: submit, watch, fetch. Without `--server` it starts an embedded server
//! in-process on a free loopback port (data in `<out>/server-data/`, fresh for each run) and
//! talks to it over HTTP like to any other server.

use crate::api::Api;
use crate::exit;
use crate::fetch::{fetch, Formats};
use crate::outcome::{api_fail, fail, outcome_code, report_outcome};
use crate::validate::validate;
use crate::watch::watch;
use serde_json::json;
use std::path::PathBuf;

pub async fn run(
    server: Option<Api>,
    token: Option<String>,
    case: PathBuf,
    out: Option<PathBuf>,
    formats: String,
    threads: Option<usize>,
    json_out: bool,
) -> i32 {
    let formats = match Formats::parse(&formats) {
        Ok(f) => f,
        Err(m) => return fail(exit::USAGE, &m),
    };
    let (code, ok) = validate(&case, false);
    let Some((text, _name)) = ok else { return code };
    let stem = case.file_stem().and_then(|s| s.to_str()).unwrap_or("case").to_string();
    let out = out.unwrap_or_else(|| PathBuf::from("fluidbed-out").join(&stem));
    if let Err(m) = fresh_out(&out) {
        return fail(exit::USAGE, &m);
    }
    let (api, embedded) = match server {
        Some(api) => (api, None),
        None => match start_embedded(&out, Embedding::one_job(threads), token.as_deref()) {
            Ok(pair) => pair,
            Err(code) => return code,
        },
    };
    if !json_out {
        eprintln!("fluidbed: running {} on {}", case.display(), api.base);
    }
    let code = submit_watch_fetch(&api, &text, &out, &formats, json_out).await;
    stop_embedded(embedded).await;
    code
}

/// Stop the embedded server, if one was started (its jobs checkpoint first).
pub(crate) async fn stop_embedded(embedded: Option<Embedded>) {
    #[cfg(feature = "embedded")]
    if let Some(s) = embedded {
        let _ = tokio::task::spawn_blocking(move || s.shutdown()).await;
    }
    #[cfg(not(feature = "embedded"))]
    let _ = embedded;
}

/// Marks a folder as written by `fluidbed run`, so that a later run may replace it whole.
const RUN_MARKER: &str = ".fluidbed-run";

/// Make `out` an empty folder for this run's results: a previous run's folder is replaced (no
/// stale files beside new ones); any other non-empty folder is refused.
pub(crate) fn fresh_out(out: &std::path::Path) -> Result<(), String> {
    let entries = match std::fs::read_dir(out) {
        Ok(rd) => rd.count(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => 0,
        Err(e) => return Err(format!("cannot read the output folder {}: {e}", out.display())),
    };
    if entries > 0 {
        if !out.join(RUN_MARKER).is_file() {
            return Err(format!(
                "the output folder {} is not empty and was not written by `fluidbed run`: choose another --out",
                out.display()
            ));
        }
        std::fs::remove_dir_all(out).map_err(|e| format!("cannot clear {}: {e}", out.display()))?;
    }
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    std::fs::write(out.join(RUN_MARKER), b"results of `fluidbed run`; the next run into this folder replaces it\n")
        .map_err(|e| format!("cannot write in {}: {e}", out.display()))
}

async fn submit_watch_fetch(api: &Api, text: &str, out: &std::path::Path, formats: &Formats, json_out: bool) -> i32 {
    let job = match api.submit(text).await {
        Ok(j) => j,
        Err(e) => return api_fail(e, json_out),
    };
    let id = job.id;
    if !json_out {
        eprintln!("fluidbed: job {id} submitted");
    }
    let outcome = match watch(api, &id, json_out).await {
        Ok(o) => o,
        Err(e) => return api_fail(e, json_out),
    };
    // Fetch what exists even when the job failed: the last good snapshots are kept.
    let files = match fetch(api, &id, out, formats).await {
        Ok(f) => f,
        Err(e) => return api_fail(e, json_out),
    };
    report_outcome(&id, outcome.status, outcome.message.as_deref(), false);
    if !json_out {
        if let Ok(job) = api.job(&id).await {
            for line in crate::plan_view::plan_lines(&job).into_iter().chain(crate::plan_view::stage_line(&job)) {
                eprintln!("fluidbed: {line}");
            }
        }
    }
    if json_out {
        println!(
            "{}",
            json!({ "id": id, "status": outcome.status, "message": outcome.message, "out": out, "files": files })
        );
    } else {
        eprintln!("fluidbed: {} files in {}", files.len(), out.display());
    }
    outcome_code(outcome.status)
}

#[cfg(feature = "embedded")]
pub(crate) type Embedded = fluidbed_server::Server;
#[cfg(not(feature = "embedded"))]
pub(crate) type Embedded = ();

/// How the embedded server runs its jobs.
pub(crate) struct Embedding {
    pub workers: usize,
    pub threads_per_job: usize,
    pub max_queued: usize,
}

fn cores() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

impl Embedding {
    /// One job on every core (or `threads`).
    pub fn one_job(threads: Option<usize>) -> Embedding {
        Embedding { workers: 1, threads_per_job: threads.unwrap_or_else(cores), max_queued: 64 }
    }
    /// Independent points: one job per core, one thread each (`threads` each if given), and a
    /// queue long enough for the sweep.
    pub fn many_jobs(threads: Option<usize>, points: usize) -> Embedding {
        let threads_per_job = threads.unwrap_or(1).max(1);
        Embedding { workers: (cores() / threads_per_job).max(1), threads_per_job, max_queued: points.max(64) }
    }
}

#[cfg(feature = "embedded")]
pub(crate) fn start_embedded(
    out: &std::path::Path,
    how: Embedding,
    token: Option<&str>,
) -> Result<(Api, Option<Embedded>), i32> {
    let data = out.join("server-data");
    if data.exists() {
        std::fs::remove_dir_all(&data)
            .map_err(|e| fail(exit::SERVER, &format!("cannot clear {}: {e}", data.display())))?;
    }
    let mut cfg = fluidbed_server::Config::new(data);
    cfg.listen = std::net::SocketAddr::from(([127, 0, 0, 1], 0));
    cfg.workers = how.workers;
    cfg.threads_per_job = how.threads_per_job;
    cfg.max_queued = how.max_queued;
    cfg.token = token.map(str::to_string);
    let server = fluidbed_server::Server::start(cfg)
        .map_err(|e| fail(exit::SERVER, &format!("cannot start the embedded server: {e:#}")))?;
    let api = Api::new(&server.url(), token).map_err(|e| fail(exit::SERVER, &e.to_string()))?;
    Ok((api, Some(server)))
}

#[cfg(not(feature = "embedded"))]
pub(crate) fn start_embedded(
    _out: &std::path::Path,
    _how: Embedding,
    _token: Option<&str>,
) -> Result<(Api, Option<Embedded>), i32> {
    Err(fail(exit::USAGE, "this build has no embedded server (feature `embedded`): pass --server URL"))
}
