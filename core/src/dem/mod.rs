//! Soft-sphere DEM: Hertz–Mindlin + Tsuji contacts (or a linear spring–dashpot), tube wall, AB3
//! (paper section 2.1).
//!
//! - `contact`: the contact law (PHYSICS.md 2), one generic source for pairs (f32) and walls (f64);
//! - `contact_styles`: the styles' springs and dashpots (Hertz–Mindlin, linear spring–dashpot);
//! - `real`: the float types a law is evaluated in;
//! - `integrator`: AB3 with a Heun/AB2 start (PHYSICS.md 7);
//! - `ab_update`: the AB update on flat arrays (with the largest move, for positions);
//! - `neighbors`: linked cells, cell-order sort, half Verlet list;
//! - `id_histories`: the live contact histories carried by particle id across a re-sort;
//! - `near_list`: the Verlet list's entries within a small gap, the list the pair pass walks;
//! - `near_refresh`: the near list redrawn in its own storage;
//! - `reference`: the positions at the last build and refresh, single precision;
//! - `batch`: a batch of touching pairs as lanes, and the inputs the lanes are gathered from;
//! - `pair_batch`: the same law for batches of particle pairs (the fast path);
//! - `pair_simd`: AVX-512 scan and gather of the pair pass, eight entries at a time;
//! - `pair_scatter`: a batch's forces added into the chunk buffers;
//! - `kernel`: the code paths (portable, AVX2, AVX-512) and `FLUIDBED_KERNEL`;
//! - `walls`: plate, tube and lid contacts for the particles near them;
//! - `forces`: the pair pass of a step (deterministic, parallel) and the shared types;
//! - `work_split`: the pair pass's chunks and their force buffers;
//! - `particle_pass`: the particle pass (buffer sums, walls, gravity, AB3);
//! - `team_step`, `steal_ranges`: both passes of a step as one team of threads sharing the work;
//! - one team per pool at a time: `crate::team` (`solver_pool` builds a pool with its own lock);
//! - `system`: `DemSystem`, the state; `step`: the step loop; `list_upkeep`: the lists' refresh
//!   and rebuild; `diagnostics`: energies, loads, counters;
//! - `bed`: pouring and settling a bed from a seed, with an on-disk cache.

mod ab_update;
mod batch;
mod bed;
mod contact;
mod contact_styles;
mod diagnostics;
mod forces;
mod id_histories;
mod impact;
mod integrator;
mod kernel;
mod list_upkeep;
mod near_list;
mod near_refresh;
mod neighbors;
mod pair_batch;
mod pair_scatter;
#[cfg(target_arch = "x86_64")]
mod pair_simd;
mod particle_pass;
mod real;
mod reference;
mod steal_ranges;
mod step;
mod system;
mod team_step;
mod verlet_list;
mod walls;
mod work_split;

#[cfg(test)]
mod tests;

pub use crate::team::solver_pool;
pub use bed::{build_bed, build_bed_until, fnv1a, Stop, STOPPED};
pub use contact::{linear_damping_ratio, ContactLaw, ContactStyle, V3};
pub use impact::{plate_impact, Impact};
pub use kernel::{Kernel, KERNEL_ENV};
pub use system::DemSystem;

use crate::case::Case;
use serde::{Deserialize, Serialize};

/// Everything a step needs that does not change during a run (from the case).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DemParams {
    pub radius: f64,
    pub mass: f64,
    /// Moment of inertia of a solid sphere, 2/5 m R².
    pub inertia: f64,
    pub dt: f64,
    /// Magnitude of gravity along −z.
    pub gravity: f64,
    pub tube_radius: f64,
    pub height: f64,
    pub lid: bool,
    /// Verlet skin (absolute; the case's) and the Verlet list's cutoff d + skin + near gap: the
    /// list is drawn that much wider so that it is rebuilt as often as a plain list of this skin
    /// (when a particle has moved skin/2), while the pair pass walks the near list.
    pub skin: f64,
    pub cutoff: f64,
    /// Particle-particle law: R* = R/2, m* = m/2.
    pub pair: ContactLaw,
    /// Particle-wall law: R* = R, m* = m, the wall of the particles' material.
    pub wall: ContactLaw,
    /// μ > 0: tangential history and rotation are integrated (else skipped, same result).
    pub friction: bool,
    /// Extra viscous damping rate (1/s) on v and ω; used only while pouring a bed, 0 otherwise.
    pub extra_damping: f64,
    /// Work chunks of the pair pass; 0 = twice the pool's threads. The summation order follows
    /// the chunks, so a fixed value makes results independent of the thread count.
    pub work_chunks: usize,
    /// Measure every contact's Coulomb excess (`DemSystem::max_coulomb_excess`), a check for
    /// tests; off, the passes skip it (2–3% of a step) and the trajectory is the same.
    #[serde(default)]
    pub audit: bool,
}

/// Pair-pass chunks of a reproducible run (`dem.reproducible`): fixed, so that the chunk sums and
/// their order do not depend on the thread count; enough to share among 8 threads.
pub const REPRODUCIBLE_CHUNKS: usize = 16;

/// The near gap as a fraction of the skin: 0.1 and 0.2 ran the settled DEM bench at the same
/// speed; 0.15 runs it 3–6% faster than walking the whole list (docs/BENCHMARKS.md).
const NEAR_GAP: f64 = 0.15;

impl DemParams {
    /// Gap below which a Verlet-list entry joins the near list (`near_list`).
    pub fn near_gap(&self) -> f64 {
        NEAR_GAP * self.skin
    }
    /// Displacement since the near-list refresh that triggers the next one: just under half the
    /// near gap (the 2% margin covers rounding in the distance checks).
    pub fn near_move(&self) -> f64 {
        0.49 * self.near_gap()
    }
    /// Displacement since the Verlet-list build beyond which a refresh rebuilds the list first:
    /// just under skin/2, so the list (cutoff d + skin + near gap) holds every pair closer than
    /// d + near gap.
    pub fn outer_move(&self) -> f64 {
        0.49 * self.skin
    }

    pub fn new(case: &Case) -> Self {
        let r = case.particles.diameter_m / 2.0;
        let m = case.particle_mass_kg();
        let skin = case.dem.skin_fraction * case.particles.diameter_m;
        DemParams {
            radius: r,
            mass: m,
            inertia: 0.4 * m * r * r,
            dt: case.dem.time_step_s,
            gravity: case.gravity_m_s2,
            tube_radius: case.column.diameter_m / 2.0,
            height: case.column.height_m,
            lid: case.column.lid,
            skin,
            cutoff: 2.0 * r + skin * (1.0 + NEAR_GAP),
            pair: ContactLaw::new(case, r / 2.0, m / 2.0),
            wall: ContactLaw::new(case, r, m),
            friction: case.particles.sliding_friction > 0.0,
            extra_damping: 0.0,
            work_chunks: if case.dem.reproducible { REPRODUCIBLE_CHUNKS } else { 0 },
            audit: false,
        }
    }
}
