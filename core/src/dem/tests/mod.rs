//! DEM tests: each compares with an analytic or published value (PHYSICS.md 2, 7; textbook
//! mechanics) and stays small enough to run in seconds.

mod batch_kernel;
mod checkpoint;
mod energy;
mod integrator_order;
mod kernel_paths;
mod near_list;
mod pair_scatter;
mod poured_bed;
mod reproducible;
mod restitution;
mod sliding;
mod team_step;
mod wall_loads;
mod work_split;

use crate::case::{Bed, Case, Column, Damping, ExplicitBed, Particles};

/// A case with the paper's particles in a column of diameter `col_d` and height `height`.
pub fn test_case(col_d: f64, height: f64, lid: bool, gravity: f64, dt: f64) -> Case {
    let mut c = Case {
        name: "dem test".into(),
        column: Column { diameter_m: col_d, height_m: height, lid },
        particles: Particles::default(),
        bed: Bed::Explicit(ExplicitBed { positions_m: vec![], velocities_m_s: None }),
        gravity_m_s2: gravity,
        dem: Default::default(),
        end_time_s: 1.0,
        outputs: Default::default(),
        gas: None,
        grid: Default::default(),
        voidage: Default::default(),
        coupling: Default::default(),
        analysis: Default::default(),
    };
    c.dem.time_step_s = dt;
    c
}

/// Report a test (or part of one) that cannot run on this machine, on the process's stderr
/// directly so that it shows in `cargo test` output even when the test passes.
pub fn skip(test: &str, reason: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "test {test}: SKIPPED ({reason})");
}

pub fn with_damping(mut c: Case, alpha_n: f64, alpha_t: f64, mu: f64) -> Case {
    c.particles.normal_damping = Damping::TsujiAlpha(alpha_n);
    c.particles.tangential_damping = Damping::TsujiAlpha(alpha_t);
    c.particles.sliding_friction = mu;
    c
}
