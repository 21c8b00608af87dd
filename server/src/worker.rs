//! Worker threads: each claims a job from the store's queue (holding its lease, heartbeat.rs)
//! and runs it on its own rayon pool, never on the async runtime. Between chunks of steps it
//! checks for cancellation and a lost lease, stores snapshots, writes checkpoints atomically, and
//! publishes progress.

use crate::events::{snapshot_payload, EventKind, JobEvent};
use crate::job::{now_rfc3339, SnapshotInfo, Status};
use crate::metrics::JobRate;
use crate::App;
use anyhow::Result;
use fluidbed_core::case::Case;
use fluidbed_core::dem::solver_pool;
use fluidbed_core::output::fields;
use fluidbed_core::sim::{Simulation, StageTimers};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// Wall time one chunk of steps aims at: short enough for prompt cancels and smooth progress.
const CHUNK_WALL: Duration = Duration::from_millis(150);
/// Least wall time between two progress events.
const PROGRESS_EVERY: Duration = Duration::from_millis(300);

/// Rung when a job is submitted here, so that an idle worker claims it at once (jobs from other
/// nodes are found by polling).
#[derive(Default)]
pub struct Queue {
    rung: Mutex<bool>,
    ready: Condvar,
}

impl Queue {
    pub fn ring(&self) {
        *self.rung.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.ready.notify_all();
    }
    /// Until rung or `timeout`.
    fn wait(&self, timeout: Duration) {
        let mut rung = self.rung.lock().unwrap_or_else(|e| e.into_inner());
        if !*rung {
            rung = self.ready.wait_timeout(rung, timeout).unwrap_or_else(|e| e.into_inner()).0;
        }
        *rung = false;
    }
    pub fn wake_all(&self) {
        self.ring();
    }
}

/// How often an idle worker looks for work (another node's submission, an expired lease).
fn poll_every(app: &App) -> Duration {
    if app.store.records().shared() {
        Duration::from_millis(500)
    } else {
        Duration::from_millis(200)
    }
}

/// Start `n` worker threads (none for 0: jobs are accepted and wait in the queue).
pub fn spawn(app: &Arc<App>, n: usize) -> Vec<std::thread::JoinHandle<()>> {
    (0..n)
        .map(|k| {
            let app = app.clone();
            std::thread::Builder::new()
                .name(format!("fluidbed-worker-{k}"))
                .spawn(move || {
                    while !app.stopping() {
                        let lease_s = app.config.lease.as_secs_f64();
                        match app.store.records().claim(&app.node, lease_s) {
                            Ok(Some(id)) => {
                                let _job = tracing::info_span!("job", id = %id).entered();
                                run_claimed(&app, &id);
                            }
                            Ok(None) => app.queue.wait(poll_every(&app)),
                            Err(e) => {
                                tracing::warn!("cannot look for queued jobs: {e:#}");
                                app.queue.wait(Duration::from_secs(1));
                            }
                        }
                    }
                })
                .expect("spawn worker thread")
        })
        .collect()
}

/// Run a job this node holds the lease of, renewing the lease meanwhile (heartbeat.rs).
fn run_claimed(app: &Arc<App>, id: &str) {
    let lost = AtomicBool::new(false);
    let done = crate::heartbeat::Done::default();
    std::thread::scope(|s| {
        s.spawn(|| crate::heartbeat::beat(app, id, &lost, &done));
        // A panic in the solver fails its job, not the worker.
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run_job(app, id, &lost)));
        done.set();
        app.metrics.job_stopped(id);
        let error = match outcome {
            Ok(Ok(())) => None,
            Ok(Err(e)) => {
                // Most likely a write that failed (a full or read-only disk): free the reserve
                // so that the failure itself can be stored.
                app.store.release_reserve();
                app.health.write_failed(&format!("{e:#}"));
                Some(format!("cannot store the job's results: {e:#}"))
            }
            Err(p) => Some(format!("the solver panicked: {}", panic_text(&*p))),
        };
        if let Some(msg) = error.filter(|_| !app.stopping() && !lost.load(Ordering::SeqCst)) {
            tracing::error!("{msg}");
            finish(app, id, Status::Failed, Some(&msg));
        }
    });
    if lost.load(Ordering::SeqCst) {
        tracing::warn!("lease lost: stopped here, the job goes on where its lease is now");
    }
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// End a job. Listeners get `status` and `end` even when the store cannot record it (a full
/// disk), so that no client waits for ever.
fn finish(app: &App, id: &str, status: Status, message: Option<&str>) {
    if app.stopping() {
        return;
    }
    let doc = match app.store.finish(id, status, message, &now_rfc3339(), Some(&app.node)) {
        Ok(true) => app.store.get(id).ok().flatten().map(|j| j.status_event()),
        Ok(false) => None,
        Err(e) => {
            let msg = format!("cannot record that job {id} {}: {e:#}", status.as_str());
            tracing::error!("{msg}");
            app.health.write_failed(&msg);
            Some(fluidbed_api::StatusEvent { status, message: message.map(str::to_string) })
        }
    };
    tracing::info!(status = status.as_str(), reason = message, "job ended");
    if let Some(doc) = doc {
        app.hub.publish(id, JobEvent::new(EventKind::Status, None, &doc));
        app.hub.publish(id, JobEvent::new(EventKind::End, None, &doc));
    }
    app.cancels.lock().unwrap_or_else(|e| e.into_inner()).remove(id);
    app.hub.close(id);
}

/// After this many starts that took the server down (a crash, an abort, a kill), a job is failed
/// instead of resumed: it would take the next server down too.
pub const MAX_CRASHES: u32 = 2;

/// The cancel flag of a job (created on first use).
pub fn cancel_flag(app: &App, id: &str) -> Arc<AtomicBool> {
    app.cancels.lock().unwrap_or_else(|e| e.into_inner()).entry(id.to_string()).or_default().clone()
}

fn run_job(app: &Arc<App>, id: &str, lost: &AtomicBool) -> Result<()> {
    let Some(job) = app.store.get(id)? else { return Ok(()) };
    if job.status.is_final() {
        return Ok(());
    }
    let cancel = cancel_flag(app, id);
    if job.cancel_requested {
        cancel.store(true, Ordering::SeqCst);
    }
    if cancel.load(Ordering::SeqCst) {
        let when = if job.status == Status::Queued { "before it started" } else { "by request" };
        finish(app, id, Status::Cancelled, Some(&format!("cancelled {when}")));
        return Ok(());
    }
    if job.attempts >= MAX_CRASHES {
        let msg = format!(
            "not resumed: the server stopped unexpectedly {} times while running this job (out of memory?); \
             submit it again with a smaller case or a larger --max-job-memory",
            job.attempts
        );
        return fail(app, id, &msg);
    }
    if !app.store.set_running(id, &now_rfc3339())? {
        return Ok(());
    }
    if let Some(job) = app.store.get(id)? {
        app.hub.publish(id, JobEvent::new(EventKind::Status, None, &job.status_event()));
    }
    let threads = app.config.threads_per_job.max(1);
    // Its own team lock, so that concurrent jobs each step DEM as a team (`team_step`).
    let pool = solver_pool().num_threads(threads).thread_name(|k| format!("fluidbed-job-{k}")).build()?;
    let base_wall = job.wall_s;
    tracing::info!(threads, resumed = job.status == Status::Running, "job started");
    let span = tracing::Span::current();
    let out = pool.install(|| span.in_scope(|| drive(app, id, &cancel, lost, base_wall)));
    if app.stopping() && app.graceful() && !lost.load(Ordering::SeqCst) {
        app.store.records().release(id, &app.node, true)?;
    }
    out
}

/// Build or restore the simulation and step it to the end, a chunk at a time.
fn drive(app: &Arc<App>, id: &str, cancel: &AtomicBool, lost: &AtomicBool, base_wall: f64) -> Result<()> {
    let prepared_from = Instant::now();
    let lost = || lost.load(Ordering::SeqCst);
    // A crash-like stop or a lost lease: write nothing more.
    let abandon = || lost() || (app.stopping() && !app.graceful());
    let mut sim = match app.store.checkpoint(id)? {
        Some(bytes) => match Simulation::restore(&bytes) {
            Ok(s) => s,
            Err(e) => return fail(app, id, &e.to_string()),
        },
        None => {
            let case_json = app.store.case_json(id)?.unwrap_or_default();
            let case = Case::from_stored_json(&case_json)?;
            // A generated bed is poured and settled first (minutes for a large bed, then
            // cached): say so, since the run's progress stays at 0 meanwhile.
            let preparing = matches!(case.bed, fluidbed_core::case::Bed::Generated(_));
            if preparing {
                say(app, id, Some("preparing the bed: pouring and settling the particles (reused from the cache if this bed was made before)"))?;
            }
            // The pour stops at once on a cancel or a server stop (then Simulation::new finds
            // the poured bed in the cache).
            let stop = || cancel.load(Ordering::SeqCst) || app.stopping() || lost();
            let cache = app.store.cache_dir();
            if let Err(e) = fluidbed_core::dem::build_bed_until(&case, Some(&cache), &stop) {
                return if app.stopping() || lost() {
                    Ok(())
                } else if cancel.load(Ordering::SeqCst) {
                    finish(app, id, Status::Cancelled, Some("cancelled by request while preparing the bed"));
                    Ok(())
                } else {
                    fail(app, id, &format!("cannot prepare the bed: {e}"))
                };
            }
            let sim = match Simulation::new(case, Some(&cache)) {
                Ok(s) => s,
                Err(e) => return fail(app, id, &e.to_string()),
            };
            if preparing {
                say(app, id, None)?;
            }
            sim
        }
    };
    if app.stopping() || lost() {
        return Ok(());
    }
    if cancel.load(Ordering::SeqCst) {
        finish(app, id, Status::Cancelled, Some("cancelled by request"));
        return Ok(());
    }
    let mut plan = serde_json::to_value(sim.plan())?;
    plan["skipped"] = serde_json::to_value(sim.plan().skipped(sim.case()))?;
    app.store.set_plan(id, &plan)?;
    // The ETA's rate counts stepping only, not the preparation before it.
    let started = Instant::now();
    let checkpoint_every = sim.case().outputs.checkpoint_interval_s;
    let mut last_checkpoint_t = sim.time();
    let (t_start, end, steps_start) = (sim.time(), sim.end_time(), sim.steps());
    let mut chunk: u64 = 10;
    let mut last_progress = Instant::now() - PROGRESS_EVERY;
    let wall_before = base_wall + prepared_from.elapsed().as_secs_f64();
    while !sim.is_finished() {
        if lost() {
            return Ok(());
        }
        if app.stopping() {
            return stop_here(app, id, &sim);
        }
        if cancel.load(Ordering::SeqCst) {
            finish(app, id, Status::Cancelled, Some("cancelled by request"));
            return Ok(());
        }
        let t0 = Instant::now();
        let out = sim.advance(chunk);
        // Aim each chunk at CHUNK_WALL, growing or shrinking by at most 2x.
        let took = t0.elapsed().as_secs_f64().max(1e-6);
        chunk = ((chunk as f64 * (CHUNK_WALL.as_secs_f64() / took).clamp(0.5, 2.0)) as u64).clamp(1, 1 << 24);
        let snap = match out {
            Ok(s) => s,
            Err(e) => return fail(app, id, &e.to_string()),
        };
        // A crash-like stop writes nothing more; a graceful one stores this chunk's snapshot and
        // checkpoints at the top of the loop.
        if abandon() {
            return Ok(());
        }
        let wall = wall_before + started.elapsed().as_secs_f64();
        let rate = (sim.time() - t_start) / started.elapsed().as_secs_f64().max(1e-9);
        let eta = (rate > 0.0).then(|| (end - sim.time()).max(0.0) / rate);
        if let Some(s) = snap {
            let info = SnapshotInfo {
                n: s.index,
                time_s: s.time_s,
                step: s.step,
                pressure_drop_pa: s.pressure_drop_pa,
                mean_particle_height_m: fields::mean_particle_height_m(&s),
            };
            app.metrics.snapshot_written(app.store.put_snapshot(id, &s, &info)?);
            if sim.time() - last_checkpoint_t >= checkpoint_every || sim.is_finished() {
                if abandon() {
                    return Ok(());
                }
                put_checkpoint(app, id, &sim)?;
                last_checkpoint_t = sim.time();
            }
            app.store.set_progress(id, sim.time(), end, sim.steps(), wall, eta)?;
            app.hub.publish(id, JobEvent::new(EventKind::Snapshot, Some(s.index), &snapshot_payload(&s, &info)));
        }
        let stepped = (sim.steps() - steps_start) as f64;
        app.metrics.job_running(id, job_rate(stepped / started.elapsed().as_secs_f64().max(1e-9), sim.timers()));
        if last_progress.elapsed() >= PROGRESS_EVERY || sim.is_finished() {
            last_progress = Instant::now();
            app.store.set_stages(id, &stage_seconds(sim.timers()))?;
            app.store.set_progress(id, sim.time(), end, sim.steps(), wall, eta)?;
            if let Some(job) = app.store.get(id)? {
                app.hub.publish(id, JobEvent::new(EventKind::Progress, None, &job.progress_event()));
            }
        }
    }
    finish(app, id, Status::Succeeded, None);
    Ok(())
}

/// Set (or clear) a running job's message and tell the listeners with a `status` event.
fn say(app: &Arc<App>, id: &str, message: Option<&str>) -> Result<()> {
    app.store.set_message(id, message)?;
    if let Some(job) = app.store.get(id)? {
        app.hub.publish(id, JobEvent::new(EventKind::Status, None, &job.status_event()));
    }
    Ok(())
}

/// A server stop: a graceful one checkpoints the state reached (the job resumes from here); a
/// crash-like one (`Server::kill`) writes nothing more.
fn stop_here(app: &Arc<App>, id: &str, sim: &Simulation) -> Result<()> {
    if app.graceful() {
        put_checkpoint(app, id, sim)?;
    }
    Ok(())
}

fn put_checkpoint(app: &App, id: &str, sim: &Simulation) -> Result<()> {
    let bytes = sim.checkpoint();
    app.store.put_checkpoint(id, &bytes)?;
    app.metrics.checkpoint_written(bytes.len() as u64);
    Ok(())
}

/// Wall seconds per stage, by name.
fn stages_of(t: &StageTimers) -> Vec<(&'static str, f64)> {
    vec![
        ("neighbours", t.neighbours),
        ("contacts_integration", t.contacts_integration),
        ("voidage", t.voidage),
        ("exchange", t.exchange),
        ("gas", t.gas),
        ("output", t.output),
    ]
}

/// The job status's `stage_seconds`.
fn stage_seconds(t: &StageTimers) -> serde_json::Value {
    serde_json::Value::Object(stages_of(t).into_iter().map(|(k, v)| (k.to_string(), v.into())).collect())
}

/// The metrics of a running job: its stepping rate and wall time per stage.
fn job_rate(steps_per_s: f64, t: &StageTimers) -> JobRate {
    JobRate { steps_per_s, stages: stages_of(t) }
}

fn fail(app: &Arc<App>, id: &str, message: &str) -> Result<()> {
    finish(app, id, Status::Failed, Some(message));
    Ok(())
}
