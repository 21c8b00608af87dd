//! The drag voidage on sub-layers (exchange.rs `DragCells`, sublayer_pressure.rs): a packed
//! sub-layer of a half-filled cell feels Beetstra's drag of its packing at the cell's superficial
//! flux and its share of the pressure drop; the gas loses what the particles gain. (Against
//! published values: the packed-bed and U_mf validations, docs/VALIDATION.md.)

use super::*;
use rand::{Rng, SeedableRng};

/// Three fluid layers of 4.4 mm and the grid of two sub-layers per layer.
fn grids() -> (CylGrid, CylGrid) {
    (CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3), CylGrid::new(0.022, 0.0132, 0.0044, 0.0022, 3))
}

#[test]
fn a_packed_sublayer_gets_its_share_of_the_pressure_drop() {
    let (g, fine) = grids();
    let n = g.num_cells();
    let (mu, rho, d, u0) = (1.8e-5, 1.204, 1.2e-3, 0.3);
    let vp = PI * d * d * d / 6.0;
    // 25 particles at rest at the centre of the lower sub-cell of one fluid cell (middle layer),
    // its voidage the one they make; the upper sub-cell at 0.95, every other cell empty.
    let s_lo = fine.index(2, 5, 2);
    let x = fine.centre_xyz(s_lo);
    let pos: Vec<[f64; 3]> = (0..25).map(|k| [x[0] + 1e-5 * k as f64, x[1], x[2]]).collect();
    let vel = vec![[0.0; 3]; pos.len()];
    let (v_s, np) = (fine.cell_volume(), pos.len() as f64);
    let (e_s, e_hi) = (1.0 - np * vp / v_s, 0.95);
    let mut sub = vec![1.0; fine.num_cells()];
    sub[s_lo] = e_s;
    sub[s_lo + fine.cells_per_layer()] = e_hi;
    let c = g.locate(x[0], x[1], x[2]);
    let e_c = 0.5 * (e_s + e_hi);
    let mut void = vec![1.0; n];
    void[c] = e_c;
    let vel_c: Vec<[f64; 3]> = void.iter().map(|e| [0.0, 0.0, u0 / e]).collect();
    let (dens, grad) = (vec![rho; n], vec![[0.0; 3]; n]);
    let gas =
        GasAtCells { velocity_cyl: &vel_c, density: &dens, grad_p_cyl: &grad, voidage: &void, layers: usize::MAX };
    let (mut f, mut cf) = (vec![[0.0; 3]; pos.len()], vec![[0.0; 3]; n]);
    let par = ExchangeParams { law: DragModel::Beetstra, mu, eps_min: 0.1, d };
    let drag = DragCells { grid: &fine, sublayers: 2, voidage: &sub };
    Exchange::new(&g, pos.len()).particle_gas_forces(&g, drag, &gas, par, (&pos, &vel), &mut f, &mut cf);
    // Drag at ε_s with the cell's superficial flux: F_d = 3πμ d U₀ F(ε_s, ρU₀d/μ).
    let fd = 3.0 * PI * mu * d * u0 * beetstra_f(e_s, re_of(rho, u0, d, mu));
    // Each of the two sub-cells sees the drag of the three-sub-layer window around it,
    // N F_d/(3 V_s), over its voidage: G = I/ε; the particles get V_p(G_lo − G_c).
    let i_w = np * fd / (3.0 * v_s);
    let (g_lo, g_hi) = (i_w / e_s, i_w / e_hi);
    let share = vp * (g_lo - 0.5 * (g_lo + g_hi));
    for (k, fk) in f.iter().enumerate() {
        assert!((fk[2] / (fd + share) - 1.0).abs() < 1e-10, "particle {k}: {} vs {}", fk[2], fd + share);
        assert!(fk[0].abs() < 1e-12 * fk[2] && fk[1].abs() < 1e-12 * fk[2], "particle {k}: {fk:?}");
    }
    // The share is an upward push (the packed sub-layer holds most of the cell's pressure drop).
    assert!(share > 0.05 * fd, "{share} vs {fd}");
    // What the particles gain, the gas loses.
    let lost = -cf[c][2] * g.cell_volume();
    assert!((lost / (np * (fd + share)) - 1.0).abs() < 1e-12, "{lost} vs {}", np * (fd + share));
}

fn re_of(rho: f64, u: f64, d: f64, mu: f64) -> f64 {
    rho * u * d / mu
}

#[test]
fn what_the_particles_gain_with_sublayers_the_gas_loses() {
    let (g, fine) = grids();
    let n = g.num_cells();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
    let m = 4000;
    let scene = super::tests::RandomScene::new(&mut rng, n, m, false);
    let (gas, pos, vel, grad) = (scene.gas(), &scene.pos, &scene.vel, &scene.grad);
    let par = ExchangeParams { law: DragModel::Beetstra, mu: 1.8e-5, eps_min: 0.1, d: 1.2e-3 };
    let (mut f2, mut c2) = (vec![[0.0; 3]; m], vec![[0.0; 3]; n]);
    // Random sub-layer voidage: what the particles gain (less −V_p∇p) the gas loses.
    let sub: Vec<f64> = (0..fine.num_cells()).map(|_| rng.gen_range(0.35..1.0)).collect();
    let drag = DragCells { grid: &fine, sublayers: 2, voidage: &sub };
    Exchange::new(&g, m).particle_gas_forces(&g, drag, &gas, par, (pos, vel), &mut f2, &mut c2);
    let vp = PI * par.d.powi(3) / 6.0;
    let scale = f2.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
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

#[test]
fn the_layers_with_particles_give_the_same_forces_as_the_whole_column_with_sublayers() {
    // Six fluid layers, four sub-layers each; the bed in the lower two. The call that stops at
    // the bed's top layer gives the particles the same bits as the whole column's, and the gas
    // the same force in every cell (none above the bed).
    let g = CylGrid::new(0.022, 0.0264, 0.0044, 0.0044, 3);
    let fine = CylGrid::new(0.022, 0.0264, 0.0044, 0.0011, 3);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let mut scene = super::tests::RandomScene::new(&mut rng, g.num_cells(), 3000, true);
    for p in &mut scene.pos {
        p[2] *= 0.6;
    }
    let sub: Vec<f64> = (0..fine.num_cells()).map(|_| rng.gen_range(0.35..1.0)).collect();
    let layers = layers_with_particles(&g, &scene.pos);
    assert!(layers + 1 < g.nz, "the bed leaves layers free");
    let par = ExchangeParams { law: DragModel::Beetstra, mu: 1.8e-5, eps_min: 0.1, d: 1.2e-3 };
    let run = |layers: usize, ex: &mut Exchange| {
        let (mut f, mut cf) = (vec![[0.0; 3]; scene.pos.len()], vec![[0.0; 3]; g.num_cells()]);
        let gas = GasAtCells { layers, ..scene.gas() };
        let drag = DragCells { grid: &fine, sublayers: 4, voidage: &sub };
        ex.particle_gas_forces(&g, drag, &gas, par, (&scene.pos, &scene.vel), &mut f, &mut cf);
        (f, cf)
    };
    let (f_all, cf_all) = run(usize::MAX, &mut Exchange::new(&g, scene.pos.len()));
    // The same Exchange first on the whole column, so stale sums above the bed would show.
    let mut ex = Exchange::new(&g, scene.pos.len());
    run(usize::MAX, &mut ex);
    let (f, cf) = run(layers, &mut ex);
    assert!(f == f_all, "particle forces differ");
    assert!(cf == cf_all, "gas forces differ");
    let per = g.cells_per_layer();
    assert!(cf[layers * per..].iter().all(|c| *c == [0.0; 3]), "force above the bed");
}
