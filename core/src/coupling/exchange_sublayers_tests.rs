//! The drag voidage on sub-layers (exchange.rs `DragCells`): a particle in a packed sub-layer of a
//! half-filled cell feels Beetstra's drag of the packing at the cell's superficial flux; a uniform
//! cell gives the paper's model; the gas loses what the particles gain.

use super::*;
use rand::{Rng, SeedableRng};

/// Three fluid layers of 4.4 mm and the grid of two sub-layers per layer.
fn grids() -> (CylGrid, CylGrid) {
    (CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3), CylGrid::new(0.022, 0.0132, 0.0044, 0.0022, 3))
}

/// Sub-cell voidage: ε_lo in the lower sub-layer of every cell, ε_hi in the upper one.
fn split_voidage(fine: &CylGrid, lo: f64, hi: f64) -> Vec<f64> {
    let per = fine.cells_per_layer();
    (0..fine.num_cells()).map(|s| if (s / per).is_multiple_of(2) { lo } else { hi }).collect()
}

#[test]
fn a_particle_in_a_packed_sublayer_feels_the_drag_of_the_packing_at_the_cells_flux() {
    let (g, fine) = grids();
    let n = g.num_cells();
    let (mu, rho, d, u0) = (1.8e-5, 1.204, 1.2e-3, 0.3);
    // The cell: its lower half packed at 0.4, its upper half loose at 0.9, so ε_c = 0.65; the gas moves
    // at the superficial velocity U₀ (interstitial U₀/ε_c).
    let (e_lo, e_hi) = (0.4, 0.9);
    let e_c = 0.5 * (e_lo + e_hi);
    let sub = split_voidage(&fine, e_lo, e_hi);
    let (void, vel_c) = (vec![e_c; n], vec![[0.0, 0.0, u0 / e_c]; n]);
    let (dens, grad) = (vec![rho; n], vec![[0.0; 3]; n]);
    let gas = GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void };
    // At rest, in the lower sub-layer of the middle layer (z = 4.4–6.6 mm), and one in the upper.
    let pos = vec![[0.003, 0.004, 0.005], [0.003, 0.004, 0.007]];
    let vel = vec![[0.0; 3]; 2];
    let (mut f, mut cf) = (vec![[0.0; 3]; 2], vec![[0.0; 3]; n]);
    let par = ExchangeParams { law: DragModel::Beetstra, mu, eps_min: 0.1, d };
    let drag = DragCells { grid: &fine, sublayers: 2, voidage: &sub };
    Exchange::new(&g, 2).particle_gas_forces(&g, drag, &gas, par, (&pos, &vel), &mut f, &mut cf);
    // Beetstra at ε with the superficial slip U₀: F_d = 3πμ d U₀ F(ε, ρ U₀ d/μ).
    let re = rho * u0 * d / mu;
    let want = |eps: f64| 3.0 * PI * mu * d * u0 * beetstra_f(eps, re);
    for (k, eps) in [(0, e_lo), (1, e_hi)] {
        assert!((f[k][2] / want(eps) - 1.0).abs() < 1e-12, "particle {k}: {} vs {}", f[k][2], want(eps));
    }
    // The cell's own voidage gives neither: the packed particle would feel about a quarter of its drag.
    assert!(want(e_c) < 0.3 * want(e_lo), "{} vs {}", want(e_c), want(e_lo));
    // The gas of the middle layer's cell loses both drags.
    let c = g.locate(0.003, 0.004, 0.005);
    let lost = -cf[c][2] * g.cell_volume();
    assert!((lost / (f[0][2] + f[1][2]) - 1.0).abs() < 1e-12, "{lost} vs {}", f[0][2] + f[1][2]);
}

#[test]
fn uniform_sublayers_give_the_cells_drag_and_momentum_is_conserved() {
    let (g, fine) = grids();
    let n = g.num_cells();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
    let vel_c: Vec<[f64; 3]> =
        (0..n).map(|_| [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(0.0..2.0)]).collect();
    let dens: Vec<f64> = (0..n).map(|_| rng.gen_range(1.1..1.3)).collect();
    let grad: Vec<[f64; 3]> = (0..n).map(|_| [rng.gen_range(-50.0..50.0), 0.0, -6000.0]).collect();
    let void: Vec<f64> = (0..n).map(|_| rng.gen_range(0.35..1.0)).collect();
    let gas = GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void };
    let m = 4000;
    let pos: Vec<[f64; 3]> = (0..m)
        .map(|_| {
            let (r, t) = (0.021 * rng.gen::<f64>().sqrt(), rng.gen_range(0.0..2.0 * PI));
            [r * t.cos(), r * t.sin(), rng.gen_range(0.0..0.0132)]
        })
        .collect();
    let vel: Vec<[f64; 3]> =
        (0..m).map(|_| [rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5)]).collect();
    let par = ExchangeParams { law: DragModel::Beetstra, mu: 1.8e-5, eps_min: 0.1, d: 1.2e-3 };
    let per = g.cells_per_layer();
    // Every sub-cell at its cell's voidage: the paper's model.
    let same: Vec<f64> = (0..fine.num_cells()).map(|s| void[(s / per / 2) * per + s % per]).collect();
    let (mut f1, mut c1, mut f2, mut c2) = (vec![[0.0; 3]; m], vec![[0.0; 3]; n], vec![[0.0; 3]; m], vec![[0.0; 3]; n]);
    Exchange::new(&g, m).particle_gas_forces(
        &g,
        DragCells::cells(&g, &void),
        &gas,
        par,
        (&pos, &vel),
        &mut f1,
        &mut c1,
    );
    let drag = DragCells { grid: &fine, sublayers: 2, voidage: &same };
    Exchange::new(&g, m).particle_gas_forces(&g, drag, &gas, par, (&pos, &vel), &mut f2, &mut c2);
    let scale = f1.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    for k in 0..m {
        for q in 0..3 {
            assert!((f1[k][q] - f2[k][q]).abs() <= 1e-13 * scale, "particle {k}: {:?} vs {:?}", f1[k], f2[k]);
        }
    }
    // Sub-layers that differ: what the particles gain (less −V_p∇p) the gas loses.
    let sub: Vec<f64> = (0..fine.num_cells()).map(|_| rng.gen_range(0.35..1.0)).collect();
    let drag = DragCells { grid: &fine, sublayers: 2, voidage: &sub };
    Exchange::new(&g, m).particle_gas_forces(&g, drag, &gas, par, (&pos, &vel), &mut f2, &mut c2);
    let vp = PI * par.d.powi(3) / 6.0;
    let (mut on_particles, mut on_gas) = ([0.0; 3], [0.0; 3]);
    for (k, p) in pos.iter().enumerate() {
        let c = g.locate(p[0], p[1], p[2]);
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let gp = cyl_to_cart(grad[c], p[0] / r, p[1] / r);
        (0..3).for_each(|q| on_particles[q] += f2[k][q] + vp * gp[q]);
    }
    for (c, i_cyl) in c2.iter().enumerate() {
        let (i, j, _) = g.ijk(c);
        let th = g.centre_polar(i, j).1;
        let v = cyl_to_cart(*i_cyl, th.cos(), th.sin());
        (0..3).for_each(|q| on_gas[q] += v[q] * g.cell_volume());
    }
    for q in 0..3 {
        assert!((on_particles[q] + on_gas[q]).abs() < 1e-12 * scale * m as f64, "{q}: {on_particles:?} vs {on_gas:?}");
    }
}
