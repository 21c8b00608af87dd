//! The data directory's health as `/healthz` reports it: the last write that failed (cleared by a
//! later successful probe as large as the largest result write that failed, so a disk that still
//! has no room for that write stays degraded), whether the reserve (store.rs) is held, and a probe write.

use crate::store::Store;
use fluidbed_api::DataDirReport;
use std::sync::Mutex;

#[derive(Default)]
pub struct Health {
    last_write_error: Mutex<Option<String>>,
}

impl Health {
    /// Remember a failed write (a full or read-only disk) until a probe succeeds again.
    pub fn write_failed(&self, message: &str) {
        *self.last_write_error.lock().unwrap_or_else(|e| e.into_inner()) = Some(message.to_string());
    }

    /// Probe the data directory; (healthy, the `data_dir` report). The reserve is set aside again
    /// first; a probe that then fits forgets an earlier failure.
    pub fn check(&self, store: &Store) -> (bool, DataDirReport) {
        let dir = store.dir();
        let probe = dir.join(".health-probe");
        store.restore_reserve();
        let size = store.failed_write_bytes().clamp(4096, 1 << 30) as usize;
        let written = std::fs::write(&probe, vec![0u8; size]).and_then(|_| std::fs::remove_file(&probe));
        let _ = std::fs::remove_file(&probe);
        let mut last = self.last_write_error.lock().unwrap_or_else(|e| e.into_inner());
        if written.is_ok() && store.reserve_held() {
            *last = None;
            store.forget_failed_writes();
        }
        let ok = written.is_ok() && store.reserve_held() && last.is_none();
        let report = DataDirReport {
            path: dir.display().to_string(),
            writable: written.is_ok(),
            probe_error: written.err().map(|e| format!("cannot write {}: {e}", probe.display())),
            reserve_held: store.reserve_held(),
            last_write_error: last.clone(),
        };
        (ok, report)
    }
}
