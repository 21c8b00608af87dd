//! What a `DemSystem` can tell about itself without changing: energies, momentum, wall loads,
//! the last step's largest overlap and Coulomb excess, list sizes and counters.

use super::contact::V3;
use super::system::DemSystem;
use super::verlet_list::ListRows;

impl DemSystem {
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
        (self.outer.entries(), self.near.list.nbr.len())
    }
    /// Particle pairs touching at the last step; `None` without friction (no contact flags are
    /// kept then). For diagnostics.
    pub fn touching_pairs(&self) -> Option<usize> {
        self.p.friction.then(|| self.near.list.touch.iter().filter(|&&t| t != 0).count())
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

    /// The particle (index in the current order) with the deepest overlap now, pairs and walls,
    /// and that overlap over d: the watchdog's "where" when an overlap stops a run (O(pairs)).
    pub fn deepest_overlap(&self) -> Option<(usize, f64)> {
        let (r, x) = (self.p.radius, &self.x);
        let nl = &self.near.list;
        let mut worst: Option<(usize, f64)> = None;
        let mut keep = |k: usize, depth: f64| {
            if depth > 0.0 && worst.is_none_or(|w| depth > w.1) {
                worst = Some((k, depth));
            }
        };
        for i in 0..x.len() {
            for k in nl.offsets.get(i).map_or(0, |&o| o as usize)..nl.offsets.get(i + 1).map_or(0, |&o| o as usize) {
                let j = nl.nbr[k] as usize;
                let d = ((0..3).map(|a| (x[j][a] - x[i][a]).powi(2)).sum::<f64>()).sqrt();
                keep(i, 2.0 * r - d);
            }
            let rho = (x[i][0].powi(2) + x[i][1].powi(2)).sqrt();
            keep(i, r - x[i][2]);
            keep(i, rho + r - self.p.tube_radius);
            if self.p.lid {
                keep(i, x[i][2] + r - self.p.height);
            }
        }
        worst.map(|(k, depth)| (k, depth / (2.0 * r)))
    }
}
