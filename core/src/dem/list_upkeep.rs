//! Keeping the neighbour lists valid as the particles move: the near list redrawn from the
//! Verlet list, the Verlet list rebuilt (with a re-sort by cell and the contact histories
//! carried by particle id) when a particle could have moved past its skin (`near_list`).

use super::id_histories::IdHistories;
use super::near_list::Histories;
use super::neighbors::cell_order;
use super::system::DemSystem;
use super::verlet_list::VerletList;
use super::walls::WallList;
use rayon::prelude::*;

impl DemSystem {
    /// Redraw the near list from the Verlet list, rebuilding that first if a particle has moved
    /// far enough since its build that it might miss a pair closer than d + near gap.
    pub(super) fn refresh(&mut self) {
        let reach = self.p.outer_move();
        if self.x_build.any_beyond(&self.x, reach) {
            self.rebuild_due = true;
            return;
        }
        self.near.refresh(&self.outer, &self.x, 2.0 * self.p.radius, self.p.near_gap());
        self.sc.bounds.clear(); // replanned for the new list at the next step
        self.x_near.store(&self.x);
        self.moved_bound = self.x_near.err; // a bound on the measured distance too
        self.builds.1 += 1;
    }

    /// The displacement bound and the largest displacement since the last refresh (tests).
    #[cfg(test)]
    pub(super) fn moved_bound_and_largest(&self) -> (f64, f64) {
        (self.moved_bound, self.largest_disp2().sqrt())
    }

    /// The largest squared displacement since the last refresh (as the particle pass measures it).
    pub(super) fn largest_disp2(&self) -> f64 {
        self.x_near.largest_disp2(&self.x)
    }

    /// Re-sort particles by linked cell, rebuild the Verlet list, carry contact history by id,
    /// draw the near list.
    pub(super) fn rebuild(&mut self) {
        let order = cell_order(&self.x, self.p.tube_radius, self.p.cutoff);
        // Each array is gathered into the storage the previous one left, not into fresh pages
        // (which fault in at first touch: docs/BENCHMARKS.md, "Scaling", Decisions).
        let mut spare = Vec::new();
        for a in [&mut self.x, &mut self.v, &mut self.w, &mut self.ext] {
            if !a.is_empty() {
                permuted(a, &order, &mut spare);
            }
        }
        let mut spare = Vec::new();
        for s in self.past.slots_mut() {
            permuted(s, &order, &mut spare);
        }
        let old_ids = std::mem::take(&mut self.ids);
        self.ids = order.par_iter().map(|&o| old_ids[o as usize]).collect();
        let diameter = 2.0 * self.p.radius;
        self.outer = Default::default(); // the old list is not read again
        let outer = VerletList::build(&self.x, self.p.tube_radius, self.p.cutoff, diameter);
        let carried = if self.p.friction { IdHistories::of(&self.near.list, &old_ids) } else { Default::default() };
        // The old near list's storage takes the new one (its histories are carried by now).
        let hist = Histories::Carried(&carried, &self.ids);
        self.near.select_into(&outer, &self.x, diameter, self.p.near_gap(), hist);
        self.outer = outer;
        let had_walls = !self.x_build.is_empty();
        self.walls = WallList::build(&self.p, &self.x, &self.walls, had_walls.then_some(&order[..]));
        self.sc.bounds.clear(); // replanned for the new list at the next step
        self.x_build.store(&self.x);
        self.x_near.store(&self.x);
        self.moved_bound = self.x_near.err; // a bound on the measured distance too
        self.rebuild_due = false;
        self.builds.0 += 1;
    }
}

/// `a` in the order `order` (a[i] becomes the old a[order[i]]), gathered into `spare`'s storage;
/// `spare` takes the old storage.
fn permuted<T: Copy + Send + Sync>(a: &mut Vec<T>, order: &[u32], spare: &mut Vec<T>) {
    spare.clear();
    spare.par_extend(order.par_iter().map(|&o| a[o as usize]));
    std::mem::swap(a, spare);
}
