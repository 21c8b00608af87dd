//! The job store: job records behind `Records` (SQLite in the data directory, or PostgreSQL shared
//! by many nodes), and snapshots and checkpoints as files in the data directory (shared by the
//! nodes of a cluster), each written atomically (temporary file, fsync, rename). Layout:
//!
//! ```text
//! DIR/fluidbed.sqlite            jobs and the snapshot index (without --database)
//! DIR/jobs/<id>/snapshots/<n>.bin  snapshot n (bincode of core's Snapshot, raw f64)
//! DIR/jobs/<id>/checkpoint.bin   the complete simulation state after the last checkpoint
//! DIR/cache/                     settled beds shared between jobs (core's bed cache)
//! DIR/reserve.bin                space set aside so that a full disk can still record a failure
//! ```
//! A job's folder is created by the worker that runs it, so a rejected request writes nothing.

mod postgres;
pub mod records;
mod sqlite;

use crate::job::{Job, SnapshotInfo, Status};
use anyhow::{bail, Context, Result};
use fluidbed_core::sim::snapshot::Snapshot;
pub use records::{EventKind, Lease, Notice, NoticeSink, Records, SweepRecord};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The job records (either backend) and the files of the data directory.
pub struct Store {
    dir: PathBuf,
    records: Box<dyn Records>,
    /// Size of the largest snapshot or checkpoint write that failed since the last healthy probe
    /// (health.rs probes with that many bytes, so a disk with room for less stays degraded).
    failed_write_bytes: std::sync::atomic::AtomicU64,
}

/// Bytes kept in DIR/reserve.bin: freed when a write fails, so that the database can still mark the job.
const RESERVE_BYTES: usize = 256 << 10;

impl Store {
    /// Open (or create) the store: records in `database` (a `postgres://` URL) or, without one,
    /// in DIR/fluidbed.sqlite. Every error names the path or database it is about.
    pub fn open(dir: &Path, database: Option<&str>) -> Result<Store> {
        let jobs = dir.join("jobs");
        std::fs::create_dir_all(&jobs)
            .with_context(|| format!("cannot create the data directory {}", jobs.display()))?;
        let probe = dir.join(format!(".write-probe-{}", std::process::id()));
        std::fs::write(&probe, b"fluidbed")
            .and_then(|_| std::fs::remove_file(&probe))
            .with_context(|| format!("the data directory {} is not writable", dir.display()))?;
        let records: Box<dyn Records> = match database {
            None => Box::new(sqlite::Sqlite::open(&dir.join("fluidbed.sqlite"))?),
            Some(url) if url.starts_with("postgres://") || url.starts_with("postgresql://") => {
                Box::new(postgres::Postgres::open(url)?)
            }
            Some(other) => bail!(
                "--database `{}` is not supported: give a postgres://user@host:port/db URL, or leave it out for SQLite in the data directory",
                other.split('@').next_back().unwrap_or(other)
            ),
        };
        let store = Store { dir: dir.to_path_buf(), records, failed_write_bytes: Default::default() };
        store.restore_reserve();
        Ok(store)
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }
    /// The job records, whichever backend keeps them.
    pub fn records(&self) -> &dyn Records {
        &*self.records
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
    /// The largest result write that failed since `forget_failed_writes` (0: none).
    pub fn failed_write_bytes(&self) -> u64 {
        self.failed_write_bytes.load(std::sync::atomic::Ordering::SeqCst)
    }
    pub fn forget_failed_writes(&self) {
        self.failed_write_bytes.store(0, std::sync::atomic::Ordering::SeqCst);
    }
    /// `write_atomic`, remembering the size of a write that failed.
    fn put_file(&self, path: &Path, bytes: &[u8]) -> Result<()> {
        write_atomic(path, bytes).map_err(|e| {
            self.failed_write_bytes.fetch_max(bytes.len() as u64, std::sync::atomic::Ordering::SeqCst);
            anyhow::Error::new(e).context(format!("cannot write {}", path.display()))
        })
    }
    pub fn reserve_held(&self) -> bool {
        std::fs::metadata(self.reserve_path()).is_ok_and(|m| m.len() as usize == RESERVE_BYTES)
    }

    /// The last call on a store.
    pub fn close(&self) -> Result<()> {
        self.records.close()
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
        self.records.insert(job, case_json)
    }
    pub fn get(&self, id: &str) -> Result<Option<Job>> {
        self.records.get(id)
    }
    pub fn case_json(&self, id: &str) -> Result<Option<String>> {
        self.records.case_json(id)
    }
    /// Newest first; optionally only one status. Returns (page, total matching).
    pub fn list(&self, status: Option<Status>, limit: usize, offset: usize) -> Result<(Vec<Job>, usize)> {
        self.records.list(status, limit, offset)
    }
    pub fn count(&self, status: Status) -> Result<usize> {
        self.records.count(status)
    }
    /// Mark running and count the attempt (a clean stop gives it back with `release`; a crash
    /// does not, so the count tells how often this job took a server down); false if it ended.
    pub fn set_running(&self, id: &str, now: &str) -> Result<bool> {
        self.records.set_running(id, now)
    }
    /// Record a cancel request (it survives a restart); false if the job is already final.
    pub fn request_cancel(&self, id: &str) -> Result<bool> {
        self.records.request_cancel(id)
    }
    /// What a running job is doing when that is not stepping (e.g. preparing its bed); None clears it.
    pub fn set_message(&self, id: &str, message: Option<&str>) -> Result<()> {
        self.records.set_message(id, message)
    }
    pub fn set_plan(&self, id: &str, plan: &serde_json::Value) -> Result<()> {
        self.records.set_plan(id, plan)
    }
    pub fn set_stages(&self, id: &str, stages: &serde_json::Value) -> Result<()> {
        self.records.set_stages(id, stages)
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
        self.records.set_progress(id, time_s, end_time_s, steps, wall_s, eta_s)
    }
    /// Move to a final status. Only a job that is not already final changes (a cancel racing
    /// with the end keeps whichever came first), and with `owner` only while that node holds it.
    pub fn finish(
        &self,
        id: &str,
        status: Status,
        message: Option<&str>,
        now: &str,
        owner: Option<&str>,
    ) -> Result<bool> {
        self.records.finish(id, status, message, now, owner)
    }

    /// Insert a sweep and its jobs, all or none.
    pub fn insert_sweep(&self, sweep: &SweepRecord, jobs: &[(Job, String)]) -> Result<()> {
        self.records.insert_sweep(sweep, jobs)
    }
    pub fn sweep(&self, id: &str) -> Result<Option<SweepRecord>> {
        self.records.sweep(id)
    }
    /// Newest first. Returns (page, total).
    pub fn sweeps(&self, limit: usize, offset: usize) -> Result<(Vec<SweepRecord>, usize)> {
        self.records.sweeps(limit, offset)
    }

    /// Store snapshot `s`; the bytes written.
    pub fn put_snapshot(&self, id: &str, s: &Snapshot, info: &SnapshotInfo) -> Result<u64> {
        let path = self.snapshot_path(id, s.index);
        let bytes = bincode::serialize(s)?;
        self.put_file(&path, &bytes)?;
        self.records.put_snapshot_info(id, info)?;
        Ok(bytes.len() as u64)
    }

    pub fn snapshots(&self, id: &str) -> Result<Vec<SnapshotInfo>> {
        self.records.snapshots(id)
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
        self.put_file(&self.checkpoint_path(id), bytes)
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
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    // Per process: nodes sharing the folder never write the same temporary file.
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
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
