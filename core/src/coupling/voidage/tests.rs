//! Tests of the voidage methods against exact volumes (Table 3 set-up, lattice sampling).

use super::sampling::sampled_solid;
use super::*;
use crate::case::BoxSplit;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;

fn all_methods(g: &CylGrid) -> Vec<Box<dyn VoidageMethod>> {
    let mut v: Vec<Box<dyn VoidageMethod>> =
        vec![Box::new(Direct::new(g)), Box::new(Grouping::new(g)), Box::new(ExactCylindrical::new(g))];
    for dl in table3::BOX_SIDES {
        v.push(Box::new(SquareGrid::new(g, dl, BoxSplit::Cuboid, 1.0)));
        v.push(Box::new(SquareGrid::new(g, dl, BoxSplit::Exact, 1.0)));
    }
    v.push(Box::new(SquareGrid::new(g, 1.375e-3, BoxSplit::Cuboid, 1.5)));
    v
}

/// Random centres anywhere in the column, touching the wall, the axis, the bottom and the top.
fn random_bed(g: &CylGrid, n: usize, a: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut p: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            let r = (g.radius - a) * rng.gen::<f64>().sqrt();
            let t = rng.gen_range(0.0..2.0 * PI);
            [r * t.cos(), r * t.sin(), rng.gen_range(a..g.height - a)]
        })
        .collect();
    p.push([0.0, 0.0, a]);
    p.push([g.radius - a, 0.0, g.height - a]);
    p.push([
        (g.radius - a) * std::f64::consts::FRAC_1_SQRT_2,
        (g.radius - a) * std::f64::consts::FRAC_1_SQRT_2,
        2.0 * g.dz,
    ]);
    p
}

#[test]
fn every_method_conserves_particle_volume() {
    let g = CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3);
    let a = 0.6e-3;
    // below and above the parallel threshold
    for n in [500, 5000] {
        let pos = random_bed(&g, n, a, 7);
        let want = pos.len() as f64 * 4.0 / 3.0 * PI * a * a * a;
        let mut out = vec![0.0; g.num_cells()];
        for mut m in all_methods(&g) {
            m.solid_volume(&pos, a, &mut out);
            let got: f64 = out.iter().sum();
            assert!((got / want - 1.0).abs() < 1e-12, "{}: {}", m.name(), got / want - 1.0);
            assert!(out.iter().all(|&v| v >= 0.0), "{}", m.name());
        }
    }
}

struct Table3 {
    g: CylGrid,
    cells: [usize; 9],
    pos: Vec<[f64; 3]>,
    a: f64,
}

fn table3_setup() -> Table3 {
    let g = table3::grid();
    let cells = table3::cells(&g);
    let pos = table3::particles(&g, 2014);
    Table3 { g, cells, pos, a: table3::DIAMETER / 2.0 }
}

fn voidage_of(t: &Table3, m: &mut dyn VoidageMethod) -> Vec<f64> {
    let mut s = vec![0.0; t.g.num_cells()];
    m.solid_volume(&t.pos, t.a, &mut s);
    let mut e = vec![0.0; t.g.num_cells()];
    voidage_from_solid(&t.g, &s, &mut e);
    t.cells.iter().map(|&c| e[c]).collect()
}

#[test]
fn table3_direct_is_exact_and_grouping_has_the_papers_weights() {
    let t = table3_setup();
    let vs = table3::COUNT as f64 * PI * table3::DIAMETER.powi(3) / 6.0;
    let exact = 1.0 - vs / t.g.cell_volume();
    let e = voidage_of(&t, &mut Direct::new(&t.g));
    assert!((e[0] - exact).abs() < 1e-14);
    assert!(e[1..].iter().all(|&v| v == 1.0));
    // grouping: cells 1, 2, 3, 8, 9 all 1 − V_s/7V; radial cells 4..7 with weights 0.4, 0.2, 0.6, 0.8
    let e = voidage_of(&t, &mut Grouping::new(&t.g));
    let f = vs / (7.0 * t.g.cell_volume());
    for (k, w) in [(0, 1.0), (1, 1.0), (2, 1.0), (3, 0.4), (4, 0.2), (5, 0.6), (6, 0.8), (7, 1.0), (8, 1.0)] {
        assert!((e[k] - (1.0 - w * f)).abs() < 1e-12, "cell {}: {} vs {}", k + 1, e[k], 1.0 - w * f);
    }
}

#[test]
fn table3_square_grid_keeps_layers_and_finer_boxes_are_nearer_exact() {
    let t = table3_setup();
    let vs = table3::COUNT as f64 * PI * table3::DIAMETER.powi(3) / 6.0;
    let exact = 1.0 - vs / t.g.cell_volume();
    for split in [BoxSplit::Cuboid, BoxSplit::Exact] {
        let e: Vec<Vec<f64>> =
            table3::BOX_SIDES.iter().map(|&dl| voidage_of(&t, &mut SquareGrid::new(&t.g, dl, split, 1.0))).collect();
        for ec in &e {
            assert_eq!((ec[7], ec[8]), (1.0, 1.0), "{split:?}: cells below/above");
        }
        assert!(
            (e[2][0] - exact).abs() < (e[0][0] - exact).abs(),
            "{split:?}: config 3 {} config 1 {} exact {exact}",
            e[2][0],
            e[0][0]
        );
    }
    // the exact-cylindrical method is exact here
    let e = voidage_of(&t, &mut ExactCylindrical::new(&t.g));
    assert!((e[0] - exact).abs() < 1e-14);
}

/// The exact-cylindrical split against an independent reference: lattice sampling with 96 points
/// per diameter (its own L1 error ≈ 1e-3 of V_p, falling as 1/n). The converged split (40 nodes)
/// must agree to within that, and the default node count nearly so.
#[test]
fn exact_cylindrical_matches_lattice_sampling() {
    let g = CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3);
    let a = 0.6e-3;
    let pos = random_bed(&g, 120, a, 21);
    let vp = 4.0 / 3.0 * PI * a * a * a;
    let mut reference = vec![0.0; g.num_cells()];
    sampled_solid(&g, &pos, a, 96, &mut reference);
    let l1 = |x: &[f64]| x.iter().zip(&reference).map(|(p, q)| (p - q).abs()).sum::<f64>() / (pos.len() as f64 * vp);
    let mut out = vec![0.0; g.num_cells()];
    ExactCylindrical::with_nodes(&g, 40).solid_volume(&pos, a, &mut out);
    assert!(l1(&out) < 1.5e-3, "40 nodes: {}", l1(&out));
    ExactCylindrical::new(&g).solid_volume(&pos, a, &mut out);
    assert!(l1(&out) < 3e-3, "default nodes: {}", l1(&out));
    // while the cuboid square grid (config. 3) is far off
    SquareGrid::new(&g, 1.375e-3, BoxSplit::Cuboid, 1.0).solid_volume(&pos, a, &mut out);
    assert!(l1(&out) > 0.02, "cuboid L1 {}", l1(&out));
}

#[test]
fn direct_jumps_by_one_particle_across_a_face() {
    let g = CylGrid::new(0.022, 0.0132, 0.0044, 0.0044, 3);
    let a = 0.6e-3;
    let mut m = Direct::new(&g);
    let mut s = vec![0.0; g.num_cells()];
    let mut e1 = vec![0.0; g.num_cells()];
    let mut e2 = vec![0.0; g.num_cells()];
    let c = g.index(2, 1, 1);
    m.solid_volume(&[[0.011, 0.011 * 0.6, 0.0088 - 1e-9]], a, &mut s);
    voidage_from_solid(&g, &s, &mut e1);
    m.solid_volume(&[[0.011, 0.011 * 0.6, 0.0088 + 1e-9]], a, &mut s);
    voidage_from_solid(&g, &s, &mut e2);
    let vp = 4.0 / 3.0 * PI * a * a * a;
    assert!((e2[c] - e1[c] - vp / g.cell_volume()).abs() < 1e-14);
}

#[test]
fn default_box_side_is_the_papers_configuration_3() {
    assert!((default_box_side(0.044, 0.0012) - 1.375e-3).abs() < 1e-15);
}
