//! The simulation: state, plan, step loop, watchdog, snapshots and checkpoints.
