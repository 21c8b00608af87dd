//! Events across nodes: each event a node publishes goes out as a small notice (node, job, kind,
//! snapshot number); a node that has listeners for that job rebuilds the event from the shared
//! store (the job record, the snapshot file) and hands it to them, so every node streams every
//! job with the same ids and payloads as the node running it.

use crate::events::{snapshot_payload, EventKind, JobEvent};
use crate::store::Notice;
use crate::App;
use anyhow::Result;
use std::sync::mpsc::RecvTimeoutError;
use std::sync::{Arc, Weak};
use std::time::Duration;

/// Connect the hub to the other nodes (nothing to do on an unshared store).
pub fn start(app: &Arc<App>) -> Result<()> {
    if !app.store.records().shared() {
        return Ok(());
    }
    let weak: Weak<App> = Arc::downgrade(app);
    let node = app.node.clone();
    app.hub.set_outbound(Box::new(move |id, ev| {
        if let Some(app) = weak.upgrade() {
            app.store.records().notify(Notice { node: node.clone(), job: id.to_string(), kind: ev.kind, n: ev.n });
        }
    }));
    let (tx, rx) = std::sync::mpsc::channel::<Notice>();
    app.store.records().listen(Box::new(move |n| {
        let _ = tx.send(n);
    }))?;
    let weak = Arc::downgrade(app);
    // Store reads block: on a thread of its own, in arrival order.
    std::thread::Builder::new().name("fluidbed-relay".into()).spawn(move || loop {
        let notice = match rx.recv_timeout(Duration::from_millis(500)) {
            Ok(n) => Some(n),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => return,
        };
        let Some(app) = weak.upgrade() else { return };
        if app.stopping() {
            return;
        }
        if let Some(n) = notice.filter(|n| n.node != app.node) {
            relay(&app, &n);
        }
    })?;
    Ok(())
}

/// Hand one notice of another node to this node's listeners of its job.
fn relay(app: &App, n: &Notice) {
    if app.hub.has_listeners(&n.job) {
        match rebuild(app, n) {
            Ok(Some(ev)) => app.hub.deliver(&n.job, ev),
            Ok(None) => {}
            Err(e) => tracing::warn!(job = %n.job, "cannot relay a {} event: {e:#}", n.kind.as_str()),
        }
    }
    if n.kind == EventKind::End {
        app.hub.close(&n.job);
    }
}

/// The event a notice stands for, read from the store (None if what it names is gone).
fn rebuild(app: &App, n: &Notice) -> Result<Option<JobEvent>> {
    let store = &app.store;
    Ok(match (n.kind, n.n) {
        (EventKind::Snapshot, Some(k)) => {
            let (Some(info), Some(s)) = (store.records().snapshot_info(&n.job, k)?, store.snapshot(&n.job, k)?) else {
                return Ok(None);
            };
            Some(JobEvent::new(EventKind::Snapshot, Some(k), &snapshot_payload(&s, &info)))
        }
        (EventKind::Snapshot, None) => None,
        (EventKind::Progress, _) => {
            store.get(&n.job)?.map(|j| JobEvent::new(EventKind::Progress, None, &j.progress_event()))
        }
        (kind, _) => store.get(&n.job)?.map(|j| JobEvent::new(kind, None, &j.status_event())),
    })
}
