//! `DemSystem`: the particle state (structure of arrays) and the step loop.
//! A step is: pair pass over the near list → fused particle pass (walls, gravity, external
//! force, AB update; both passes run by one team of threads, `team_step`) → near-list refresh
//! when any particle moved more than about half the near gap, with a Verlet-list rebuild and
//! re-sort first if the list could miss a near pair.

use super::contact::{dist2, V3};
use super::forces::{pair_pass, Acc, Past, Scratch, Stats};
use super::integrator::weights;
use super::kernel::Kernel;
use super::near_list::{Histories, NearList};
use super::neighbors::{build_list, cell_order, NeighborList};
use super::particle_pass::{accel_pass, update_pass, Motion, Weights};
use super::team_lock::TeamLock;
use super::team_step::{team_step, StepState};
use super::walls::WallList;
use super::DemParams;
use crate::case::Case;
use rayon::prelude::*;
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
    ring: u8,
    /// Positions at the last Verlet-list build and at the last near-list refresh.
    x_build: Vec<V3>,
    x_near: Vec<V3>,
    /// External forces; empty until a coupling sets them (a DEM-only scene reads none).
    pub(super) ext: Vec<V3>,
    pub(super) ids: Vec<u32>,
    /// The Verlet list (cutoff `p.cutoff`; its history arrays are emptied once the near list is
    /// drawn) and the near list drawn from it, which holds the live contact histories.
    pub(super) outer: NeighborList,
    pub(super) near: NearList,
    pub(super) walls: WallList,
    /// Derivative levels held for the multistep scheme: 0 → Heun next, 2 → AB2, 3 → AB3.
    levels: u8,
    steps: u64,
    time: f64,
    frozen: bool,
    rebuild_due: bool,
    /// Verlet-list builds and near-list refreshes so far (diagnostics).
    builds: (u64, u64),
    /// Steps run by a team of threads (`team_step`) since creation or restore (diagnostics).
    #[serde(skip)]
    team_steps: u64,
    last: (f64, f64),
    /// An upper bound on the largest displacement since the last near-list refresh, grown by
    /// each step's largest move, so that the exact check against `x_near` (a pass over every
    /// position, ~3% of a step) runs only when the bound nears the refresh distance; the
    /// refreshes fall on the same steps. Unknown (+∞) after a restore, and `last_move` (the
    /// last step's largest move) 0.
    #[serde(skip, default = "unknown_bound")]
    moved_bound: f64,
    #[serde(skip)]
    last_move: f64,
    /// Storage reused by near-list refreshes (the previous list's, and a code per entry).
    #[serde(skip)]
    spare: (NearList, Vec<u32>),
    #[serde(skip)]
    sc_threads: usize,
    #[serde(skip)]
    neighbour_s: f64,
    /// Chunk plan and force buffers of the pair pass (rebuilt with the list or the pool size).
    #[serde(skip)]
    sc: Scratch,
    /// The code path of the passes (`FLUIDBED_KERNEL`, else the best the CPU has).
    #[serde(skip, default = "Kernel::from_env")]
    kernel: Kernel,
}

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
            x_build: Vec::new(),
            x_near: Vec::new(),
            ext: Vec::new(),
            ids: (0..n as u32).collect(),
            outer: NeighborList::default(),
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
            spare: Default::default(),
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
    /// Verlet-list builds and near-list refreshes (without a build) so far.
    pub fn list_builds(&self) -> (u64, u64) {
        self.builds
    }
    /// Steps run by a team of threads rather than two parallel loops (see `team_step`).
    pub fn team_steps(&self) -> u64 {
        self.team_steps
    }
    /// Entries of the Verlet list and of the near list now.
    pub fn list_sizes(&self) -> (usize, usize) {
        (self.outer.nbr.len(), self.near.list.nbr.len())
    }
    /// Particle pairs touching at the last step; `None` without friction (no contact flags are
    /// kept then). For diagnostics.
    pub fn touching_pairs(&self) -> Option<usize> {
        self.p.friction.then(|| self.near.list.touch.iter().filter(|&&t| t != 0).count())
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
    /// Translational + rotational kinetic energy.
    pub fn kinetic_energy(&self) -> f64 {
        let (m, i) = (self.p.mass, self.p.inertia);
        let sq = |a: &V3| a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
        self.v.iter().map(|a| 0.5 * m * sq(a)).sum::<f64>() + self.w.iter().map(|a| 0.5 * i * sq(a)).sum::<f64>()
    }

    /// Elastic energy of the normal springs, Σ 2/5 K_n δ^{5/2} over pairs and walls.
    pub fn elastic_energy(&self) -> f64 {
        let (r, x) = (self.p.radius, &self.x);
        let mut e = 0.0;
        for i in 0..x.len() {
            let nl = &self.near.list;
            for k in nl.offsets[i] as usize..nl.offsets[i + 1] as usize {
                let j = nl.nbr[k] as usize;
                let d = ((0..3).map(|a| (x[j][a] - x[i][a]).powi(2)).sum::<f64>()).sqrt();
                e += self.p.pair.elastic_energy((2.0 * r - d).max(0.0));
            }
            let rho = (x[i][0].powi(2) + x[i][1].powi(2)).sqrt();
            let mut walls = vec![r - x[i][2], rho + r - self.p.tube_radius];
            if self.p.lid {
                walls.push(x[i][2] + r - self.p.height);
            }
            e += walls.into_iter().map(|d| self.p.wall.elastic_energy(d.max(0.0))).sum::<f64>();
        }
        e
    }

    /// Vertical force of the plate, the tube and the lid on the particles now (`walls::wall_loads`).
    pub fn wall_loads(&self) -> [f64; 3] {
        super::walls::wall_loads(&self.p, &self.x, &self.v, &self.w, &self.walls)
    }

    /// External (gas) force summed over the particles.
    pub fn external_force_total(&self) -> V3 {
        self.ext.iter().fold([0.0; 3], |a, f| [a[0] + f[0], a[1] + f[1], a[2] + f[2]])
    }

    /// Total linear momentum of the particles.
    pub fn momentum(&self) -> V3 {
        let m = self.p.mass;
        self.v.iter().fold([0.0; 3], |a, u| [a[0] + m * u[0], a[1] + m * u[1], a[2] + m * u[2]])
    }

    /// Largest overlap over the diameter in the last step (pairs and walls).
    pub fn max_overlap_fraction(&self) -> f64 {
        self.last.0 / (2.0 * self.p.radius)
    }

    /// Largest (|F_t|² − (μ F_n)²) / (μ F_n)² over all contacts in the last step (≤ round-off
    /// when the Coulomb limit holds: ~1e-16 for walls, ~1e-6 for the single-precision pair law;
    /// −∞ without frictional contacts, and unless `set_audit(true)`). For tests and diagnostics.
    pub fn max_coulomb_excess(&self) -> f64 {
        self.last.1
    }

    /// Measure the contacts' Coulomb excess from the next step on (`DemParams::audit`); the
    /// trajectory is the same either way.
    pub fn set_audit(&mut self, on: bool) {
        self.p.audit = on;
    }

    /// One DEM step of the case's time step (uses the current rayon pool).
    pub fn step(&mut self) {
        let team = TeamLock::try_take();
        self.step_with(team.as_ref());
    }

    /// One step; with the team lock (held by the caller) the pair and particle passes run as
    /// one team of threads (`team_step`), without it as two parallel loops (another system
    /// holds the team: nested or concurrent use of the pool). The same bits either way.
    pub fn step_with(&mut self, team: Option<&TeamLock>) {
        if !self.frozen && !self.x.is_empty() {
            if self.p.friction {
                self.advance::<true>(team);
            } else {
                self.advance::<false>(team);
            }
        }
        self.steps += 1;
        self.time += self.p.dt;
    }

    fn advance<const FR: bool>(&mut self, team: Option<&TeamLock>) {
        let chunks = if self.p.work_chunks > 0 { self.p.work_chunks } else { 2 * rayon::current_num_threads() };
        if self.sc.bounds.is_empty() || self.sc_threads != chunks {
            self.sc.replan(&self.near.list, self.x.len(), chunks);
            self.sc_threads = chunks;
        }
        let limit = self.p.near_move();
        let refresh_disp2 = limit * limit;
        // Measure exactly when the bound, grown by twice the last step's move, could pass the
        // limit; a step whose move exceeds that is measured after it (below).
        let safe = limit * (1.0 - 1e-9);
        let exact = self.levels == 0 || self.moved_bound + 2.0 * SQRT_3 * self.last_move >= safe;
        let x_ref = if exact { &self.x_near[..] } else { &[] };
        let st = if self.levels == 0 {
            let st1 =
                pair_pass::<FR>(&self.p, (&self.x, &self.v, &self.w), &mut self.near.list, &mut self.sc, self.kernel);
            let st = st1.max(self.heun::<FR>());
            self.sc.bounds.clear(); // replanned at the next step, now with the contacts' flags
            st
        } else {
            let h = self.p.dt;
            let b = weights(self.levels);
            let step = Weights { hb: [h * b[0], h * b[1], h * b[2]], ring: self.ring as usize };
            let st = match team {
                Some(_) => {
                    let s = StepState {
                        x: &mut self.x,
                        v: &mut self.v,
                        w: &mut self.w,
                        past: &mut self.past,
                        walls: &mut self.walls,
                        nl: &mut self.near.list,
                        sc: &mut self.sc,
                    };
                    self.team_steps += 1;
                    team_step::<FR>(self.kernel, &self.p, step, s, x_ref, &self.ext)
                }
                // Two parallel loops, which cannot wait on another team's threads.
                None => {
                    let state = (&self.x[..], &self.v[..], &self.w[..]);
                    let st1 = pair_pass::<FR>(&self.p, state, &mut self.near.list, &mut self.sc, self.kernel);
                    let m = Motion {
                        x: &mut self.x,
                        v: &mut self.v,
                        w: &mut self.w,
                        past: &mut self.past,
                        x_ref,
                        walls: &mut self.walls,
                    };
                    st1.max(update_pass::<FR>(self.kernel, &self.p, step, m, &self.ext, self.sc.sums()))
                }
            };
            self.ring = 1 - self.ring;
            self.levels = (self.levels + 1).min(3);
            st
        };
        self.last = (st.overlap, st.coulomb_excess);
        self.last_move = st.moved;
        let (disp2, measured) = if exact {
            (st.disp2, true)
        } else {
            // |Δx| ≤ √3 (max |Δx_k| + rounding of the new coordinate, ≤ ε/2 of it).
            let grown = self.moved_bound + SQRT_3 * (st.moved + 0.5 * f64::EPSILON * st.extent) * (1.0 + 1e-12);
            if grown < safe {
                self.moved_bound = grown;
                (0.0, false) // below the limit (and so below the exact check's result) for certain
            } else {
                (self.largest_disp2(), true)
            }
        };
        if measured {
            // The computed distance is within a few ε of the true one.
            self.moved_bound = disp2.sqrt() * (1.0 + 1e-12);
        }
        if disp2 > refresh_disp2 || self.rebuild_due {
            let t0 = std::time::Instant::now();
            if disp2 > refresh_disp2 {
                self.refresh();
            }
            if self.rebuild_due {
                self.rebuild();
            }
            self.neighbour_s += t0.elapsed().as_secs_f64();
        }
    }

    /// Redraw the near list from the Verlet list, rebuilding that first if a particle has moved
    /// far enough since its build that it might miss a pair closer than d + near gap.
    fn refresh(&mut self) {
        let reach = self.p.outer_move();
        let moved = self.x.iter().zip(&self.x_build).any(|(&a, &b)| dist2(a, b) > reach * reach);
        if moved {
            self.rebuild_due = true;
            return;
        }
        let (spare, code) = &mut self.spare;
        spare.select_into(
            &self.outer,
            &self.x,
            2.0 * self.p.radius,
            self.p.near_gap(),
            Histories::Near(&self.near),
            code,
        );
        std::mem::swap(&mut self.near, spare);
        self.sc.bounds.clear(); // replanned for the new list at the next step
        self.x_near.clone_from(&self.x);
        self.moved_bound = 0.0;
        self.builds.1 += 1;
    }

    /// The displacement bound and the largest displacement since the last refresh (tests).
    #[cfg(test)]
    pub(super) fn moved_bound_and_largest(&self) -> (f64, f64) {
        (self.moved_bound, self.largest_disp2().sqrt())
    }

    /// The largest squared displacement since the last refresh (as the particle pass measures it).
    fn largest_disp2(&self) -> f64 {
        self.x.par_iter().zip(&self.x_near).map(|(&a, &b)| dist2(a, b)).reduce(|| 0.0, f64::max)
    }

    /// First step: Heun (Euler predictor, trapezoid corrector; two force evaluations). The
    /// contact histories keep the values of the first evaluation (they are integrated by Euler).
    fn heun<const FR: bool>(&mut self) -> Stats {
        let n = self.x.len();
        let h = self.p.dt;
        let mut d0: Vec<Acc> = vec![[0.0; 6]; n];
        let st =
            accel_pass::<FR>(&self.p, (&self.x, &self.v, &self.w), &mut self.walls, &self.ext, self.sc.sums(), &mut d0);
        let (x0, v0, w0) = (self.x.clone(), self.v.clone(), self.w.clone());
        let nl = &self.near.list;
        let (shear1, touch1, walls1) = (nl.shear.clone(), nl.touch.clone(), self.walls.clone());
        let step = |y: &V3, f: &[f64], c: f64| [y[0] + c * f[0], y[1] + c * f[1], y[2] + c * f[2]];
        for i in 0..n {
            self.x[i] = step(&x0[i], &v0[i], h);
            self.v[i] = step(&v0[i], &d0[i][..3], h);
            self.w[i] = step(&w0[i], &d0[i][3..], h);
        }
        pair_pass::<FR>(&self.p, (&self.x, &self.v, &self.w), &mut self.near.list, &mut self.sc, self.kernel);
        let mut d1: Vec<Acc> = vec![[0.0; 6]; n];
        accel_pass::<FR>(&self.p, (&self.x, &self.v, &self.w), &mut self.walls, &self.ext, self.sc.sums(), &mut d1);
        (self.near.list.shear, self.near.list.touch, self.walls) = (shear1, touch1, walls1);
        let newer = 1 - self.ring as usize;
        for i in 0..n {
            let vs = self.v[i];
            self.x[i] = step(&step(&x0[i], &v0[i], 0.5 * h), &vs, 0.5 * h);
            self.v[i] = step(&step(&v0[i], &d0[i][..3], 0.5 * h), &d1[i][..3], 0.5 * h);
            if FR {
                self.w[i] = step(&step(&w0[i], &d0[i][3..], 0.5 * h), &d1[i][3..], 0.5 * h);
            }
            let q = &mut self.past;
            q.v[newer][i] = v0[i];
            q.a[newer][i] = [d0[i][0], d0[i][1], d0[i][2]];
            q.alpha[newer][i] = [d0[i][3], d0[i][4], d0[i][5]];
        }
        self.ring = newer as u8;
        self.levels = 2;
        Stats { disp2: self.largest_disp2(), ..st }
    }

    /// Replace the parameters mid-run (bed pouring stiffens the contacts in stages). The state
    /// and contact histories stay; the multistep scheme restarts (Heun) for the new step.
    pub(super) fn set_params(&mut self, p: DemParams) {
        self.p = p;
        self.levels = 0;
        self.rebuild();
    }

    /// Re-sort particles by linked cell, rebuild the Verlet list, carry contact history by id,
    /// draw the near list.
    fn rebuild(&mut self) {
        let order = cell_order(&self.x, self.p.tube_radius, self.p.cutoff);
        let perm = |src: &Vec<V3>| -> Vec<V3> { order.iter().map(|&o| src[o as usize]).collect() };
        self.x = perm(&self.x);
        self.v = perm(&self.v);
        self.w = perm(&self.w);
        if !self.ext.is_empty() {
            self.ext = perm(&self.ext);
        }
        self.past.permute(&order);
        let old_ids = std::mem::take(&mut self.ids);
        self.ids = order.iter().map(|&o| old_ids[o as usize]).collect();
        let diameter = 2.0 * self.p.radius;
        let mut nl = build_list(&self.x, self.p.tube_radius, self.p.cutoff, diameter);
        if self.p.friction {
            nl.carry_history(&self.near.list, &old_ids, &self.ids);
        }
        let (spare, code) = &mut self.spare;
        spare.select_into(&nl, &self.x, diameter, self.p.near_gap(), Histories::Outer, code);
        std::mem::swap(&mut self.near, spare);
        (nl.shear, nl.touch) = (Vec::new(), Vec::new());
        self.outer = nl;
        let had_walls = !self.x_build.is_empty();
        self.walls = WallList::build(&self.p, &self.x, &self.walls, had_walls.then_some(&order[..]));
        self.sc.bounds.clear(); // replanned for the new list at the next step
        self.x_build.clone_from(&self.x);
        self.x_near.clone_from(&self.x);
        self.moved_bound = 0.0;
        self.rebuild_due = false;
        self.builds.0 += 1;
    }
}

/// Positions, velocities (read) and external forces (written) of `DemSystem::coupling_views`.
pub type CouplingViews<'a> = (&'a [V3], &'a [V3], &'a mut [V3]);

/// √3, rounded up (the bound's factor from the largest component to the length).
const SQRT_3: f64 = 1.7320508075688774;

fn unknown_bound() -> f64 {
    f64::INFINITY
}
