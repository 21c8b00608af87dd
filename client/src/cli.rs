//! The command line: verbs map one-to-one to the HTTP API; `run` = submit + watch + fetch.

use crate::api::Api;
use crate::exit;
use crate::fetch::{fetch, fetch_analysis, Formats};
use crate::outcome::{api_fail, fail, outcome_code, report_outcome};
use crate::validate::validate;
use crate::watch::watch;
use clap::{Parser, Subcommand};
use fluidbed_api::{Job, JobStatus, ListQuery};
use serde_json::json;
use std::ffi::OsString;
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "fluidbed", version, about = "Run and fetch fluidbed DEM-CFD jobs", after_help = EXIT_HELP)]
struct Cli {
    /// Server URL; without it `run` starts an embedded server on a free loopback port.
    #[arg(long, global = true, env = "FLUIDBED_SERVER")]
    server: Option<String>,
    /// Bearer token for a server started with --token.
    #[arg(long, global = true, env = "FLUIDBED_TOKEN")]
    token: Option<String>,
    /// Machine-readable output (JSON) instead of text and progress bars.
    #[arg(long, global = true)]
    json: bool,
    #[command(subcommand)]
    verb: Verb,
}

const EXIT_HELP: &str = "Exit codes: 0 success, 2 invalid case, 3 job failed or cancelled, 4 server or connection error, 64 bad command line.";

#[derive(Subcommand)]
enum Verb {
    /// Check a case locally (the same checks and messages as the server).
    Validate { case: PathBuf },
    /// Submit a case; prints the job id.
    Submit { case: PathBuf },
    /// List jobs, newest first.
    List {
        #[arg(long)]
        status: Option<String>,
        #[arg(long, default_value_t = 20)]
        limit: usize,
    },
    /// Show a job's status.
    Status { id: String },
    /// Follow a job to its end with a progress bar (ETA, latest ΔP).
    Watch { id: String },
    /// Download results into a folder.
    Fetch {
        id: String,
        /// Output folder (default ./fluidbed-out/<job id>/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Per-snapshot encodings: npy, vtk, json (comma separated).
        #[arg(long, default_value = "npy,vtk")]
        formats: String,
    },
    /// Download the job's analysis (analysis.json and its figures) and print its main figures;
    /// the case's `analysis` section sets the window and the heights.
    Analyze {
        id: String,
        /// Output folder (default ./fluidbed-out/<job id>/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Take the ΔP statistics, bubble count and rise velocity from this simulated time (s);
        /// the maps and profiles keep the whole window of the case's `analysis`.
        #[arg(long, value_name = "T")]
        from: Option<f64>,
    },
    /// Cancel a job.
    Cancel { id: String },
    /// Run a base case over a grid of values, one job per point, and print a summary table
    /// (ΔP mean and deviation, bed height) when every point has ended; with no --server, on an
    /// embedded server running one point per core.
    Sweep {
        base: PathBuf,
        /// POINTER=FROM:TO:STEP, POINTER=V1,V2,… or POINTER=V; repeat for a grid of every combination.
        #[arg(long = "set", required = true, value_name = "POINTER=VALUES")]
        set: Vec<String>,
        /// The sweep's name (default: the base case's).
        #[arg(long)]
        name: Option<String>,
        /// Output folder (default ./fluidbed-out/<case file name>-sweep/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Threads per point on the embedded server (default 1, one point per core).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Submit, watch and fetch; with no --server, on an embedded server.
    Run {
        case: PathBuf,
        /// Output folder (default ./fluidbed-out/<case file name>/).
        #[arg(long)]
        out: Option<PathBuf>,
        #[arg(long, default_value = "npy,vtk")]
        formats: String,
        /// Threads for the job on the embedded server (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
    },
}

/// Run the CLI with these arguments (argv[0] first); returns the exit code.
pub fn main_with<I: IntoIterator<Item = T>, T: Into<OsString> + Clone>(args: I) -> i32 {
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { exit::USAGE } else { exit::OK };
        }
    };
    if let Verb::Validate { case } = &cli.verb {
        return validate(case, cli.json).0;
    }
    let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(rt) => rt,
        Err(e) => return fail(exit::SERVER, &format!("cannot start the async runtime: {e}")),
    };
    rt.block_on(dispatch(cli))
}

fn print_job(j: &Job, json_out: bool) {
    if json_out {
        println!("{}", serde_json::to_string(j).unwrap_or_default());
    } else {
        let eta = j.eta_s.map(|e| format!(", ETA {e:.0} s")).unwrap_or_default();
        let msg = j.message.as_deref().map(|m| format!(" — {m}")).unwrap_or_default();
        println!(
            "{}  {:9}  {:5.1}%  t = {:.4}/{:.4} s  {} steps  {:.1} s wall{eta}  {}{msg}",
            j.id,
            j.status.as_str(),
            100.0 * j.progress,
            j.time_s,
            j.end_time_s,
            j.steps,
            j.wall_time_s,
            j.name
        );
    }
}

/// The headline figures of an analysis document.
fn print_analysis(a: &serde_json::Value) {
    let num = |v: &serde_json::Value| v.as_f64().map(|x| format!("{x:.4}")).unwrap_or_else(|| "—".into());
    println!("window {} – {} s, {} samples", num(&a["from_s"]), num(&a["to_s"]), a["samples"]);
    if a["series_samples"] != a["samples"] {
        println!("ΔP, bubbles and rise velocity from {} s, {} samples", num(&a["series_from_s"]), a["series_samples"]);
    }
    let dp = &a["pressure_drop"];
    println!(
        "ΔP mean {} Pa, std {} Pa, dominant frequency {} Hz",
        num(&dp["mean_pa"]),
        num(&dp["std_pa"]),
        num(&dp["dominant_frequency_hz"])
    );
    println!("bed height {} m", num(&a["bed_height_m"]));
    println!(
        "bubbles {} per second at {} m",
        num(&a["bubbles"]["count"]["per_second"]),
        num(&a["bubbles"]["height_m"])
    );
    let rise = &a["rise_velocity"];
    println!(
        "rise velocity {} m/s between {} and {} m",
        num(&rise["voidage"]["velocity_m_s"]),
        num(&rise["lower_m"]),
        num(&rise["upper_m"])
    );
    let e = &a["eruptions"];
    println!(
        "eruptions {} per second at {} m, {} ΔP cycles per eruption, ΔP swing {} Pa around them",
        num(&e["fronts"]["count"]["per_second"]),
        num(&e["fronts"]["height_m"]),
        num(&e["dp_frequency_per_eruption"]),
        num(&e["link"]["swing_pa"])
    );
    println!(
        "bed surface falls {} times per second, {} ΔP cycles per surface fall",
        num(&e["surface_frequency_hz"]),
        num(&e["dp_frequency_per_surface_cycle"])
    );
}

async fn dispatch(cli: Cli) -> i32 {
    let token = cli.token.clone().filter(|t| !t.is_empty());
    let server = cli.server.clone().unwrap_or_else(|| "http://127.0.0.1:8471".into());
    let api = match Api::new(&server, token.as_deref()) {
        Ok(a) => a,
        Err(e) => return fail(exit::USAGE, &format!("bad --server or --token: {e}")),
    };
    let j = cli.json;
    // A job id is 16 hex digits: anything else (`../../x`) would leave the output folder or the URL.
    if let Verb::Status { id }
    | Verb::Watch { id }
    | Verb::Fetch { id, .. }
    | Verb::Analyze { id, .. }
    | Verb::Cancel { id } = &cli.verb
    {
        if id.is_empty() || id.len() > 64 || !id.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-') {
            return fail(exit::USAGE, &format!("`{id}` is not a job id (letters, digits and '-')"));
        }
    }
    match cli.verb {
        Verb::Validate { .. } => exit::OK,
        Verb::Submit { case } => {
            let (code, ok) = validate(&case, false);
            let Some((text, _)) = ok else { return code };
            match api.submit(&text).await {
                Ok(job) if j => {
                    println!("{}", serde_json::to_string(&job).unwrap_or_default());
                    exit::OK
                }
                Ok(job) => {
                    println!("{}", job.id);
                    exit::OK
                }
                Err(e) => api_fail(e, j),
            }
        }
        Verb::List { status, limit } => {
            let status = match status.as_deref().map(|s| JobStatus::parse(s).ok_or(s)).transpose() {
                Ok(s) => s,
                Err(s) => {
                    return fail(
                        exit::USAGE,
                        &format!("`{s}` is not a status (queued, running, succeeded, failed, cancelled)"),
                    )
                }
            };
            match api.jobs(&ListQuery { status, limit: Some(limit as u64), offset: None }).await {
                Ok(list) if j => {
                    println!("{}", serde_json::to_string(&list).unwrap_or_default());
                    exit::OK
                }
                Ok(list) => {
                    list.jobs.iter().for_each(|job| print_job(job, false));
                    exit::OK
                }
                Err(e) => api_fail(e, j),
            }
        }
        Verb::Status { id } => match api.job(&id).await {
            Ok(v) => {
                print_job(&v, j);
                if !j {
                    for line in crate::plan_view::plan_lines(&v).into_iter().chain(crate::plan_view::stage_line(&v)) {
                        println!("  {line}");
                    }
                }
                exit::OK
            }
            Err(e) => api_fail(e, j),
        },
        Verb::Watch { id } => match watch(&api, &id, j).await {
            Ok(o) => {
                report_outcome(&id, o.status, o.message.as_deref(), j);
                outcome_code(o.status)
            }
            Err(e) => api_fail(e, j),
        },
        Verb::Fetch { id, out, formats } => {
            let out = out.unwrap_or_else(|| PathBuf::from("fluidbed-out").join(&id));
            let f = match Formats::parse(&formats) {
                Ok(f) => f,
                Err(m) => return fail(exit::USAGE, &m),
            };
            match fetch(&api, &id, &out, &f).await {
                Ok(files) => {
                    if j {
                        println!("{}", json!({ "id": id, "files": files }));
                    } else {
                        println!("{} files in {}", files.len(), out.display());
                    }
                    exit::OK
                }
                Err(e) => api_fail(e, j),
            }
        }
        Verb::Analyze { id, out, from } => {
            if from.is_some_and(|t| !(t.is_finite() && t >= 0.0)) {
                return fail(exit::USAGE, "--from must be a simulated time ≥ 0 s");
            }
            let out = out.unwrap_or_else(|| PathBuf::from("fluidbed-out").join(&id));
            match fetch_analysis(&api, &id, &out, from).await {
                Ok(files) if files.is_empty() => {
                    fail(exit::SERVER, &format!("job {id} has no analysis yet (no checkpoint written)"))
                }
                Ok(files) => {
                    let text = std::fs::read_to_string(out.join("analysis.json")).unwrap_or_default();
                    let a: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
                    if j {
                        println!("{}", json!({ "id": id, "files": files, "analysis": a }));
                    } else {
                        print_analysis(&a);
                        println!("{} files in {}", files.len(), out.display());
                    }
                    exit::OK
                }
                Err(e) => api_fail(e, j),
            }
        }
        Verb::Cancel { id } => match api.cancel(&id).await {
            Ok(v) => {
                print_job(&v, j);
                exit::OK
            }
            Err(e) => api_fail(e, j),
        },
        Verb::Sweep { base, set, name, out, threads } => {
            let args = crate::cli_sweep::SweepArgs { base, set, name, out, threads };
            crate::cli_sweep::sweep(cli.server.is_some().then_some(api), token, args, j).await
        }
        Verb::Run { case, out, formats, threads } => {
            crate::cli_run::run(cli.server.is_some().then_some(api), token, case, out, formats, threads, j).await
        }
    }
}
