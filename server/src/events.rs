//! Server-sent events of a job: `status`, `progress`, `snapshot` (id = snapshot number) and a
//! final `end` event, after which the stream closes. A client connecting late, or resuming with
//! `Last-Event-ID: n`, first gets the stored snapshots after n, then the live events; a gap in
//! the live numbers is filled from the store, so every stream has every snapshot once, in order.

use crate::job::SnapshotInfo;
use crate::App;
use axum::response::sse::Event;
pub use fluidbed_api::events::EventKind;
use fluidbed_api::{GridInfo, SnapshotEvent};
use fluidbed_core::output::fields;
use fluidbed_core::sim::snapshot::Snapshot;
use serde::Serialize;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use tokio::sync::{broadcast, mpsc};

/// One event as broadcast to live listeners.
#[derive(Clone, Debug)]
pub struct JobEvent {
    pub kind: EventKind,
    /// The snapshot number of a `snapshot` event.
    pub n: Option<u64>,
    pub data: Arc<String>,
}

impl JobEvent {
    /// An event with `data` as its JSON payload (one of fluidbed-api's event types).
    pub fn new(kind: EventKind, n: Option<u64>, data: &impl Serialize) -> JobEvent {
        JobEvent { kind, n, data: Arc::new(serde_json::to_string(data).unwrap_or_else(|_| "null".into())) }
    }
    fn sse(&self) -> Event {
        let e = Event::default().event(self.kind.as_str()).data(self.data.as_str());
        match self.n {
            Some(n) => e.id(n.to_string()),
            None => e,
        }
    }
}

/// Where a node's own events also go (the other nodes, see relay.rs).
pub type Outbound = Box<dyn Fn(&str, &JobEvent) + Send + Sync>;

/// Per-job broadcast channels.
#[derive(Default)]
pub struct Hub {
    channels: Mutex<HashMap<String, broadcast::Sender<JobEvent>>>,
    outbound: OnceLock<Outbound>,
}

impl Hub {
    fn sender(&self, id: &str) -> broadcast::Sender<JobEvent> {
        let mut m = self.channels.lock().unwrap_or_else(|e| e.into_inner());
        m.entry(id.to_string()).or_insert_with(|| broadcast::channel(256).0).clone()
    }
    /// An event of a job run here: to this node's listeners and, in a cluster, the others'.
    pub fn publish(&self, id: &str, ev: JobEvent) {
        if let Some(out) = self.outbound.get() {
            out(id, &ev);
        }
        self.deliver(id, ev);
    }
    /// To this node's listeners only (an event relayed from another node).
    pub fn deliver(&self, id: &str, ev: JobEvent) {
        let _ = self.sender(id).send(ev);
    }
    /// Whether anyone here follows the job.
    pub fn has_listeners(&self, id: &str) -> bool {
        self.channels.lock().unwrap_or_else(|e| e.into_inner()).get(id).is_some_and(|s| s.receiver_count() > 0)
    }
    /// Send every published event also to `out` (set once, when the server starts).
    pub fn set_outbound(&self, out: Outbound) {
        let _ = self.outbound.set(out);
    }
    pub fn subscribe(&self, id: &str) -> broadcast::Receiver<JobEvent> {
        self.sender(id).subscribe()
    }
    /// Forget a finished job's channel (listeners already hold their receivers).
    pub fn close(&self, id: &str) {
        self.channels.lock().unwrap_or_else(|e| e.into_inner()).remove(id);
    }
}

/// The `snapshot` event's payload: the grid, cell voidage and pressure, total and per-layer ΔP.
pub fn snapshot_payload(s: &Snapshot, info: &SnapshotInfo) -> SnapshotEvent {
    SnapshotEvent {
        n: s.index,
        time_s: s.time_s,
        step: s.step,
        cells_per_layer: s.grid.grid().cells_per_layer() as u64,
        nz: s.grid.nz as u64,
        grid: GridInfo::from(&s.grid),
        voidage: fields::voidage(s),
        pressure_pa: s.pressure_pa.clone(),
        pressure_drop_pa: s.pressure_drop_pa,
        layer_pressure_drop_pa: s.layer_pressure_drop_pa.clone(),
        mean_particle_height_m: info.mean_particle_height_m,
    }
}

/// Feed one listener: replay what it missed from the store, then follow the live channel.
pub async fn pump(app: Arc<App>, id: String, last_seen: Option<u64>, tx: mpsc::Sender<Event>) {
    let mut live = app.hub.subscribe(&id);
    let mut next = last_seen.map_or(0, |n| n + 1);
    let Ok(Some(job)) = app.store.get(&id) else { return };
    if tx.send(JobEvent::new(EventKind::Status, None, &job.status_event()).sse()).await.is_err() {
        return;
    }
    if !replay(&app, &id, &mut next, &tx).await {
        return;
    }
    let Ok(Some(job)) = app.store.get(&id) else { return };
    if tx.send(JobEvent::new(EventKind::Progress, None, &job.progress_event()).sse()).await.is_err() {
        return;
    }
    if job.status.is_final() {
        let _ = replay(&app, &id, &mut next, &tx).await;
        let _ = tx.send(JobEvent::new(EventKind::End, None, &job.status_event()).sse()).await;
        return;
    }
    loop {
        match live.recv().await {
            Ok(ev) => {
                // A snapshot past the next one expected, or the end: first what the store holds
                // in between (the notices of a node killed after its writes never came).
                let gap = ev.n.is_some_and(|n| n > next) || ev.kind == EventKind::End;
                if gap && !replay(&app, &id, &mut next, &tx).await {
                    return;
                }
                if let Some(n) = ev.n {
                    if n < next {
                        continue;
                    }
                    next = n + 1;
                }
                let end = ev.kind == EventKind::End;
                if tx.send(ev.sse()).await.is_err() || end {
                    return;
                }
            }
            Err(broadcast::error::RecvError::Lagged(_)) => {
                if !replay(&app, &id, &mut next, &tx).await {
                    return;
                }
            }
            Err(broadcast::error::RecvError::Closed) => return,
        }
    }
}

/// Send stored snapshots numbered `next` and up; false when the listener has gone.
async fn replay(app: &Arc<App>, id: &str, next: &mut u64, tx: &mpsc::Sender<Event>) -> bool {
    let Ok(list) = app.store.snapshots(id) else { return true };
    let from = *next;
    for info in list.into_iter().filter(|i| i.n >= from) {
        let (a, job) = (app.clone(), id.to_string());
        let n = info.n;
        let loaded = tokio::task::spawn_blocking(move || a.store.snapshot(&job, n)).await;
        if let Ok(Ok(Some(s))) = loaded {
            let ev = JobEvent::new(EventKind::Snapshot, Some(n), &snapshot_payload(&s, &info));
            if tx.send(ev.sse()).await.is_err() {
                return false;
            }
            *next = n + 1;
        }
    }
    true
}
