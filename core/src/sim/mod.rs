//! The simulation: state, plan, step loop, watchdog, snapshots and checkpoints.

pub mod snapshot;
pub use snapshot::{GridInfo, ParticleSnapshot, Snapshot, SnapshotSink};
