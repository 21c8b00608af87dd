//! The embedded backend: job records in one SQLite file (WAL) in the data directory, for a
//! single server. Leases are kept as on PostgreSQL, but a start frees them all: no other node
//! can hold one.

use super::records::{unix_now, Lease, Notice, NoticeSink, Records, SweepRecord};
use crate::job::{Job, SnapshotInfo, Status};
use anyhow::{Context, Result};
use rusqlite::{params, Connection, OptionalExtension};
use std::path::Path;
use std::sync::Mutex;

mod migrations {
    refinery::embed_migrations!("src/store/migrations/sqlite");
}

pub struct Sqlite {
    db: Mutex<Connection>,
}

/// Columns added to `jobs` before the schema had migrations, with their definitions.
const ADDED_COLUMNS: [(&str, &str); 2] =
    [("cancel_requested", "INTEGER NOT NULL DEFAULT 0"), ("attempts", "INTEGER NOT NULL DEFAULT 0")];

const JOB_COLUMNS: &str = "id, name, status, created_at, started_at, finished_at, time_s, end_time_s, steps, wall_s, eta_s, message, warnings, plan, cancel_requested, attempts, stage_seconds";

fn job_of(r: &rusqlite::Row) -> rusqlite::Result<Job> {
    let status: String = r.get(2)?;
    let warnings: String = r.get(12)?;
    let plan: Option<String> = r.get(13)?;
    Ok(Job {
        id: r.get(0)?,
        name: r.get(1)?,
        status: Status::parse(&status).unwrap_or(Status::Failed),
        created_at: r.get(3)?,
        started_at: r.get(4)?,
        finished_at: r.get(5)?,
        time_s: r.get(6)?,
        end_time_s: r.get(7)?,
        steps: r.get::<_, i64>(8)? as u64,
        wall_s: r.get(9)?,
        eta_s: r.get(10)?,
        message: r.get(11)?,
        warnings: serde_json::from_str(&warnings).unwrap_or_default(),
        plan: plan.and_then(|p| serde_json::from_str(&p).ok()),
        cancel_requested: r.get::<_, i64>(14)? != 0,
        attempts: r.get::<_, i64>(15)? as u32,
        stage_seconds: r.get::<_, Option<String>>(16)?.and_then(|t| serde_json::from_str(&t).ok()),
    })
}

fn info_of(r: &rusqlite::Row) -> rusqlite::Result<SnapshotInfo> {
    Ok(SnapshotInfo {
        n: r.get::<_, i64>(0)? as u64,
        time_s: r.get(1)?,
        step: r.get::<_, i64>(2)? as u64,
        pressure_drop_pa: r.get(3)?,
        mean_particle_height_m: r.get(4)?,
    })
}

/// Bring a database from before migrations up to migration 1 (which it then counts as applied).
fn upgrade_unversioned(db: &Connection) -> rusqlite::Result<()> {
    let has_jobs: bool =
        db.query_row("SELECT COUNT(*) > 0 FROM sqlite_master WHERE type = 'table' AND name = 'jobs'", [], |r| {
            r.get(0)
        })?;
    if !has_jobs {
        return Ok(());
    }
    for (col, def) in ADDED_COLUMNS {
        let has: bool =
            db.query_row("SELECT COUNT(*) > 0 FROM pragma_table_info('jobs') WHERE name = ?1", [col], |r| r.get(0))?;
        if !has {
            db.execute_batch(&format!("ALTER TABLE jobs ADD COLUMN {col} {def}"))?;
        }
    }
    Ok(())
}

impl Sqlite {
    /// Open (or create) `path` and migrate it; every error names the file.
    pub fn open(path: &Path) -> Result<Sqlite> {
        let open = || -> Result<Connection> {
            let mut db = Connection::open(path)?;
            db.pragma_update(None, "journal_mode", "WAL")?;
            db.pragma_update(None, "synchronous", "NORMAL")?;
            db.busy_timeout(std::time::Duration::from_secs(10))?;
            upgrade_unversioned(&db)?;
            migrations::migrations::runner().run(&mut db)?;
            // One server per file: leases of a server that stopped are void.
            db.execute("UPDATE jobs SET owner = NULL, lease_until = NULL WHERE owner IS NOT NULL", [])?;
            Ok(db)
        };
        let db = open().with_context(|| format!("cannot open the job database {}", path.display()))?;
        Ok(Sqlite { db: Mutex::new(db) })
    }

    fn db(&self) -> std::sync::MutexGuard<'_, Connection> {
        self.db.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Records for Sqlite {
    fn shared(&self) -> bool {
        false
    }

    fn insert(&self, job: &Job, case_json: &str) -> Result<()> {
        self.db().execute(
            "INSERT INTO jobs (id, name, status, case_json, created_at, end_time_s, warnings) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
            params![job.id, job.name, job.status.as_str(), case_json, job.created_at, job.end_time_s, serde_json::to_string(&job.warnings)?],
        )?;
        Ok(())
    }

    fn get(&self, id: &str) -> Result<Option<Job>> {
        let sql = format!("SELECT {JOB_COLUMNS} FROM jobs WHERE id = ?1");
        Ok(self.db().query_row(&sql, [id], job_of).optional()?)
    }

    fn case_json(&self, id: &str) -> Result<Option<String>> {
        Ok(self.db().query_row("SELECT case_json FROM jobs WHERE id = ?1", [id], |r| r.get(0)).optional()?)
    }

    fn list(&self, status: Option<Status>, limit: usize, offset: usize) -> Result<(Vec<Job>, usize)> {
        let db = self.db();
        let filter = if status.is_some() { "WHERE status = ?1" } else { "WHERE ?1 IS NULL" };
        let st = status.map(|s| s.as_str());
        let sql = format!("SELECT {JOB_COLUMNS} FROM jobs {filter} ORDER BY seq DESC LIMIT ?2 OFFSET ?3");
        let jobs = db
            .prepare(&sql)?
            .query_map(params![st, limit as i64, offset as i64], job_of)?
            .collect::<Result<Vec<_>, _>>()?;
        let total: i64 = db.query_row(&format!("SELECT COUNT(*) FROM jobs {filter}"), params![st], |r| r.get(0))?;
        Ok((jobs, total as usize))
    }

    fn count(&self, status: Status) -> Result<usize> {
        let n: i64 =
            self.db().query_row("SELECT COUNT(*) FROM jobs WHERE status = ?1", [status.as_str()], |r| r.get(0))?;
        Ok(n as usize)
    }

    fn claim(&self, node: &str, lease_s: f64) -> Result<Option<String>> {
        let now = unix_now();
        // One statement under the connection's lock: atomic within this (only) server.
        let id = self
            .db()
            .query_row(
                "UPDATE jobs SET owner = ?1, lease_until = ?2 WHERE id = (SELECT id FROM jobs \
                 WHERE status IN ('queued', 'running') AND (lease_until IS NULL OR lease_until < ?3) ORDER BY status = 'running' DESC, seq LIMIT 1) \
                 RETURNING id",
                params![node, now + lease_s, now],
                |r| r.get(0),
            )
            .optional()?;
        Ok(id)
    }

    fn renew(&self, id: &str, node: &str, lease_s: f64) -> Result<Lease> {
        let cancel: Option<i64> = self
            .db()
            .query_row(
                "UPDATE jobs SET lease_until = ?3 WHERE id = ?1 AND owner = ?2 AND status IN ('queued', 'running') \
                 RETURNING cancel_requested",
                params![id, node, unix_now() + lease_s],
                |r| r.get(0),
            )
            .optional()?;
        Ok(cancel.map_or(Lease::Lost, |c| Lease::Held { cancel_requested: c != 0 }))
    }

    fn release(&self, id: &str, node: &str, attempt: bool) -> Result<()> {
        self.db().execute(
            "UPDATE jobs SET owner = NULL, lease_until = NULL, attempts = MAX(attempts - ?3, 0) WHERE id = ?1 AND owner = ?2",
            params![id, node, i64::from(attempt)],
        )?;
        Ok(())
    }

    fn set_running(&self, id: &str, now: &str) -> Result<bool> {
        let n = self.db().execute(
            "UPDATE jobs SET status = 'running', started_at = COALESCE(started_at, ?2), attempts = attempts + 1 \
             WHERE id = ?1 AND status IN ('queued', 'running')",
            params![id, now],
        )?;
        Ok(n > 0)
    }

    fn request_cancel(&self, id: &str) -> Result<bool> {
        let n = self
            .db()
            .execute("UPDATE jobs SET cancel_requested = 1 WHERE id = ?1 AND status IN ('queued', 'running')", [id])?;
        Ok(n > 0)
    }

    fn cancel_queued(&self, id: &str, message: &str, now: &str) -> Result<bool> {
        let n = self.db().execute(
            "UPDATE jobs SET status = 'cancelled', message = ?2, finished_at = ?3, eta_s = NULL WHERE id = ?1 AND status = 'queued'",
            params![id, message, now],
        )?;
        Ok(n > 0)
    }

    fn set_message(&self, id: &str, message: Option<&str>) -> Result<()> {
        self.db().execute("UPDATE jobs SET message = ?2 WHERE id = ?1 AND status = 'running'", params![id, message])?;
        Ok(())
    }

    fn set_plan(&self, id: &str, plan: &serde_json::Value) -> Result<()> {
        self.db().execute("UPDATE jobs SET plan = ?2 WHERE id = ?1", params![id, plan.to_string()])?;
        Ok(())
    }

    fn set_stages(&self, id: &str, stages: &serde_json::Value) -> Result<()> {
        self.db().execute("UPDATE jobs SET stage_seconds = ?2 WHERE id = ?1", params![id, stages.to_string()])?;
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
        self.db().execute(
            "UPDATE jobs SET time_s = ?2, end_time_s = ?3, steps = ?4, wall_s = ?5, eta_s = ?6 WHERE id = ?1",
            params![id, time_s, end_time_s, steps as i64, wall_s, eta_s],
        )?;
        Ok(())
    }

    fn finish(&self, id: &str, status: Status, message: Option<&str>, now: &str, owner: Option<&str>) -> Result<bool> {
        let n = self.db().execute(
            "UPDATE jobs SET status = ?2, message = ?3, finished_at = ?4, eta_s = NULL, owner = NULL, lease_until = NULL \
             WHERE id = ?1 AND status IN ('queued', 'running') AND (?5 IS NULL OR owner = ?5)",
            params![id, status.as_str(), message, now, owner],
        )?;
        Ok(n > 0)
    }

    fn put_snapshot_info(&self, id: &str, info: &SnapshotInfo) -> Result<()> {
        self.db().execute(
            "INSERT OR REPLACE INTO snapshots (job_id, n, time_s, step, pressure_drop_pa, mean_particle_height_m) VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
            params![id, info.n as i64, info.time_s, info.step as i64, info.pressure_drop_pa, info.mean_particle_height_m],
        )?;
        Ok(())
    }

    fn snapshots(&self, id: &str) -> Result<Vec<SnapshotInfo>> {
        let db = self.db();
        let rows = db
            .prepare("SELECT n, time_s, step, pressure_drop_pa, mean_particle_height_m FROM snapshots WHERE job_id = ?1 ORDER BY n")?
            .query_map([id], info_of)?
            .collect::<Result<Vec<_>, _>>()?;
        Ok(rows)
    }

    fn snapshot_info(&self, id: &str, n: u64) -> Result<Option<SnapshotInfo>> {
        Ok(self
            .db()
            .query_row(
                "SELECT n, time_s, step, pressure_drop_pa, mean_particle_height_m FROM snapshots WHERE job_id = ?1 AND n = ?2",
                params![id, n as i64],
                info_of,
            )
            .optional()?)
    }

    fn insert_sweep(&self, sweep: &SweepRecord, jobs: &[(Job, String)]) -> Result<()> {
        let mut db = self.db();
        let tx = db.transaction()?;
        for (job, case_json) in jobs {
            tx.execute(
                "INSERT INTO jobs (id, name, status, case_json, created_at, end_time_s, warnings) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
                params![job.id, job.name, job.status.as_str(), case_json, job.created_at, job.end_time_s, serde_json::to_string(&job.warnings)?],
            )?;
        }
        tx.execute(
            "INSERT INTO sweeps (id, name, created_at, points) VALUES (?1, ?2, ?3, ?4)",
            params![sweep.id, sweep.name, sweep.created_at, sweep.points_json()],
        )?;
        tx.commit()?;
        Ok(())
    }

    fn sweep(&self, id: &str) -> Result<Option<SweepRecord>> {
        let row = self
            .db()
            .query_row("SELECT id, name, created_at, points FROM sweeps WHERE id = ?1", [id], |r| {
                Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get::<_, String>(3)?))
            })
            .optional()?;
        row.map(|(id, name, at, pts)| SweepRecord::from_columns(id, name, at, &pts)).transpose()
    }

    fn sweeps(&self, limit: usize, offset: usize) -> Result<(Vec<SweepRecord>, usize)> {
        let db = self.db();
        let rows = db
            .prepare("SELECT id, name, created_at, points FROM sweeps ORDER BY seq DESC LIMIT ?1 OFFSET ?2")?
            .query_map(params![limit as i64, offset as i64], |r| {
                Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get::<_, String>(3)?))
            })?
            .collect::<Result<Vec<(String, String, String, String)>, _>>()?;
        let total: i64 = db.query_row("SELECT COUNT(*) FROM sweeps", [], |r| r.get(0))?;
        let sweeps = rows
            .into_iter()
            .map(|(id, name, at, pts)| SweepRecord::from_columns(id, name, at, &pts))
            .collect::<Result<_>>()?;
        Ok((sweeps, total as usize))
    }

    fn notify(&self, _notice: Notice) {}

    fn listen(&self, _sink: NoticeSink) -> Result<()> {
        Ok(())
    }

    /// Fold the WAL into the database and close it.
    fn close(&self) -> Result<()> {
        let mut db = self.db();
        db.execute_batch("PRAGMA wal_checkpoint(TRUNCATE);")?;
        let real = std::mem::replace(&mut *db, Connection::open_in_memory()?);
        real.close().map_err(|(_, e)| e)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::job::now_rfc3339;

    fn job(id: &str) -> Job {
        Job {
            id: id.into(),
            name: id.into(),
            status: Status::Queued,
            created_at: now_rfc3339(),
            started_at: None,
            finished_at: None,
            time_s: 0.0,
            end_time_s: 1.0,
            steps: 0,
            wall_s: 0.0,
            eta_s: None,
            message: None,
            warnings: vec![],
            plan: None,
            stage_seconds: None,
            cancel_requested: false,
            attempts: 0,
        }
    }

    fn records(tag: &str) -> (Sqlite, std::path::PathBuf) {
        let dir = std::env::temp_dir().join(format!("fluidbed-sqlite-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        (Sqlite::open(&dir.join("fluidbed.sqlite")).unwrap(), dir)
    }

    #[test]
    fn a_live_lease_keeps_a_job_and_an_expired_one_hands_it_over() {
        let (r, dir) = records("lease");
        r.insert(&job("one"), "{}").unwrap();
        assert_eq!(r.claim("a", 60.0).unwrap().as_deref(), Some("one"));
        assert!(r.set_running("one", &now_rfc3339()).unwrap());
        assert_eq!(r.claim("b", 60.0).unwrap(), None, "held by a");
        assert_eq!(r.renew("one", "a", -1.0).unwrap(), Lease::Held { cancel_requested: false });
        // a's lease has now run out: b takes the job, a loses it and cannot end it.
        assert_eq!(r.claim("b", 60.0).unwrap().as_deref(), Some("one"));
        assert_eq!(r.renew("one", "a", 60.0).unwrap(), Lease::Lost);
        assert!(!r.finish("one", Status::Succeeded, None, &now_rfc3339(), Some("a")).unwrap());
        assert!(r.request_cancel("one").unwrap());
        assert_eq!(r.renew("one", "b", 60.0).unwrap(), Lease::Held { cancel_requested: true });
        assert!(r.finish("one", Status::Cancelled, None, &now_rfc3339(), Some("b")).unwrap());
        assert_eq!(r.renew("one", "b", 60.0).unwrap(), Lease::Lost, "a final job has no lease");
        assert_eq!(r.claim("c", 60.0).unwrap(), None);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn a_running_job_is_claimed_before_older_queued_ones_and_reopening_frees_leases() {
        let (r, dir) = records("order");
        for id in ["old", "new"] {
            r.insert(&job(id), "{}").unwrap();
        }
        assert_eq!(r.claim("a", 60.0).unwrap().as_deref(), Some("old"));
        r.release("old", "a", false).unwrap();
        assert_eq!(r.claim("a", 60.0).unwrap().as_deref(), Some("old"), "released: free again");
        assert_eq!(r.claim("a", 60.0).unwrap().as_deref(), Some("new"));
        assert!(r.set_running("new", &now_rfc3339()).unwrap());
        drop(r);
        let r = Sqlite::open(&dir.join("fluidbed.sqlite")).unwrap();
        assert_eq!(r.claim("b", 60.0).unwrap().as_deref(), Some("new"), "the running job resumes first");
        assert_eq!(r.claim("b", 60.0).unwrap().as_deref(), Some("old"));
        assert!(r.cancel_queued("old", "cancelled before it started", &now_rfc3339()).unwrap());
        assert!(!r.set_running("old", &now_rfc3339()).unwrap(), "a cancelled job does not start");
        let _ = std::fs::remove_dir_all(dir);
    }
}
