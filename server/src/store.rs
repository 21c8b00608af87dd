//! The job store: job records in an embedded SQLite database (WAL) in the data directory, and
//! snapshots and checkpoints as files beside it, each written atomically (temporary file, fsync,
//! rename). Layout:
//!
//! ```text
//! DIR/fluidbed.sqlite            jobs and the snapshot index
//! DIR/jobs/<id>/snapshots/<n>.bin  snapshot n (bincode of core's Snapshot, raw f64)
//! DIR/jobs/<id>/checkpoint.bin   the complete simulation state after the last checkpoint
//! DIR/cache/                     settled beds shared between jobs (core's bed cache)
//! DIR/reserve.bin                space set aside so that a full disk can still record a failure
//! ```
//! A job's folder is created by the worker that runs it, so a rejected request writes nothing.

use crate::job::{Job, SnapshotInfo, Status};
use anyhow::{Context, Result};
use fluidbed_core::sim::snapshot::Snapshot;
use rusqlite::{params, Connection, OptionalExtension};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

pub struct Store {
    dir: PathBuf,
    db: Mutex<Connection>,
}

const SCHEMA: &str = "
CREATE TABLE IF NOT EXISTS jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT UNIQUE NOT NULL,
  name TEXT NOT NULL,
  status TEXT NOT NULL,
  case_json TEXT NOT NULL,
  created_at TEXT NOT NULL,
  started_at TEXT,
  finished_at TEXT,
  time_s REAL NOT NULL DEFAULT 0,
  end_time_s REAL NOT NULL,
  steps INTEGER NOT NULL DEFAULT 0,
  wall_s REAL NOT NULL DEFAULT 0,
  eta_s REAL,
  message TEXT,
  warnings TEXT NOT NULL,
  plan TEXT,
  cancel_requested INTEGER NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS jobs_status ON jobs(status);
CREATE TABLE IF NOT EXISTS snapshots (
  job_id TEXT NOT NULL,
  n INTEGER NOT NULL,
  time_s REAL NOT NULL,
  step INTEGER NOT NULL,
  pressure_drop_pa REAL,
  mean_particle_height_m REAL,
  PRIMARY KEY (job_id, n)
);";

/// Columns added after the first release, with their definitions (added to older databases).
const ADDED_COLUMNS: [(&str, &str); 2] =
    [("cancel_requested", "INTEGER NOT NULL DEFAULT 0"), ("attempts", "INTEGER NOT NULL DEFAULT 0")];

/// Bytes kept in DIR/reserve.bin: freed when a write fails, so that SQLite can still mark the job.
const RESERVE_BYTES: usize = 256 << 10;

const JOB_COLUMNS: &str = "id, name, status, created_at, started_at, finished_at, time_s, end_time_s, steps, wall_s, eta_s, message, warnings, plan, cancel_requested, attempts";

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
    })
}

impl Store {
    /// Open (or create) the store; every error names the path it is about.
    pub fn open(dir: &Path) -> Result<Store> {
        let jobs = dir.join("jobs");
        std::fs::create_dir_all(&jobs)
            .with_context(|| format!("cannot create the data directory {}", jobs.display()))?;
        let probe = dir.join(".write-probe");
        std::fs::write(&probe, b"fluidbed")
            .and_then(|_| std::fs::remove_file(&probe))
            .with_context(|| format!("the data directory {} is not writable", dir.display()))?;
        let path = dir.join("fluidbed.sqlite");
        let open = || -> rusqlite::Result<Connection> {
            let db = Connection::open(&path)?;
            db.pragma_update(None, "journal_mode", "WAL")?;
            db.pragma_update(None, "synchronous", "NORMAL")?;
            db.busy_timeout(std::time::Duration::from_secs(10))?;
            db.execute_batch(SCHEMA)?;
            for (col, def) in ADDED_COLUMNS {
                let has: bool =
                    db.query_row("SELECT COUNT(*) > 0 FROM pragma_table_info('jobs') WHERE name = ?1", [col], |r| {
                        r.get(0)
                    })?;
                if !has {
                    db.execute_batch(&format!("ALTER TABLE jobs ADD COLUMN {col} {def}"))?;
                }
            }
            Ok(db)
        };
        let db = open().with_context(|| format!("cannot open the job database {}", path.display()))?;
        let store = Store { dir: dir.to_path_buf(), db: Mutex::new(db) };
        store.restore_reserve();
        Ok(store)
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn reserve_path(&self) -> PathBuf {
        self.dir.join("reserve.bin")
    }
    /// Set the reserve aside again (best effort: on a full disk it stays released).
    pub fn restore_reserve(&self) {
        let p = self.reserve_path();
        if std::fs::metadata(&p).map(|m| m.len() as usize).ok() != Some(RESERVE_BYTES)
            && write_atomic(&p, &vec![0u8; RESERVE_BYTES]).is_err()
        {
            let _ = std::fs::remove_file(&p);
        }
    }
    /// Free the reserve (after a failed write), so that the failure itself can be recorded.
    pub fn release_reserve(&self) {
        let _ = std::fs::remove_file(self.reserve_path());
    }
    pub fn reserve_held(&self) -> bool {
        std::fs::metadata(self.reserve_path()).is_ok_and(|m| m.len() as usize == RESERVE_BYTES)
    }

    /// Fold the WAL into the database and close it (the last call on a store).
    pub fn close(&self) -> Result<()> {
        let mut db = self.db();
        db.execute_batch("PRAGMA wal_checkpoint(TRUNCATE);")?;
        let real = std::mem::replace(&mut *db, Connection::open_in_memory()?);
        real.close().map_err(|(_, e)| e)?;
        Ok(())
    }

    fn db(&self) -> std::sync::MutexGuard<'_, Connection> {
        self.db.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub fn cache_dir(&self) -> PathBuf {
        self.dir.join("cache")
    }
    fn job_dir(&self, id: &str) -> PathBuf {
        self.dir.join("jobs").join(id)
    }
    fn snapshot_path(&self, id: &str, n: u64) -> PathBuf {
        self.job_dir(id).join("snapshots").join(format!("{n:06}.bin"))
    }
    fn checkpoint_path(&self, id: &str) -> PathBuf {
        self.job_dir(id).join("checkpoint.bin")
    }

    pub fn insert(&self, job: &Job, case_json: &str) -> Result<()> {
        self.db().execute(
            "INSERT INTO jobs (id, name, status, case_json, created_at, end_time_s, warnings) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
            params![job.id, job.name, job.status.as_str(), case_json, job.created_at, job.end_time_s, serde_json::to_string(&job.warnings)?],
        )?;
        Ok(())
    }

    pub fn get(&self, id: &str) -> Result<Option<Job>> {
        let db = self.db();
        let sql = format!("SELECT {JOB_COLUMNS} FROM jobs WHERE id = ?1");
        Ok(db.query_row(&sql, [id], job_of).optional()?)
    }

    pub fn case_json(&self, id: &str) -> Result<Option<String>> {
        Ok(self.db().query_row("SELECT case_json FROM jobs WHERE id = ?1", [id], |r| r.get(0)).optional()?)
    }

    /// Newest first; optionally only one status. Returns (page, total matching).
    pub fn list(&self, status: Option<Status>, limit: usize, offset: usize) -> Result<(Vec<Job>, usize)> {
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

    pub fn count(&self, status: Status) -> Result<usize> {
        let n: i64 =
            self.db().query_row("SELECT COUNT(*) FROM jobs WHERE status = ?1", [status.as_str()], |r| r.get(0))?;
        Ok(n as usize)
    }

    /// Ids with this status, oldest first.
    pub fn ids_with(&self, status: Status) -> Result<Vec<String>> {
        let db = self.db();
        let ids = db
            .prepare("SELECT id FROM jobs WHERE status = ?1 ORDER BY seq")?
            .query_map([status.as_str()], |r| r.get(0))?
            .collect::<Result<Vec<String>, _>>()?;
        Ok(ids)
    }

    /// Mark running and count the attempt (a server stop gives it back with `release_attempt`;
    /// a crash does not, so the count tells how often this job took a server down).
    pub fn set_running(&self, id: &str, now: &str) -> Result<()> {
        self.db().execute(
            "UPDATE jobs SET status = 'running', started_at = COALESCE(started_at, ?2), attempts = attempts + 1 WHERE id = ?1",
            params![id, now],
        )?;
        Ok(())
    }

    /// A clean stop: this attempt did not crash the server.
    pub fn release_attempt(&self, id: &str) -> Result<()> {
        self.db().execute("UPDATE jobs SET attempts = MAX(attempts - 1, 0) WHERE id = ?1", [id])?;
        Ok(())
    }

    /// Record a cancel request (it survives a restart); false if the job is already final.
    pub fn request_cancel(&self, id: &str) -> Result<bool> {
        let n = self
            .db()
            .execute("UPDATE jobs SET cancel_requested = 1 WHERE id = ?1 AND status IN ('queued', 'running')", [id])?;
        Ok(n > 0)
    }

    /// What a running job is doing when that is not stepping (e.g. preparing its bed); None clears it.
    pub fn set_message(&self, id: &str, message: Option<&str>) -> Result<()> {
        self.db().execute("UPDATE jobs SET message = ?2 WHERE id = ?1 AND status = 'running'", params![id, message])?;
        Ok(())
    }

    pub fn set_plan(&self, id: &str, plan: &serde_json::Value) -> Result<()> {
        self.db().execute("UPDATE jobs SET plan = ?2 WHERE id = ?1", params![id, plan.to_string()])?;
        Ok(())
    }

    pub fn set_progress(
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

    /// Move to a final status. Only a job that is not already final changes (a cancel racing
    /// with the end keeps whichever came first). Returns whether it changed.
    pub fn finish(&self, id: &str, status: Status, message: Option<&str>, now: &str) -> Result<bool> {
        let n = self.db().execute(
            "UPDATE jobs SET status = ?2, message = ?3, finished_at = ?4, eta_s = NULL WHERE id = ?1 AND status IN ('queued', 'running')",
            params![id, status.as_str(), message, now],
        )?;
        Ok(n > 0)
    }

    /// Store snapshot `s`; the bytes written.
    pub fn put_snapshot(&self, id: &str, s: &Snapshot, info: &SnapshotInfo) -> Result<u64> {
        let path = self.snapshot_path(id, s.index);
        let bytes = bincode::serialize(s)?;
        write_atomic(&path, &bytes).with_context(|| format!("cannot write {}", path.display()))?;
        self.db().execute(
            "INSERT OR REPLACE INTO snapshots (job_id, n, time_s, step, pressure_drop_pa, mean_particle_height_m) VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
            params![id, info.n as i64, info.time_s, info.step as i64, info.pressure_drop_pa, info.mean_particle_height_m],
        )?;
        Ok(bytes.len() as u64)
    }

    pub fn snapshots(&self, id: &str) -> Result<Vec<SnapshotInfo>> {
        let db = self.db();
        let rows = db
            .prepare("SELECT n, time_s, step, pressure_drop_pa, mean_particle_height_m FROM snapshots WHERE job_id = ?1 ORDER BY n")?
            .query_map([id], |r| {
                Ok(SnapshotInfo {
                    n: r.get::<_, i64>(0)? as u64,
                    time_s: r.get(1)?,
                    step: r.get::<_, i64>(2)? as u64,
                    pressure_drop_pa: r.get(3)?,
                    mean_particle_height_m: r.get(4)?,
                })
            })?
            .collect::<Result<Vec<_>, _>>()?;
        Ok(rows)
    }

    /// Snapshot n of a job, if stored.
    pub fn snapshot(&self, id: &str, n: u64) -> Result<Option<Snapshot>> {
        match std::fs::read(self.snapshot_path(id, n)) {
            Ok(b) => Ok(Some(bincode::deserialize(&b)?)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e.into()),
        }
    }

    pub fn put_checkpoint(&self, id: &str, bytes: &[u8]) -> Result<()> {
        let path = self.checkpoint_path(id);
        write_atomic(&path, bytes).with_context(|| format!("cannot write {}", path.display()))
    }

    pub fn checkpoint(&self, id: &str) -> Result<Option<Vec<u8>>> {
        match std::fs::read(self.checkpoint_path(id)) {
            Ok(b) => Ok(Some(b)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e.into()),
        }
    }
}

/// Write a file so that readers see the old content or the new one, never a part: write a
/// temporary file in the same folder, fsync it, rename it over the target, fsync the folder.
/// On failure (a full disk) the temporary file is removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().ok_or_else(|| std::io::Error::other("file has no parent folder"))?;
    std::fs::create_dir_all(dir)?;
    let tmp = dir.join(format!(".{}.tmp", path.file_name().and_then(|n| n.to_str()).unwrap_or("file")));
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written?;
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}
