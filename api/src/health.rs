//! `GET /healthz`: whether the server's data directory takes writes.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum HealthStatus {
    /// 200: the data directory takes writes.
    Ok,
    /// 503: it does not (a full or read-only disk).
    Degraded,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct Health {
    pub status: HealthStatus,
    /// The server's version.
    pub version: String,
    pub data_dir: DataDirReport,
}

/// The data directory as a probe write found it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct DataDirReport {
    pub path: String,
    pub writable: bool,
    pub probe_error: Option<String>,
    /// Whether the space set aside to record a failed write is held.
    pub reserve_held: bool,
    /// The last write that failed, until a probe succeeds again.
    pub last_write_error: Option<String>,
}
