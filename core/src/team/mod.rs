//! Teams of threads: several passes of a step as one rayon broadcast, so that the pool's threads
//! are woken once per step instead of once per pass (the DEM step, `dem::team_step`; the gas
//! right-hand side, `cfd::team_rhs`).
//!
//! - `lock`: at most one team per pool at a time; `solver_pool` builds a pool with its own lock;
//! - `shared_slice`: a slice the team reads in windows and writes in disjoint pieces;
//! - `spin_barrier`: the barrier between a team's passes.

mod lock;
mod shared_slice;
mod spin_barrier;

#[cfg(test)]
pub(crate) use lock::has_own_team;
pub use lock::solver_pool;
pub(crate) use lock::TeamLock;
pub(crate) use shared_slice::Raw;
pub(crate) use spin_barrier::{spin_until, SpinBarrier};
