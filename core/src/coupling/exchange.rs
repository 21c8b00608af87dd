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

/// Fluid force on every particle (Cartesian, −V_p∇p + drag) into `force_out`, and the interaction
/// force per unit volume on the gas, I = −Σ drag / V_cell (cylindrical, cell-centre basis), into
/// `cell_force_out` (overwritten). `d` is the particle diameter; ε is clamped to [eps_min, 1).
#[allow(clippy::too_many_arguments)]
pub fn particle_gas_forces(
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
    // 1. drag on every particle (parallel), kept in force_out for now
    force_out.par_iter_mut().zip(pos.par_iter().zip(vel.par_iter())).for_each(|(f, (p, v))| {
        let c = grid.locate(p[0], p[1], p[2]);
        let (cos, sin) = angle_of(p[0], p[1]);
        let u = cyl_to_cart(gas.velocity_cyl[c], cos, sin);
        let slip = [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
        *f = drag_force(mu, gas.density[c], d, gas.voidage[c], eps_min, slip);
    });
    // 2. the gas loses the drag in the cell of the particle's centre (fixed order: deterministic)
    for f in cell_force_out.iter_mut() {
        *f = [0.0; 3];
    }
    let inv_v = 1.0 / grid.cell_volume();
    for (f, p) in force_out.iter().zip(pos) {
        let c = grid.locate(p[0], p[1], p[2]);
        let (i, j, _) = grid.ijk(c);
        let th = grid.centre_polar(i, j).1;
        let fc = cart_to_cyl(*f, th.cos(), th.sin());
        for m in 0..3 {
            cell_force_out[c][m] -= fc[m] * inv_v;
        }
    }
    // 3. add the pressure-gradient force −V_p∇p (model A)
    let vp = PI * d * d * d / 6.0;
    force_out.par_iter_mut().zip(pos.par_iter()).for_each(|(f, p)| {
        let c = grid.locate(p[0], p[1], p[2]);
        let (cos, sin) = angle_of(p[0], p[1]);
        let g = cyl_to_cart(gas.grad_p_cyl[c], cos, sin);
        for m in 0..3 {
            f[m] -= vp * g[m];
        }
    });
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
        particle_gas_forces(&g, &gas, mu, 0.1, d, &pos, &vel, &mut f, &mut cf);
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
        let vel_c: Vec<[f64; 3]> = (0..n).map(|_| [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0)]).collect();
        let dens: Vec<f64> = (0..n).map(|_| rng.gen_range(1.1..1.3)).collect();
        let grad: Vec<[f64; 3]> = (0..n).map(|_| [rng.gen_range(-50.0..50.0), rng.gen_range(-50.0..50.0), -6000.0]).collect();
        let void: Vec<f64> = (0..n).map(|_| rng.gen_range(0.35..1.0)).collect();
        let gas = GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void };
        let m = 5000;
        let pos: Vec<[f64; 3]> = (0..m)
            .map(|_| {
                let (r, t) = (0.021 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
                [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
            })
            .collect();
        let vel: Vec<[f64; 3]> = (0..m).map(|_| [rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5)]).collect();
        let (mut f, mut cf) = (vec![[0.0; 3]; m], vec![[0.0; 3]; n]);
        let d = 1.2e-3;
        particle_gas_forces(&g, &gas, 1.8e-5, 0.1, d, &pos, &vel, &mut f, &mut cf);
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
}
