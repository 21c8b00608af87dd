//! The DEM step loop. A step is: pair pass over the near list → fused particle pass (walls,
//! gravity, external force, AB update; both passes run by one team of threads, `team_step`) →
//! near-list refresh when any particle moved more than about half the near gap, with a
//! Verlet-list rebuild and re-sort first if the list could miss a near pair (`list_upkeep`).
//! The first step after a start or a change of parameters is Heun's (PHYSICS.md 7).

use super::contact::V3;
use super::forces::{narrow, pair_pass, pair_pass_with, widen, PastV3, Stats, KEEP_PIECE_ROWS};
use super::integrator::weights;
use super::particle_pass::{accel_pass, update_pass, Motion, Weights};
use super::system::DemSystem;
use super::team_step::{team_step, StepState};
use crate::team::TeamLock;

impl DemSystem {
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

    pub(super) fn advance<const FR: bool>(&mut self, team: Option<&TeamLock>) {
        let chunks = if self.p.work_chunks > 0 { self.p.work_chunks } else { 2 * rayon::current_num_threads() };
        if self.sc.bounds.is_empty() || self.sc_threads != chunks {
            self.sc.replan(&self.near.list, self.x.len(), chunks);
            self.sc_threads = chunks;
        }
        let limit = self.p.near_move();
        // Measure exactly when the bound, grown by twice the last step's move, could pass the
        // limit; a step whose move exceeds that is measured after it (below).
        let safe = limit * (1.0 - 1e-9);
        let exact = self.levels == 0 || self.moved_bound + 2.0 * SQRT_3 * self.last_move >= safe;
        let x_ref = if exact { &self.x_near.x[..] } else { &[] };
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
        let mut due = false;
        if measured {
            // The computed distance is within a few ε, and the stored position's rounding, of
            // the true one.
            self.moved_bound = (disp2.sqrt() + self.x_near.err) * (1.0 + 1e-12);
            due = self.moved_bound > limit;
        }
        if due || self.rebuild_due {
            let t0 = std::time::Instant::now();
            if due {
                self.refresh();
            }
            if self.rebuild_due {
                self.rebuild();
            }
            self.neighbour_s += t0.elapsed().as_secs_f64();
        }
    }

    /// First step: Heun (Euler predictor, trapezoid corrector; two force evaluations). The
    /// contact histories keep the values of the first evaluation (they are integrated by Euler).
    /// The derivatives live in the past slots: the first evaluation's in the newer slot (the
    /// next step's history), the second's in the older (which the next step's AB2 does not read),
    /// and the corrector adds h/2 (f₁ − f₀) to the predicted state, so the step needs no arrays
    /// of its own beyond a copy of the wall list and, in the second evaluation, of the contact
    /// histories of the pair-pass chunks in flight.
    pub(super) fn heun<const FR: bool>(&mut self) -> Stats {
        let n = self.x.len();
        let h = self.p.dt;
        let newer = 1 - self.ring as usize;
        let q = &mut self.past;
        let (a0, a1) = split_slots(&mut q.a, newer);
        let (al0, al1) = split_slots(&mut q.alpha, newer);
        let st = accel_pass::<FR>(
            &self.p,
            (&self.x, &self.v, &self.w),
            &mut self.walls,
            &self.ext,
            self.sc.sums(),
            (a0, al0),
        );
        let v0 = &mut q.v[newer];
        let walls1 = self.walls.clone();
        let step = |y: &mut V3, f: [f64; 3], c: f64| {
            for k in 0..3 {
                y[k] += c * f[k];
            }
        };
        for i in 0..n {
            v0[i] = narrow(self.v[i]);
            let vi = self.v[i];
            step(&mut self.x[i], vi, h);
            step(&mut self.v[i], widen(a0[i]), h);
            step(&mut self.w[i], widen(al0[i]), h);
        }
        let state = (&self.x[..], &self.v[..], &self.w[..]);
        pair_pass_with::<FR>(&self.p, state, &mut self.near.list, &mut self.sc, self.kernel, Some(KEEP_PIECE_ROWS));
        accel_pass::<FR>(&self.p, (&self.x, &self.v, &self.w), &mut self.walls, &self.ext, self.sc.sums(), (a1, al1));
        self.walls = walls1;
        // f₁ − f₀, the first evaluation's as stored.
        let diff = |f1: V3, f0: PastV3| [0, 1, 2].map(|k| f1[k] - f0[k] as f64);
        for i in 0..n {
            let vs = self.v[i];
            step(&mut self.x[i], diff(vs, v0[i]), 0.5 * h);
            step(&mut self.v[i], diff(widen(a1[i]), a0[i]), 0.5 * h);
            if FR {
                step(&mut self.w[i], diff(widen(al1[i]), al0[i]), 0.5 * h);
            }
        }
        self.ring = newer as u8;
        self.levels = 2;
        Stats { disp2: self.largest_disp2(), ..st }
    }
}

/// The (newer, older) slots of a past derivative, `newer` being the slot index of the newer.
fn split_slots(s: &mut [Vec<PastV3>; 2], newer: usize) -> (&mut [PastV3], &mut [PastV3]) {
    let [s0, s1] = s;
    if newer == 0 {
        (s0, s1)
    } else {
        (s1, s0)
    }
}

/// √3, rounded up (the bound's factor from the largest component to the length).
const SQRT_3: f64 = 1.7320508075688774;
