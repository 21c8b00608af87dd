//! The job records as a backend keeps them: the interface that SQLite (one machine) and
//! PostgreSQL (many nodes on one queue) both implement. Nothing above `Store` sees which it is.

use crate::job::{Job, SnapshotInfo, Status};
use anyhow::Result;
pub use fluidbed_api::events::EventKind;

/// What a heartbeat found: the lease still held (and whether a cancel was asked for), or lost
/// (another node holds it now, or the job ended elsewhere): the worker must stop at once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lease {
    Held { cancel_requested: bool },
    Lost,
}

/// One event of a job as it crosses nodes: ids only, the data is read from the shared store.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Notice {
    /// The node that published it (a node skips its own).
    pub node: String,
    pub job: String,
    pub kind: EventKind,
    /// The snapshot number of a `snapshot` event.
    pub n: Option<u64>,
}

impl Notice {
    /// The wire form: `{"node":…,"job":…,"kind":"snapshot","n":3}` (well under NOTIFY's 8000 bytes).
    pub fn to_payload(&self) -> String {
        serde_json::json!({ "node": self.node, "job": self.job, "kind": self.kind.as_str(), "n": self.n }).to_string()
    }
    pub fn from_payload(text: &str) -> Option<Notice> {
        let v: serde_json::Value = serde_json::from_str(text).ok()?;
        let kind = v["kind"].as_str()?;
        Some(Notice {
            node: v["node"].as_str()?.to_string(),
            job: v["job"].as_str()?.to_string(),
            kind: *EventKind::ALL.iter().find(|k| k.as_str() == kind)?,
            n: v["n"].as_u64(),
        })
    }
}

/// A sweep as the records keep it: its points in order, each the job made for it and the values
/// set in the base case.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepRecord {
    pub id: String,
    pub name: String,
    pub created_at: String,
    pub points: Vec<(String, serde_json::Map<String, serde_json::Value>)>,
}

impl SweepRecord {
    pub fn points_json(&self) -> String {
        let pts: Vec<serde_json::Value> =
            self.points.iter().map(|(job, set)| serde_json::json!({ "job": job, "set": set })).collect();
        serde_json::Value::Array(pts).to_string()
    }
    pub fn from_columns(id: String, name: String, created_at: String, points: &str) -> Result<SweepRecord> {
        let pts: Vec<serde_json::Value> = serde_json::from_str(points)?;
        let points = pts
            .into_iter()
            .map(|p| {
                let job = p["job"].as_str().unwrap_or_default().to_string();
                (job, p["set"].as_object().cloned().unwrap_or_default())
            })
            .collect();
        Ok(SweepRecord { id, name, created_at, points })
    }
}

/// Called with each notice from another node.
pub type NoticeSink = Box<dyn Fn(Notice) + Send + Sync>;

/// Job records. Every call is synchronous and short; a backend that is asynchronous inside runs
/// its own runtime.
pub trait Records: Send + Sync {
    /// Whether other nodes may share these records (then leases expire and notices cross).
    fn shared(&self) -> bool;
    fn insert(&self, job: &Job, case_json: &str) -> Result<()>;
    fn get(&self, id: &str) -> Result<Option<Job>>;
    fn case_json(&self, id: &str) -> Result<Option<String>>;
    /// Newest first; optionally only one status. Returns (page, total matching).
    fn list(&self, status: Option<Status>, limit: usize, offset: usize) -> Result<(Vec<Job>, usize)>;
    fn count(&self, status: Status) -> Result<usize>;

    /// Take an unfinished job that no live lease holds (running on a node whose lease ran out
    /// first, then queued; oldest first), atomically: no two nodes get the same one.
    fn claim(&self, node: &str, lease_s: f64) -> Result<Option<String>>;
    /// Extend `node`'s lease on a running job.
    fn renew(&self, id: &str, node: &str, lease_s: f64) -> Result<Lease>;
    /// Give the lease back (a clean stop: another node may take the job at once); with
    /// `attempt`, the start is not counted as a crash either.
    fn release(&self, id: &str, node: &str, attempt: bool) -> Result<()>;

    /// Mark running and count the attempt (see `release`); false if the job ended meanwhile.
    fn set_running(&self, id: &str, now: &str) -> Result<bool>;
    /// Record a cancel request (it survives a restart); false if the job is already final.
    fn request_cancel(&self, id: &str) -> Result<bool>;
    /// Cancel a job no worker has started; false if it is no longer queued.
    fn cancel_queued(&self, id: &str, message: &str, now: &str) -> Result<bool>;
    fn set_message(&self, id: &str, message: Option<&str>) -> Result<()>;
    fn set_plan(&self, id: &str, plan: &serde_json::Value) -> Result<()>;
    /// Wall seconds per stage of a running job.
    fn set_stages(&self, id: &str, stages: &serde_json::Value) -> Result<()>;
    fn set_progress(
        &self,
        id: &str,
        time_s: f64,
        end_time_s: f64,
        steps: u64,
        wall_s: f64,
        eta_s: Option<f64>,
    ) -> Result<()>;
    /// Move to a final status, only from queued or running and, with `owner`, only while that
    /// node holds the job. Returns whether it changed.
    fn finish(&self, id: &str, status: Status, message: Option<&str>, now: &str, owner: Option<&str>) -> Result<bool>;

    fn put_snapshot_info(&self, id: &str, info: &SnapshotInfo) -> Result<()>;
    fn snapshots(&self, id: &str) -> Result<Vec<SnapshotInfo>>;
    fn snapshot_info(&self, id: &str, n: u64) -> Result<Option<SnapshotInfo>>;

    /// Insert a sweep and its jobs (each with its case JSON) in one transaction: all or none.
    fn insert_sweep(&self, sweep: &SweepRecord, jobs: &[(Job, String)]) -> Result<()>;
    fn sweep(&self, id: &str) -> Result<Option<SweepRecord>>;
    /// Newest first. Returns (page, total).
    fn sweeps(&self, limit: usize, offset: usize) -> Result<(Vec<SweepRecord>, usize)>;

    /// Tell the other nodes (in publishing order); nothing on a backend that is not shared.
    fn notify(&self, notice: Notice);
    /// Call `sink` with every notice of the other nodes from now on.
    fn listen(&self, sink: NoticeSink) -> Result<()>;
    /// The last call on the records.
    fn close(&self) -> Result<()>;
}

/// Now as Unix seconds (the SQLite backend's lease clock).
pub fn unix_now() -> f64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs_f64()).unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_notice_survives_its_wire_form() {
        for (kind, n) in [(EventKind::Snapshot, Some(7)), (EventKind::End, None)] {
            let notice = Notice { node: "a1".into(), job: "00ff".into(), kind, n };
            let payload = notice.to_payload();
            assert!(payload.len() < 200, "{payload}");
            assert_eq!(Notice::from_payload(&payload), Some(notice));
        }
        assert_eq!(Notice::from_payload(r#"{"node":"a","job":"b","kind":"bogus"}"#), None);
    }
}
