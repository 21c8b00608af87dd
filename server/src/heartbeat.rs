//! The heartbeat of a running job: renews this node's lease every `min(lease / 3, 1 s)` and
//! brings back a cancel asked for on any node. A lease found lost (another node took the job, or
//! it ended elsewhere), or not renewed for a whole lease (the database unreachable), sets `lost`:
//! the worker then stops without writing anything more, so that no job runs twice at once.

use crate::store::Lease;
use crate::worker::cancel_flag;
use crate::App;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// Set when the job's run is over (the heartbeat then ends at once).
#[derive(Default)]
pub struct Done {
    over: Mutex<bool>,
    signal: Condvar,
}

impl Done {
    pub fn set(&self) {
        *self.over.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.signal.notify_all();
    }
    /// Wait up to `timeout`; whether the run is over.
    fn wait(&self, timeout: Duration) -> bool {
        let over = self.over.lock().unwrap_or_else(|e| e.into_inner());
        *self.signal.wait_timeout_while(over, timeout, |o| !*o).unwrap_or_else(|e| e.into_inner()).0
    }
}

/// The interval between two renewals of a lease of `lease`.
pub fn interval(lease: Duration) -> Duration {
    (lease / 3).min(Duration::from_secs(1))
}

/// Renew the lease on `id` until `done`.
pub fn beat(app: &App, id: &str, lost: &AtomicBool, done: &Done) {
    let lease = app.config.lease;
    let mut renewed = Instant::now();
    while !done.wait(interval(lease)) {
        match app.store.records().renew(id, &app.node, lease.as_secs_f64()) {
            Ok(Lease::Held { cancel_requested }) => {
                renewed = Instant::now();
                if cancel_requested {
                    cancel_flag(app, id).store(true, Ordering::SeqCst);
                }
            }
            Ok(Lease::Lost) => {
                lost.store(true, Ordering::SeqCst);
                return;
            }
            Err(e) => {
                tracing::warn!("cannot renew the lease: {e:#}");
                // Give up before the database's deadline (renewed + lease, less one interval of slack).
                if renewed.elapsed() + interval(lease) >= lease {
                    lost.store(true, Ordering::SeqCst);
                    return;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renewals_come_three_times_a_lease_and_at_least_every_second() {
        assert_eq!(interval(Duration::from_secs(3)), Duration::from_secs(1));
        assert_eq!(interval(Duration::from_millis(600)), Duration::from_millis(200));
        assert_eq!(interval(Duration::from_secs(60)), Duration::from_secs(1));
    }

    #[test]
    fn done_ends_the_wait() {
        let d = Done::default();
        assert!(!d.wait(Duration::from_millis(1)));
        d.set();
        assert!(d.wait(Duration::from_secs(10)));
    }
}
