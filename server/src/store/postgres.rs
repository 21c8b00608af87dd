//! The shared backend: job records in PostgreSQL, one queue for every node that opens the same
//! database. A claim is `SELECT … FOR UPDATE SKIP LOCKED` (no two nodes take one job), a lease's
//! clock is the database's, and notices cross nodes by `NOTIFY fluidbed_events` / `LISTEN`.
//!
//! The calls are synchronous like SQLite's: each runs as a task on this backend's own runtime and
//! the caller waits for its answer, so the code above needs no async and no knowledge of it.

use super::records::{Lease, Notice, NoticeSink, Records, SweepRecord};
use crate::job::{Job, SnapshotInfo, Status};
use anyhow::{anyhow, Context, Result};
use deadpool_postgres::{Manager, ManagerConfig, Pool, RecyclingMethod};
use futures_util::StreamExt;
use std::future::Future;
use std::time::Duration;
use tokio::sync::mpsc;
use tokio_postgres::types::ToSql;
use tokio_postgres::{AsyncMessage, NoTls, Row};

mod migrations {
    refinery::embed_migrations!("src/store/migrations/postgres");
}

/// The channel of job notices.
const CHANNEL: &str = "fluidbed_events";
/// Serialises migrations of nodes starting together (`pg_advisory_lock` key).
const MIGRATION_LOCK: i64 = 0x666c_7569_6462;
/// Longest wait for one call (a pool connection included).
const CALL_TIMEOUT: Duration = Duration::from_secs(30);

/// The database's clock as Unix seconds.
const NOW: &str = "EXTRACT(EPOCH FROM clock_timestamp())::float8";

const JOB_COLUMNS: &str = "id, name, status, created_at, started_at, finished_at, time_s, end_time_s, steps, wall_s, eta_s, message, warnings, plan, cancel_requested, attempts, stage_seconds";
const INFO_COLUMNS: &str = "n, time_s, step, pressure_drop_pa, mean_particle_height_m";

/// The parameters of one statement, owned (they travel to the runtime's task).
type Params = Vec<Box<dyn ToSql + Send + Sync>>;

pub struct Postgres {
    rt: Option<tokio::runtime::Runtime>,
    config: tokio_postgres::Config,
    pool: Pool,
    /// Notices to send, in order, by one task on one connection.
    outbox: mpsc::UnboundedSender<String>,
}

fn job_of(r: &Row) -> Result<Job> {
    let status: String = r.try_get(2)?;
    let warnings: String = r.try_get(12)?;
    let plan: Option<String> = r.try_get(13)?;
    Ok(Job {
        id: r.try_get(0)?,
        name: r.try_get(1)?,
        status: Status::parse(&status).unwrap_or(Status::Failed),
        created_at: r.try_get(3)?,
        started_at: r.try_get(4)?,
        finished_at: r.try_get(5)?,
        time_s: r.try_get(6)?,
        end_time_s: r.try_get(7)?,
        steps: r.try_get::<_, i64>(8)? as u64,
        wall_s: r.try_get(9)?,
        eta_s: r.try_get(10)?,
        message: r.try_get(11)?,
        warnings: serde_json::from_str(&warnings).unwrap_or_default(),
        plan: plan.and_then(|p| serde_json::from_str(&p).ok()),
        cancel_requested: r.try_get(14)?,
        attempts: r.try_get::<_, i32>(15)?.max(0) as u32,
        stage_seconds: r.try_get::<_, Option<String>>(16)?.and_then(|t| serde_json::from_str(&t).ok()),
    })
}

fn info_of(r: &Row) -> Result<SnapshotInfo> {
    Ok(SnapshotInfo {
        n: r.try_get::<_, i64>(0)? as u64,
        time_s: r.try_get(1)?,
        step: r.try_get::<_, i64>(2)? as u64,
        pressure_drop_pa: r.try_get(3)?,
        mean_particle_height_m: r.try_get(4)?,
    })
}

fn sweep_of(r: &Row) -> Result<SweepRecord> {
    let points: String = r.try_get(3)?;
    SweepRecord::from_columns(r.try_get(0)?, r.try_get(1)?, r.try_get(2)?, &points)
}

/// The URL without its password, for messages.
fn redact(url: &str) -> String {
    match (url.find("://"), url.rfind('@')) {
        (Some(s), Some(at)) if at > s => {
            let user = &url[s + 3..at];
            let user = user.split(':').next().unwrap_or("");
            format!("{}{}@{}", &url[..s + 3], user, &url[at + 1..])
        }
        _ => url.to_string(),
    }
}

/// Run `f` on `rt` and wait for it, from any thread (an async one included: the wait is as
/// short as the query, like a SQLite call).
fn run_on<T: Send + 'static>(
    rt: &tokio::runtime::Runtime,
    f: impl Future<Output = Result<T>> + Send + 'static,
) -> Result<T> {
    let (tx, rx) = std::sync::mpsc::sync_channel(1);
    rt.spawn(async move {
        let out = match tokio::time::timeout(CALL_TIMEOUT, f).await {
            Ok(out) => out,
            Err(_) => Err(anyhow!("the job database did not answer within {} s", CALL_TIMEOUT.as_secs())),
        };
        let _ = tx.send(out);
    });
    rx.recv().map_err(|_| anyhow!("the job database's task stopped"))?
}

async fn migrate(config: tokio_postgres::Config) -> Result<()> {
    let (mut client, conn) = config.connect(NoTls).await?;
    tokio::spawn(conn);
    client.execute("SELECT pg_advisory_lock($1)", &[&MIGRATION_LOCK]).await?;
    let out = migrations::migrations::runner().run_async(&mut client).await;
    client.execute("SELECT pg_advisory_unlock($1)", &[&MIGRATION_LOCK]).await?;
    out?;
    Ok(())
}

/// Send queued notices one by one, in order (a notice that cannot be sent is logged and dropped:
/// listeners catch up from the store on their next event).
async fn send_notices(pool: Pool, mut outbox: mpsc::UnboundedReceiver<String>) {
    let mut client = None;
    while let Some(payload) = outbox.recv().await {
        if client.is_none() {
            client = pool.get().await.map_err(|e| tracing::warn!("cannot send a job notice: {e}")).ok();
        }
        if let Some(c) = &client {
            if let Err(e) = c.execute("SELECT pg_notify($1, $2)", &[&CHANNEL, &payload]).await {
                tracing::warn!("cannot send a job notice: {e}");
                client = None;
            }
        }
    }
}

/// Follow the channel on a connection of its own, reconnecting after a loss.
async fn receive_notices(config: tokio_postgres::Config, sink: NoticeSink) {
    loop {
        match config.connect(NoTls).await {
            Ok((client, mut conn)) => {
                let (tx, mut rx) = mpsc::unbounded_channel::<String>();
                tokio::spawn(async move {
                    let mut messages = Box::pin(futures_util::stream::poll_fn(move |cx| conn.poll_message(cx)));
                    while let Some(m) = messages.next().await {
                        match m {
                            Ok(AsyncMessage::Notification(n)) => {
                                let _ = tx.send(n.payload().to_string());
                            }
                            Ok(_) => {}
                            Err(e) => {
                                tracing::warn!("the job notice connection failed: {e}");
                                break;
                            }
                        }
                    }
                });
                match client.batch_execute(&format!("LISTEN {CHANNEL}")).await {
                    Ok(()) => {
                        while let Some(payload) = rx.recv().await {
                            if let Some(notice) = Notice::from_payload(&payload) {
                                sink(notice);
                            }
                        }
                    }
                    Err(e) => tracing::warn!("cannot LISTEN for job notices: {e}"),
                }
            }
            Err(e) => tracing::warn!("cannot connect for job notices: {e}"),
        }
        tokio::time::sleep(Duration::from_secs(1)).await;
    }
}

impl Postgres {
    /// Connect, migrate (one node at a time) and start the notice sender.
    pub fn open(url: &str) -> Result<Postgres> {
        let shown = redact(url);
        let config: tokio_postgres::Config =
            url.parse().with_context(|| format!("--database {shown} is not a PostgreSQL URL"))?;
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .thread_name("fluidbed-pg")
            .enable_all()
            .build()?;
        run_on(&rt, migrate(config.clone())).with_context(|| format!("cannot open the job database {shown}"))?;
        let manager =
            Manager::from_config(config.clone(), NoTls, ManagerConfig { recycling_method: RecyclingMethod::Fast });
        let pool = Pool::builder(manager).max_size(8).build().context("the job database's pool")?;
        let (outbox, queued) = mpsc::unbounded_channel();
        rt.spawn(send_notices(pool.clone(), queued));
        Ok(Postgres { rt: Some(rt), config, pool, outbox })
    }

    fn run<T: Send + 'static>(&self, f: impl Future<Output = Result<T>> + Send + 'static) -> Result<T> {
        let rt = self.rt.as_ref().ok_or_else(|| anyhow!("the job database is closed"))?;
        run_on(rt, f)
    }

    /// Run one statement; the rows changed.
    fn execute(&self, sql: &'static str, params: Params) -> Result<u64> {
        let pool = self.pool.clone();
        self.run(async move {
            let c = pool.get().await?;
            let refs: Vec<&(dyn ToSql + Sync)> = params.iter().map(|p| &**p as &(dyn ToSql + Sync)).collect();
            Ok(c.execute(sql, &refs).await?)
        })
    }

    /// Run one query; its rows.
    fn query(&self, sql: String, params: Params) -> Result<Vec<Row>> {
        let pool = self.pool.clone();
        self.run(async move {
            let c = pool.get().await?;
            let refs: Vec<&(dyn ToSql + Sync)> = params.iter().map(|p| &**p as &(dyn ToSql + Sync)).collect();
            Ok(c.query(&sql, &refs).await?)
        })
    }
}

macro_rules! params {
    ($($p:expr),* $(,)?) => {
        vec![$(Box::new($p) as Box<dyn ToSql + Send + Sync>),*]
    };
}

fn s(v: &str) -> String {
    v.to_string()
}
fn opt(v: Option<&str>) -> Option<String> {
    v.map(str::to_string)
}

impl Records for Postgres {
    fn shared(&self) -> bool {
        true
    }

    fn insert(&self, job: &Job, case_json: &str) -> Result<()> {
        self.execute(
            "INSERT INTO jobs (id, name, status, case_json, created_at, end_time_s, warnings) VALUES ($1, $2, $3, $4, $5, $6, $7)",
            params![s(&job.id), s(&job.name), s(job.status.as_str()), s(case_json), s(&job.created_at), job.end_time_s,
                serde_json::to_string(&job.warnings)?],
        )?;
        Ok(())
    }

    fn get(&self, id: &str) -> Result<Option<Job>> {
        let rows = self.query(format!("SELECT {JOB_COLUMNS} FROM jobs WHERE id = $1"), params![s(id)])?;
        rows.first().map(job_of).transpose()
    }

    fn case_json(&self, id: &str) -> Result<Option<String>> {
        let rows = self.query("SELECT case_json FROM jobs WHERE id = $1".into(), params![s(id)])?;
        Ok(rows.first().map(|r| r.try_get(0)).transpose()?)
    }

    fn list(&self, status: Option<Status>, limit: usize, offset: usize) -> Result<(Vec<Job>, usize)> {
        let st = status.map(|s| s.as_str().to_string());
        let filter = "WHERE ($1::text IS NULL OR status = $1)";
        let rows = self.query(
            format!("SELECT {JOB_COLUMNS} FROM jobs {filter} ORDER BY seq DESC LIMIT $2 OFFSET $3"),
            params![st.clone(), limit as i64, offset as i64],
        )?;
        let jobs = rows.iter().map(job_of).collect::<Result<Vec<_>>>()?;
        let total = self.query(format!("SELECT COUNT(*) FROM jobs {filter}"), params![st])?;
        let total: i64 = total.first().map(|r| r.try_get(0)).transpose()?.unwrap_or(0);
        Ok((jobs, total as usize))
    }

    fn count(&self, status: Status) -> Result<usize> {
        let rows = self.query("SELECT COUNT(*) FROM jobs WHERE status = $1".into(), params![s(status.as_str())])?;
        let n: i64 = rows.first().map(|r| r.try_get(0)).transpose()?.unwrap_or(0);
        Ok(n as usize)
    }

    fn claim(&self, node: &str, lease_s: f64) -> Result<Option<String>> {
        let rows = self.query(
            format!(
                "UPDATE jobs SET owner = $1, lease_until = {NOW} + $2 WHERE id = (SELECT id FROM jobs \
                 WHERE status IN ('queued', 'running') AND (lease_until IS NULL OR lease_until < {NOW}) \
                 ORDER BY status = 'running' DESC, seq LIMIT 1 FOR UPDATE SKIP LOCKED) RETURNING id"
            ),
            params![s(node), lease_s],
        )?;
        Ok(rows.first().map(|r| r.try_get(0)).transpose()?)
    }

    fn renew(&self, id: &str, node: &str, lease_s: f64) -> Result<Lease> {
        let rows = self.query(
            format!(
                "UPDATE jobs SET lease_until = {NOW} + $3 WHERE id = $1 AND owner = $2 \
                 AND status IN ('queued', 'running') RETURNING cancel_requested"
            ),
            params![s(id), s(node), lease_s],
        )?;
        Ok(match rows.first() {
            Some(r) => Lease::Held { cancel_requested: r.try_get(0)? },
            None => Lease::Lost,
        })
    }

    fn release(&self, id: &str, node: &str, attempt: bool) -> Result<()> {
        self.execute(
            "UPDATE jobs SET owner = NULL, lease_until = NULL, attempts = GREATEST(attempts - $3, 0) WHERE id = $1 AND owner = $2",
            params![s(id), s(node), i32::from(attempt)],
        )?;
        Ok(())
    }

    fn set_running(&self, id: &str, now: &str) -> Result<bool> {
        let n = self.execute(
            "UPDATE jobs SET status = 'running', started_at = COALESCE(started_at, $2), attempts = attempts + 1 \
             WHERE id = $1 AND status IN ('queued', 'running')",
            params![s(id), s(now)],
        )?;
        Ok(n > 0)
    }

    fn request_cancel(&self, id: &str) -> Result<bool> {
        let n = self.execute(
            "UPDATE jobs SET cancel_requested = TRUE WHERE id = $1 AND status IN ('queued', 'running')",
            params![s(id)],
        )?;
        Ok(n > 0)
    }

    fn cancel_queued(&self, id: &str, message: &str, now: &str) -> Result<bool> {
        let n = self.execute(
            "UPDATE jobs SET status = 'cancelled', message = $2, finished_at = $3, eta_s = NULL WHERE id = $1 AND status = 'queued'",
            params![s(id), s(message), s(now)],
        )?;
        Ok(n > 0)
    }

    fn set_message(&self, id: &str, message: Option<&str>) -> Result<()> {
        self.execute(
            "UPDATE jobs SET message = $2 WHERE id = $1 AND status = 'running'",
            params![s(id), opt(message)],
        )?;
        Ok(())
    }

    fn set_plan(&self, id: &str, plan: &serde_json::Value) -> Result<()> {
        self.execute("UPDATE jobs SET plan = $2 WHERE id = $1", params![s(id), plan.to_string()])?;
        Ok(())
    }

    fn set_stages(&self, id: &str, stages: &serde_json::Value) -> Result<()> {
        self.execute("UPDATE jobs SET stage_seconds = $2 WHERE id = $1", params![s(id), stages.to_string()])?;
        Ok(())
    }

    fn set_progress(
        &self,
        id: &str,
        time_s: f64,
        end_time_s: f64,
        steps: u64,
        wall_s: f64,
        eta_s: Option<f64>,
    ) -> Result<()> {
        self.execute(
            "UPDATE jobs SET time_s = $2, end_time_s = $3, steps = $4, wall_s = $5, eta_s = $6 WHERE id = $1",
            params![s(id), time_s, end_time_s, steps as i64, wall_s, eta_s],
        )?;
        Ok(())
    }

    fn finish(&self, id: &str, status: Status, message: Option<&str>, now: &str, owner: Option<&str>) -> Result<bool> {
        let n = self.execute(
            "UPDATE jobs SET status = $2, message = $3, finished_at = $4, eta_s = NULL, owner = NULL, lease_until = NULL \
             WHERE id = $1 AND status IN ('queued', 'running') AND ($5::text IS NULL OR owner = $5)",
            params![s(id), s(status.as_str()), opt(message), s(now), opt(owner)],
        )?;
        Ok(n > 0)
    }

    fn put_snapshot_info(&self, id: &str, info: &SnapshotInfo) -> Result<()> {
        self.execute(
            "INSERT INTO snapshots (job_id, n, time_s, step, pressure_drop_pa, mean_particle_height_m) VALUES ($1, $2, $3, $4, $5, $6) \
             ON CONFLICT (job_id, n) DO UPDATE SET time_s = EXCLUDED.time_s, step = EXCLUDED.step, \
             pressure_drop_pa = EXCLUDED.pressure_drop_pa, mean_particle_height_m = EXCLUDED.mean_particle_height_m",
            params![s(id), info.n as i64, info.time_s, info.step as i64, info.pressure_drop_pa, info.mean_particle_height_m],
        )?;
        Ok(())
    }

    fn snapshots(&self, id: &str) -> Result<Vec<SnapshotInfo>> {
        let rows =
            self.query(format!("SELECT {INFO_COLUMNS} FROM snapshots WHERE job_id = $1 ORDER BY n"), params![s(id)])?;
        rows.iter().map(info_of).collect()
    }

    fn snapshot_info(&self, id: &str, n: u64) -> Result<Option<SnapshotInfo>> {
        let rows = self.query(
            format!("SELECT {INFO_COLUMNS} FROM snapshots WHERE job_id = $1 AND n = $2"),
            params![s(id), n as i64],
        )?;
        rows.first().map(info_of).transpose()
    }

    fn insert_sweep(&self, sweep: &SweepRecord, jobs: &[(Job, String)]) -> Result<()> {
        let pool = self.pool.clone();
        let jobs: Vec<([String; 6], f64)> = jobs
            .iter()
            .map(|(j, case)| -> Result<([String; 6], f64)> {
                let text = [
                    j.id.clone(),
                    j.name.clone(),
                    s(j.status.as_str()),
                    case.clone(),
                    j.created_at.clone(),
                    serde_json::to_string(&j.warnings)?,
                ];
                Ok((text, j.end_time_s))
            })
            .collect::<Result<_>>()?;
        let row = [sweep.id.clone(), sweep.name.clone(), sweep.created_at.clone(), sweep.points_json()];
        self.run(async move {
            let mut c = pool.get().await?;
            let tx = c.transaction().await?;
            for (j, end_time_s) in &jobs {
                tx.execute(
                    "INSERT INTO jobs (id, name, status, case_json, created_at, end_time_s, warnings) VALUES ($1, $2, $3, $4, $5, $6, $7)",
                    &[&j[0], &j[1], &j[2], &j[3], &j[4], end_time_s, &j[5]],
                )
                .await?;
            }
            tx.execute(
                "INSERT INTO sweeps (id, name, created_at, points) VALUES ($1, $2, $3, $4)",
                &[&row[0], &row[1], &row[2], &row[3]],
            )
            .await?;
            tx.commit().await?;
            Ok(())
        })
    }

    fn sweep(&self, id: &str) -> Result<Option<SweepRecord>> {
        let rows =
            self.query("SELECT id, name, created_at, points FROM sweeps WHERE id = $1".into(), params![s(id)])?;
        rows.first().map(sweep_of).transpose()
    }

    fn sweeps(&self, limit: usize, offset: usize) -> Result<(Vec<SweepRecord>, usize)> {
        let rows = self.query(
            "SELECT id, name, created_at, points FROM sweeps ORDER BY seq DESC LIMIT $1 OFFSET $2".into(),
            params![limit as i64, offset as i64],
        )?;
        let sweeps = rows.iter().map(sweep_of).collect::<Result<Vec<_>>>()?;
        let total = self.query("SELECT COUNT(*) FROM sweeps".into(), params![])?;
        let total: i64 = total.first().map(|r| r.try_get(0)).transpose()?.unwrap_or(0);
        Ok((sweeps, total as usize))
    }

    fn notify(&self, notice: Notice) {
        let _ = self.outbox.send(notice.to_payload());
    }

    fn listen(&self, sink: NoticeSink) -> Result<()> {
        let rt = self.rt.as_ref().ok_or_else(|| anyhow!("the job database is closed"))?;
        rt.spawn(receive_notices(self.config.clone(), sink));
        Ok(())
    }

    fn close(&self) -> Result<()> {
        self.pool.close();
        Ok(())
    }
}

impl Drop for Postgres {
    fn drop(&mut self) {
        // Allowed from any thread, an async one included (a plain drop is not).
        if let Some(rt) = self.rt.take() {
            rt.shutdown_background();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn redact_drops_the_password_only() {
        assert_eq!(redact("postgres://u:secret@h:5432/db"), "postgres://u@h:5432/db");
        assert_eq!(redact("postgres://u@h/db"), "postgres://u@h/db");
        assert_eq!(redact("postgres://h/db"), "postgres://h/db");
    }
}
