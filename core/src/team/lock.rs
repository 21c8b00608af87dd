//! At most one team (`dem::team_step`, `cfd::team_rhs`) per rayon pool at a time, and the public way to build a pool
//! for stepping systems (`solver_pool`).

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// At most one team at a time per pool: a team's threads spin while they wait, so two teams
/// sharing a pool could each wait for a thread the other holds. Pools built by
/// `solver_pool` have a lock each; every other pool (and code outside any pool) shares
/// one process-wide lock. Whoever does not get the lock steps with plain parallel loops. Neither
/// `Send` nor `Sync`, so the holder cannot hand it to the tasks of a parallel loop (which would
/// start two teams on one pool).
pub struct TeamLock {
    flag: Option<Arc<AtomicBool>>,
    not_send: std::marker::PhantomData<*const ()>,
}

static TEAM_BUSY: AtomicBool = AtomicBool::new(false);

thread_local! {
    /// The team flag of the pool this thread works for, if it was built by `solver_pool`.
    static POOL_TEAM: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// A rayon pool builder for stepping DEM systems (set the thread count and names on it, then
/// `build` and `install`): its pool gets its own team lock, so that systems stepped on different
/// such pools at once (the server's concurrent jobs) each run as one team of threads.
pub fn solver_pool() -> rayon::ThreadPoolBuilder {
    let flag = Arc::new(AtomicBool::new(false));
    rayon::ThreadPoolBuilder::new().start_handler(move |_| POOL_TEAM.with(|p| *p.borrow_mut() = Some(flag.clone())))
}

#[cfg(test)]
pub(crate) fn has_own_team() -> bool {
    POOL_TEAM.with(|p| p.borrow().is_some())
}

impl TeamLock {
    /// The lock of the current thread's pool (the pool a broadcast from here runs on).
    pub fn try_take() -> Option<TeamLock> {
        let flag = POOL_TEAM.with(|p| p.borrow().clone());
        let busy = flag.as_deref().unwrap_or(&TEAM_BUSY);
        busy.compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed).ok()?;
        Some(TeamLock { flag, not_send: std::marker::PhantomData })
    }
}

impl Drop for TeamLock {
    fn drop(&mut self) {
        self.flag.as_deref().unwrap_or(&TEAM_BUSY).store(false, Ordering::Release);
    }
}
