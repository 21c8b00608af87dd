//! The PostgreSQL job records under concurrency, without the solver: nodes claiming at once each
//! get different jobs and every job is claimed once; a lease that ran out passes to another node
//! and the old holder learns it lost it; a notice published on one node reaches the others.

use fluidbed_server::job::{now_rfc3339, Job, Status};
use fluidbed_server::store::{EventKind, Lease, Notice, Store};
use fluidbed_tests::postgres::PgCluster;
use fluidbed_tests::TempDir;
use std::collections::HashMap;
use std::time::Duration;

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

#[test]
fn claims_leases_and_notices_across_nodes() {
    let pg = match PgCluster::start() {
        Ok(pg) => pg,
        Err(why) if std::env::var_os("CI").is_none() => {
            eprintln!("SKIPPED claims_leases_and_notices_across_nodes: no PostgreSQL here ({why})");
            return;
        }
        Err(why) => panic!("CI must have PostgreSQL (.ci/run installs it): {why}"),
    };
    let dir = TempDir::new("claims");
    let nodes: Vec<Store> = (0..4).map(|_| Store::open(dir.path(), Some(&pg.url())).expect("open")).collect();
    for k in 0..40 {
        nodes[k % 4].insert(&job(&format!("job{k:02}")), "{}").unwrap();
    }

    // Four nodes claim at once until the queue is empty.
    let claimed: Vec<Vec<String>> = std::thread::scope(|s| {
        let handles: Vec<_> = nodes
            .iter()
            .enumerate()
            .map(|(k, store)| {
                s.spawn(move || {
                    let mut mine = Vec::new();
                    while let Some(id) = store.records().claim(&format!("node{k}"), 60.0).unwrap() {
                        assert!(store.set_running(&id, &now_rfc3339()).unwrap());
                        mine.push(id);
                    }
                    mine
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut times: HashMap<&str, usize> = HashMap::new();
    for id in claimed.iter().flatten() {
        *times.entry(id).or_default() += 1;
    }
    assert_eq!(times.len(), 40, "every job claimed");
    assert!(times.values().all(|&n| n == 1), "a job claimed twice: {times:?}");
    assert!(claimed.iter().filter(|c| !c.is_empty()).count() >= 2, "the claims were spread: {claimed:?}");

    // node0's first job: its lease runs out, node1 takes it, node0 can neither renew nor end it.
    let id = &claimed.iter().find(|c| !c.is_empty()).unwrap()[0];
    let holder = claimed.iter().position(|c| c.contains(id)).unwrap();
    let (old, new) = (format!("node{holder}"), "node-next".to_string());
    assert!(matches!(nodes[0].records().renew(id, &old, -1.0).unwrap(), Lease::Held { .. }));
    assert_eq!(nodes[1].records().claim(&new, 60.0).unwrap().as_deref(), Some(id.as_str()));
    assert_eq!(nodes[0].records().renew(id, &old, 60.0).unwrap(), Lease::Lost);
    assert!(!nodes[0].finish(id, Status::Succeeded, None, &now_rfc3339(), Some(&old)).unwrap());
    assert!(nodes[2].request_cancel(id).unwrap());
    assert_eq!(nodes[1].records().renew(id, &new, 60.0).unwrap(), Lease::Held { cancel_requested: true });
    assert!(nodes[1].finish(id, Status::Cancelled, Some("cancelled by request"), &now_rfc3339(), Some(&new)).unwrap());
    assert_eq!(nodes[3].get(id).unwrap().unwrap().status, Status::Cancelled);

    // A notice from node 3 reaches node 2's listener.
    let (tx, rx) = std::sync::mpsc::channel();
    nodes[2]
        .records()
        .listen(Box::new(move |n| {
            let _ = tx.send(n);
        }))
        .unwrap();
    let sent = Notice { node: "node3".into(), job: id.clone(), kind: EventKind::Snapshot, n: Some(3) };
    // LISTEN is set up asynchronously: send until one arrives.
    let mut got = None;
    for _ in 0..50 {
        nodes[3].records().notify(sent.clone());
        if let Ok(n) = rx.recv_timeout(Duration::from_millis(200)) {
            got = Some(n);
            break;
        }
    }
    assert_eq!(got, Some(sent));
    drop(nodes);
    drop(pg);
}
