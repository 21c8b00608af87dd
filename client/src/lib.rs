//! fluidbed: the command-line client. Every verb talks HTTP to a fluidbed server; `run` without
//! `--server` starts one in-process on a free loopback port (feature `embedded`, on by default),
//! so the default and the real service never drift.

pub mod api;
pub mod cli;
mod cli_run;
mod cli_sweep;
pub mod fetch;
mod outcome;
mod plan_view;
mod validate;
pub mod watch;

/// Exit codes: what a script can tell apart.
pub mod exit {
    pub const OK: i32 = 0;
    /// The case is invalid (locally or as the server answered 422).
    pub const INVALID_CASE: i32 = 2;
    /// The job failed or was cancelled.
    pub const JOB_FAILED: i32 = 3;
    /// The server could not be reached or answered with an unexpected error.
    pub const SERVER: i32 = 4;
    /// Bad command line.
    pub const USAGE: i32 = 64;
}
