//! `DemSystem`: the particle state (structure of arrays), its construction and accessors. The
//! step loop is in `step`, the upkeep of the neighbour lists in `list_upkeep`, energies, loads
//! and counters in `diagnostics`.

use super::contact::V3;
use super::forces::{Past, Scratch};
use super::kernel::Kernel;
use super::near_list::NearList;
use super::reference::RefPositions;
use super::verlet_list::VerletList;
use super::walls::WallList;
use super::DemParams;
use crate::case::Case;
use serde::{Deserialize, Serialize};

/// The complete DEM state; serde gives checkpoints with bit-identical continuation.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DemSystem {
    pub(super) p: DemParams,
    pub(super) x: Vec<V3>,
    pub(super) v: Vec<V3>,
    pub(super) w: Vec<V3>,
    pub(super) past: Past,
    /// Slot of `past` holding the newer values.
    pub(super) ring: u8,
    /// Positions at the last Verlet-list build and at the last near-list refresh.
    pub(super) x_build: RefPositions,
    pub(super) x_near: RefPositions,
    /// External forces; empty until a coupling sets them (a DEM-only scene reads none).
    pub(super) ext: Vec<V3>,
    pub(super) ids: Vec<u32>,
    /// The Verlet list (cutoff `p.cutoff`; its history arrays are emptied once the near list is
    /// drawn) and the near list drawn from it, which holds the live contact histories.
    pub(super) outer: VerletList,
    pub(super) near: NearList,
    pub(super) walls: WallList,
    /// Derivative levels held for the multistep scheme: 0 → Heun next, 2 → AB2, 3 → AB3.
    pub(super) levels: u8,
    pub(super) steps: u64,
    pub(super) time: f64,
    pub(super) frozen: bool,
    pub(super) rebuild_due: bool,
    /// Verlet-list builds and near-list refreshes so far (diagnostics).
    pub(super) builds: (u64, u64),
    /// Steps run by a team of threads (`team_step`) since creation or restore (diagnostics).
    #[serde(skip)]
    pub(super) team_steps: u64,
    pub(super) last: (f64, f64),
    /// An upper bound on the largest displacement since the last near-list refresh, grown by
    /// each step's largest move, so that the exact check against `x_near` (a pass over every
    /// position, ~3% of a step) runs only when the bound nears the refresh distance; the
    /// refreshes fall on the same steps. Unknown (+∞) after a restore, and `last_move` (the
    /// last step's largest move) 0.
    #[serde(skip, default = "unknown_bound")]
    pub(super) moved_bound: f64,
    #[serde(skip)]
    pub(super) last_move: f64,
    #[serde(skip)]
    pub(super) sc_threads: usize,
    /// Wall time of near-list refreshes and Verlet-list rebuilds (timers).
    #[serde(skip)]
    pub(super) neighbour_s: f64,
    /// Chunk plan and force buffers of the pair pass (rebuilt with the list or the pool size);
    /// a checkpoint holds the plan's cuts only.
    pub(super) sc: Scratch,
    /// The code path of the passes (`FLUIDBED_KERNEL`, else the best the CPU has).
    #[serde(skip, default = "Kernel::from_env")]
    pub(super) kernel: Kernel,
}

/// Positions, velocities (read) and external forces (written) of `DemSystem::coupling_views`.
pub type CouplingViews<'a> = (&'a [V3], &'a [V3], &'a mut [V3]);

impl DemSystem {
    /// Particles at `positions` with `velocities` (zero spin), case parameters; order is re-sorted.
    pub fn new(case: &Case, positions: Vec<[f64; 3]>, velocities: Vec<[f64; 3]>) -> Self {
        Self::with_params(DemParams::new(case), positions, velocities)
    }

    pub(super) fn with_params(p: DemParams, positions: Vec<V3>, velocities: Vec<V3>) -> Self {
        let n = positions.len();
        assert_eq!(velocities.len(), n, "one velocity per particle");
        let mut s = DemSystem {
            p,
            x: positions,
            v: velocities,
            w: vec![[0.0; 3]; n],
            past: Past::zeros(n),
            ring: 0,
            x_build: RefPositions::default(),
            x_near: RefPositions::default(),
            ext: Vec::new(),
            ids: (0..n as u32).collect(),
            outer: VerletList::default(),
            near: NearList::default(),
            walls: WallList::default(),
            levels: 0,
            steps: 0,
            time: 0.0,
            frozen: false,
            rebuild_due: false,
            builds: (0, 0),
            team_steps: 0,
            last: (0.0, f64::NEG_INFINITY),
            moved_bound: unknown_bound(),
            last_move: 0.0,
            sc_threads: 0,
            neighbour_s: 0.0,
            sc: Scratch::default(),
            kernel: Kernel::from_env(),
        };
        s.rebuild();
        s
    }

    pub fn len(&self) -> usize {
        self.x.len()
    }
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
    /// Per-particle extra force (drag, −V∇p) in the current order, held through the next step.
    pub fn external_forces_mut(&mut self) -> &mut [[f64; 3]] {
        if self.ext.len() != self.x.len() {
            self.ext = vec![[0.0; 3]; self.x.len()];
        }
        &mut self.ext
    }
    /// Positions and velocities with the external forces to be written, all in the current order.
    pub fn coupling_views(&mut self) -> CouplingViews<'_> {
        self.external_forces_mut();
        (&self.x, &self.v, &mut self.ext)
    }
    /// Wall time spent on near-list refreshes and Verlet-list rebuilds since creation (timers).
    pub fn neighbour_seconds(&self) -> f64 {
        self.neighbour_s
    }
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.x
    }
    pub fn velocities(&self) -> &[[f64; 3]] {
        &self.v
    }
    pub fn angular_velocities(&self) -> &[[f64; 3]] {
        &self.w
    }
    /// Original index of each particle in the current order.
    pub fn ids(&self) -> &[u32] {
        &self.ids
    }
    pub fn radius(&self) -> f64 {
        self.p.radius
    }
    pub fn params(&self) -> &DemParams {
        &self.p
    }
    pub fn time(&self) -> f64 {
        self.time
    }
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// The code path the passes run (the same bits on every path).
    pub fn kernel(&self) -> Kernel {
        self.kernel
    }
    /// Run the passes on `kernel` from the next step on; an error if this CPU lacks it.
    pub fn set_kernel(&mut self, kernel: Kernel) -> Result<(), String> {
        if !kernel.is_available() {
            return Err(format!("this CPU lacks the {kernel} kernel path"));
        }
        self.kernel = kernel;
        Ok(())
    }
    pub fn is_frozen(&self) -> bool {
        self.frozen
    }
    /// Frozen: `step` only advances time. Unfreezing restarts the multistep scheme (Heun first).
    pub fn set_frozen(&mut self, frozen: bool) {
        if self.frozen && !frozen {
            self.levels = 0;
        }
        self.frozen = frozen;
    }
    /// Measure the contacts' Coulomb excess from the next step on (`DemParams::audit`); the
    /// trajectory is the same either way.
    pub fn set_audit(&mut self, on: bool) {
        self.p.audit = on;
    }

    /// Replace the parameters mid-run (bed pouring stiffens the contacts in stages). The state
    /// and contact histories stay; the multistep scheme restarts (Heun) for the new step.
    pub(super) fn set_params(&mut self, p: DemParams) {
        self.p = p;
        self.levels = 0;
        self.rebuild();
    }
}

fn unknown_bound() -> f64 {
    f64::INFINITY
}
