//! Particle–gas force exchange (paper section 2.3; model A of PHYSICS.md 11).
//!
//! Each particle feels −V_p∇p + F_d, with F_d the Beetstra drag built on the gas velocity,
//! density, voidage and pressure gradient of the cell holding its centre. The cylindrical gas
//! vectors are turned into Cartesian ones at the particle's own angle (paper: "converted to
//! rectangular velocities at the position of the particle"). The gas in that cell receives
//! I = −Σ F_d / V_cell, given in the cylindrical components of the cell centre's basis (the basis
//! in which the finite-volume solver holds that cell's momentum): this keeps Σ_particles F_d =
//! −Σ_cells R(θ_c)·I·V_cell to round-off, whereas the particle's basis would rotate each
//! contribution by up to half a cell width (±60° in the central annulus).

use super::drag::drag_force;
use crate::grid::CylGrid;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Gas state per fluid cell, as the exchange reads it.
pub struct GasAtCells<'a> {
    /// Interstitial gas velocity (U_r, U_θ, U_z).
    pub velocity_cyl: &'a [[f64; 3]],
    pub density: &'a [f64],
    /// (∂p/∂r, (1/r)∂p/∂θ, ∂p/∂z).
    pub grad_p_cyl: &'a [[f64; 3]],
    pub voidage: &'a [f64],
}

/// Cylindrical (radial, angular, axial) components at angle θ → Cartesian.
#[inline]
pub fn cyl_to_cart(v: [f64; 3], cos: f64, sin: f64) -> [f64; 3] {
    [v[0] * cos - v[1] * sin, v[0] * sin + v[1] * cos, v[2]]
}

/// Cartesian → cylindrical components at angle θ.
#[inline]
pub fn cart_to_cyl(v: [f64; 3], cos: f64, sin: f64) -> [f64; 3] {
    [v[0] * cos + v[1] * sin, -v[0] * sin + v[1] * cos, v[2]]
}

/// (cos θ, sin θ) of the particle's angle; 1, 0 on the axis.
#[inline]
fn angle_of(x: f64, y: f64) -> (f64, f64) {
    let r = (x * x + y * y).sqrt();
    if r > 0.0 {
        (x / r, y / r)
    } else {
        (1.0, 0.0)
    }
}

/// The exchange's work arrays and per-cell basis angles, allocated once per run.
pub struct Exchange {
    /// (cos θ_c, sin θ_c) of each in-layer cell's centre angle.
    cell_basis: Vec<(f64, f64)>,
    /// Cell of each particle's centre (also the next call's hint) and its drag in that cell's
    /// basis, from the parallel pass.
    cell_of: Vec<u32>,
    drag_cyl: Vec<[f64; 3]>,
    /// Frozen beds: per cell, particle count and Σcos, Σsin of (θ_p − θ_c) (see `frozen_cell_forces`).
    frozen: Vec<(f64, f64, f64)>,
    /// Beetstra's per-cell factors, refreshed each call.
    cell_drag: Vec<CellDrag>,
}

/// Everything in the drag law that depends on the cell only (PHYSICS.md 1.1 with ε clamped), so
/// that a particle pays one ln and two exp instead of three powf:
/// F = F₀ + b·Re·(c + 8.4 Re^−0.343)/(1 + p10·Re^e1), F_d = k·F·(u − v), Re = re_per_w·|u − v|.
#[derive(Clone, Copy, Default)]
struct CellDrag {
    k: f64,
    f0: f64,
    b: f64,
    c: f64,
    p10: f64,
    e1: f64,
    re_per_w: f64,
}

impl CellDrag {
    fn new(mu: f64, rho: f64, d: f64, eps: f64, eps_min: f64) -> CellDrag {
        let eps = eps.clamp(eps_min, 1.0 - f64::EPSILON);
        let phi = 1.0 - eps;
        CellDrag {
            k: 3.0 * PI * mu * d * eps,
            f0: 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * phi.max(0.0).sqrt()),
            b: 0.413 / (24.0 * eps * eps),
            c: 1.0 / eps + 3.0 * eps * phi,
            p10: 10f64.powf(3.0 * phi),
            e1: -(1.0 + 4.0 * phi) / 2.0,
            re_per_w: rho * eps * d / mu,
        }
    }
    #[inline]
    fn force(&self, slip: [f64; 3]) -> [f64; 3] {
        let w = (slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2]).sqrt();
        let re = self.re_per_w * w;
        let f = if re < 1e-12 {
            self.f0
        } else {
            let l = re.ln();
            self.f0 + self.b * re * (self.c + 8.4 * (-0.343 * l).exp()) / (1.0 + self.p10 * (self.e1 * l).exp())
        };
        let kf = self.k * f;
        [kf * slip[0], kf * slip[1], kf * slip[2]]
    }
}

impl Exchange {
    pub fn new(grid: &CylGrid, particles: usize) -> Exchange {
        let mut cell_basis = Vec::with_capacity(grid.cells_per_layer());
        for i in 0..grid.nr {
            for j in 0..grid.cells_in_annulus(i) {
                let th = grid.centre_polar(i, j).1;
                cell_basis.push((th.cos(), th.sin()));
            }
        }
        Exchange {
            cell_basis,
            cell_of: vec![0; particles],
            drag_cyl: vec![[0.0; 3]; particles],
            frozen: Vec::new(),
            cell_drag: Vec::new(),
        }
    }

    /// Fluid force on every particle (Cartesian, −V_p∇p + drag) into `force_out`, and the
    /// interaction force per unit volume on the gas, I = −Σ drag / V_cell (cylindrical,
    /// cell-centre basis), into `cell_force_out` (overwritten). `d` is the particle diameter; ε is
    /// clamped to [eps_min, 1). No allocation.
    #[allow(clippy::too_many_arguments)]
    pub fn particle_gas_forces(
        &mut self,
        grid: &CylGrid,
        gas: &GasAtCells,
        mu: f64,
        eps_min: f64,
        d: f64,
        pos: &[[f64; 3]],
        vel: &[[f64; 3]],
        force_out: &mut [[f64; 3]],
        cell_force_out: &mut [[f64; 3]],
    ) {
        assert_eq!(pos.len(), vel.len());
        assert_eq!(pos.len(), force_out.len());
        assert_eq!(cell_force_out.len(), grid.num_cells());
        self.cell_of.resize(pos.len(), 0);
        self.drag_cyl.resize(pos.len(), [0.0; 3]);
        let vp = PI * d * d * d / 6.0;
        self.cell_drag.resize(grid.num_cells(), CellDrag::default());
        for (c, cd) in self.cell_drag.iter_mut().enumerate() {
            *cd = CellDrag::new(mu, gas.density[c], d, gas.voidage[c], eps_min);
        }
        let (cell_drag, basis, per) = (&self.cell_drag, &self.cell_basis, grid.cells_per_layer());
        // 1. per particle (parallel): its cell, the drag, and the total force −V_p∇p + drag, with
        //    the gas vectors turned to Cartesian at the particle's own angle (paper section 2.3);
        //    the drag also in the basis of its cell's centre, for the gas
        (force_out, &mut self.drag_cyl[..], &mut self.cell_of[..])
            .into_par_iter()
            .zip(pos.par_iter().zip(vel.par_iter()))
            .for_each(|((f, dc, co), (p, v))| {
                // The cell of the last call is a hint (particles move little; after a re-sort
                // the hint is another particle's and `locate_near` falls back to `locate`).
                let c = grid.locate_near(p[0], p[1], p[2], *co as usize);
                let lc = c % per;
                let (cos, sin) = angle_of(p[0], p[1]);
                let u = cyl_to_cart(gas.velocity_cyl[c], cos, sin);
                let slip = [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
                let dr = cell_drag[c].force(slip);
                let g = cyl_to_cart(gas.grad_p_cyl[c], cos, sin);
                *f = [dr[0] - vp * g[0], dr[1] - vp * g[1], dr[2] - vp * g[2]];
                let (cc, sc) = basis[lc];
                *dc = cart_to_cyl(dr, cc, sc);
                *co = c as u32;
            });
        // 2. the gas loses the drag in the cell of the particle's centre (serial, fixed order:
        //    deterministic)
        cell_force_out.iter_mut().for_each(|f| *f = [0.0; 3]);
        let inv_v = 1.0 / grid.cell_volume();
        for (fc, &c) in self.drag_cyl.iter().zip(&self.cell_of) {
            let out = &mut cell_force_out[c as usize];
            for m in 0..3 {
                out[m] -= fc[m] * inv_v;
            }
        }
    }

    /// Remember a frozen bed (particles at rest for the whole run) for `frozen_cell_forces`.
    pub fn freeze(&mut self, grid: &CylGrid, pos: &[[f64; 3]]) {
        self.frozen = vec![(0.0, 0.0, 0.0); grid.num_cells()];
        let per = grid.cells_per_layer();
        for p in pos {
            let c = grid.locate(p[0], p[1], p[2]);
            let (cp, sp) = angle_of(p[0], p[1]);
            let (cc, sc) = self.cell_basis[c % per];
            let e = &mut self.frozen[c];
            // cos and sin of θ_p − θ_c
            *e = (e.0 + 1.0, e.1 + cp * cc + sp * sc, e.2 + sp * cc - cp * sc);
        }
    }

    /// The gas side of the exchange for a frozen bed, in O(cells): every particle of a cell is at
    /// rest and sees the same gas state, so its drag differs only by the rotation θ_p − θ_c of the
    /// cell's velocity; summed, I_c = −D(|u_c|)·(C u_r − S u_θ, S u_r + C u_θ, N u_z)/V_cell with
    /// N, C = Σcos, S = Σsin over the cell's particles. Equal to `Exchange::particle_gas_forces`' gas side
    /// to round-off; the particles' own forces are not needed (they do not move).
    pub fn frozen_cell_forces(
        &self,
        grid: &CylGrid,
        gas: &GasAtCells,
        mu: f64,
        eps_min: f64,
        d: f64,
        cell_force_out: &mut [[f64; 3]],
    ) {
        assert_eq!(self.frozen.len(), grid.num_cells(), "freeze() first");
        let inv_v = 1.0 / grid.cell_volume();
        for (c, (f, &(n, cs, sn))) in cell_force_out.iter_mut().zip(&self.frozen).enumerate() {
            if n == 0.0 {
                *f = [0.0; 3];
                continue;
            }
            let u = gas.velocity_cyl[c];
            // drag_force is linear in the slip at fixed |slip|: its coefficient from a unit call
            let k = drag_force(mu, gas.density[c], d, gas.voidage[c], eps_min, u);
            let w = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let coef = if w > 0.0 {
                (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt() / w
            } else {
                drag_force(mu, gas.density[c], d, gas.voidage[c], eps_min, [0.0, 0.0, 1.0])[2]
            };
            *f = [
                -coef * (cs * u[0] - sn * u[1]) * inv_v,
                -coef * (sn * u[0] + cs * u[1]) * inv_v,
                -coef * n * u[2] * inv_v,
            ];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::drag::beetstra_f;
    use super::*;
    use rand::{Rng, SeedableRng};

    fn grid() -> CylGrid {
        CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3)
    }

    #[test]
    fn cylindrical_cartesian_round_trip() {
        let th: f64 = 2.1;
        let (c, s) = (th.cos(), th.sin());
        // a purely radial unit vector at θ is (cos θ, sin θ); a purely angular one (−sin θ, cos θ)
        let r = cyl_to_cart([1.0, 0.0, 0.0], c, s);
        let t = cyl_to_cart([0.0, 1.0, 0.0], c, s);
        assert!((r[0] - c).abs() < 1e-15 && (r[1] - s).abs() < 1e-15);
        assert!((t[0] + s).abs() < 1e-15 && (t[1] - c).abs() < 1e-15);
        let v = [0.3, -1.7, 2.0];
        let back = cart_to_cyl(cyl_to_cart(v, c, s), c, s);
        for m in 0..3 {
            assert!((back[m] - v[m]).abs() < 1e-15);
        }
    }

    #[test]
    fn uniform_field_gives_the_analytic_force() {
        let g = grid();
        let n = g.num_cells();
        let (mu, rho, eps, d, u, dpdz) = (1.8e-5, 1.204, 0.55, 1.2e-3, 0.8, -5000.0);
        let vel_c = vec![[0.0, 0.0, u]; n];
        let dens = vec![rho; n];
        let grad = vec![[0.0, 0.0, dpdz]; n];
        let void = vec![eps; n];
        let gas = GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void };
        let pos = vec![[0.003, -0.007, 0.005], [0.0, 0.0, 0.001], [-0.015, 0.01, 0.012]];
        let vel = vec![[0.1, 0.0, 0.2], [0.0, 0.0, 0.0], [0.0, -0.3, -0.1]];
        let mut f = vec![[0.0; 3]; 3];
        let mut cf = vec![[0.0; 3]; n];
        Exchange::new(&g, pos.len()).particle_gas_forces(&g, &gas, mu, 0.1, d, &pos, &vel, &mut f, &mut cf);
        let vp = PI * d * d * d / 6.0;
        for k in 0..3 {
            let w = [-vel[k][0], -vel[k][1], u - vel[k][2]];
            let wm = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            let re = rho * eps * wm * d / mu;
            let c = 3.0 * PI * mu * d * eps * beetstra_f(eps, re);
            let want = [c * w[0], c * w[1], c * w[2] - vp * dpdz];
            for m in 0..3 {
                assert!((f[k][m] - want[m]).abs() < 1e-12 * want[2].abs(), "particle {k}: {:?} vs {want:?}", f[k]);
            }
        }
    }

    #[test]
    fn momentum_is_conserved_between_the_phases() {
        let g = grid();
        let n = g.num_cells();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let vel_c: Vec<[f64; 3]> =
            (0..n).map(|_| [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0)]).collect();
        let dens: Vec<f64> = (0..n).map(|_| rng.gen_range(1.1..1.3)).collect();
        let grad: Vec<[f64; 3]> =
            (0..n).map(|_| [rng.gen_range(-50.0..50.0), rng.gen_range(-50.0..50.0), -6000.0]).collect();
        let void: Vec<f64> = (0..n).map(|_| rng.gen_range(0.35..1.0)).collect();
        let gas = GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void };
        let m = 5000;
        let pos: Vec<[f64; 3]> = (0..m)
            .map(|_| {
                let (r, t) = (0.021 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
            })
            .collect();
        let vel: Vec<[f64; 3]> =
            (0..m).map(|_| [rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5)]).collect();
        let (mut f, mut cf) = (vec![[0.0; 3]; m], vec![[0.0; 3]; n]);
        let d = 1.2e-3;
        Exchange::new(&g, pos.len()).particle_gas_forces(&g, &gas, 1.8e-5, 0.1, d, &pos, &vel, &mut f, &mut cf);
        // Σ drag on particles (total force minus −V_p∇p) against −Σ I·V_cell in Cartesian
        let vp = PI * d * d * d / 6.0;
        let mut drag = [0.0; 3];
        let mut scale = 0.0f64;
        for (k, p) in pos.iter().enumerate() {
            let c = g.locate(p[0], p[1], p[2]);
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
            let gp = cyl_to_cart(grad[c], p[0] / r, p[1] / r);
            for q in 0..3 {
                let dq = f[k][q] + vp * gp[q];
                drag[q] += dq;
                scale = scale.max(dq.abs());
            }
        }
        let mut gas_side = [0.0; 3];
        for (c, i_cyl) in cf.iter().enumerate() {
            let (i, j, _) = g.ijk(c);
            let th = g.centre_polar(i, j).1;
            let v = cyl_to_cart(*i_cyl, th.cos(), th.sin());
            for q in 0..3 {
                gas_side[q] += v[q] * g.cell_volume();
            }
        }
        for q in 0..3 {
            assert!((drag[q] + gas_side[q]).abs() < 1e-12 * scale * m as f64, "{q}: {} vs {}", drag[q], gas_side[q]);
        }
    }

    #[test]
    fn frozen_shortcut_equals_the_particle_sum() {
        let g = grid();
        let n = g.num_cells();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let vel_c: Vec<[f64; 3]> =
            (0..n).map(|_| [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0)]).collect();
        let dens: Vec<f64> = (0..n).map(|_| rng.gen_range(1.1..1.3)).collect();
        let grad = vec![[0.0, 0.0, -5000.0]; n];
        let void: Vec<f64> = (0..n).map(|_| rng.gen_range(0.35..1.0)).collect();
        let gas = GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void };
        let pos: Vec<[f64; 3]> = (0..3000)
            .map(|_| {
                let (r, t) = (0.021 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
            })
            .collect();
        let vel = vec![[0.0; 3]; pos.len()];
        let (mut f, mut full, mut fast) = (vec![[0.0; 3]; pos.len()], vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        let mut ex = Exchange::new(&g, pos.len());
        ex.particle_gas_forces(&g, &gas, 1.8e-5, 0.1, 1.2e-3, &pos, &vel, &mut f, &mut full);
        ex.freeze(&g, &pos);
        ex.frozen_cell_forces(&g, &gas, 1.8e-5, 0.1, 1.2e-3, &mut fast);
        let scale = full.iter().flat_map(|v| v.iter()).fold(0.0f64, |m, x| m.max(x.abs()));
        for c in 0..n {
            for m in 0..3 {
                assert!((full[c][m] - fast[c][m]).abs() <= 1e-12 * scale, "cell {c}: {:?} vs {:?}", full[c], fast[c]);
            }
        }
    }

    #[test]
    fn per_cell_factors_reproduce_the_drag_law() {
        for &eps in &[0.05, 0.3, 0.4, 0.6, 0.9, 0.999] {
            for &w in &[0.0, 1e-9, 1e-3, 0.1, 0.6, 3.0] {
                let slip = [0.3 * w, -0.2 * w, w];
                let a = drag_force(1.8e-5, 1.2, 1.2e-3, eps, 0.1, slip);
                let b = CellDrag::new(1.8e-5, 1.2, 1.2e-3, eps, 0.1).force(slip);
                for m in 0..3 {
                    assert!((a[m] - b[m]).abs() <= 1e-13 * a[2].abs().max(1e-300), "ε={eps} w={w}: {a:?} vs {b:?}");
                }
            }
        }
    }
}
