use super::*;

fn paper_grid() -> CylGrid {
    // The 44-mm column with dr = 4.4 mm, dz = dr (paper section 3.2).
    CylGrid::new(0.022, 0.11, 0.0044, 0.0044, 3)
}

#[test]
fn every_cell_has_the_same_volume() {
    for n0 in [3, 4, 6] {
        let g = CylGrid::new(0.025, 0.1, 0.0025, 0.0025, n0);
        let v = g.cell_volume();
        for i in 0..g.nr {
            let vi = g.cell_volume_from_bounds(i);
            assert!(((vi - v) / v).abs() < 1e-14, "n0={n0} annulus {i}: {vi} vs {v}");
        }
        let total = v * g.num_cells() as f64;
        let exact = PI * 0.025f64.powi(2) * 0.1;
        assert!(((total - exact) / exact).abs() < 1e-13);
    }
}

#[test]
fn radial_face_fractions_sum_to_one_on_both_sides() {
    let g = paper_grid();
    for i in 0..g.nr {
        for j in 0..g.cells_in_annulus(i) {
            if i + 1 < g.nr {
                let s: f64 = g.outer_neighbours(i, j).iter().map(|l| l.fraction).sum();
                assert!((s - 1.0).abs() < 1e-15, "outer ({i},{j}) sums to {s}");
            } else {
                assert!(g.outer_neighbours(i, j).is_empty());
            }
            if i > 0 {
                let s: f64 = g.inner_neighbours(i, j).iter().map(|l| l.fraction).sum();
                assert!((s - 1.0).abs() < 1e-15, "inner ({i},{j}) sums to {s}");
            } else {
                assert!(g.inner_neighbours(i, j).is_empty());
            }
        }
    }
}

#[test]
fn shared_face_areas_agree_from_both_sides() {
    // Area shared by (i,j) and (i+1,jj), seen from each: r_{i+1}·Δθ_i·frac == r_{i+1}·Δθ_{i+1}·frac'.
    let g = paper_grid();
    for i in 0..g.nr - 1 {
        for j in 0..g.cells_in_annulus(i) {
            for l in g.outer_neighbours(i, j) {
                let back = g.inner_neighbours(i + 1, l.j).iter().find(|b| b.j == j).expect("symmetric link");
                let a = g.dtheta(i) * l.fraction;
                let b = g.dtheta(i + 1) * back.fraction;
                assert!((a - b).abs() < 1e-15);
            }
        }
    }
}

/// Uniform numbers in [0, 1) from a seeded LCG (reproducible, no dependency).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn locate_finds_the_cell_whose_bounds_hold_the_point() {
    let g = paper_grid();
    let mut rnd = uniform(12345);
    for _ in 0..10_000 {
        let r = g.radius * rnd().sqrt();
        let th = 2.0 * PI * rnd();
        let z = g.height * rnd();
        let idx = g.locate(r * th.cos(), r * th.sin(), z);
        let (i, j, k) = g.ijk(idx);
        assert_eq!(g.index(i, j, k), idx);
        assert!(r >= i as f64 * g.dr - 1e-12 && r <= (i + 1) as f64 * g.dr + 1e-12);
        let (t0, t1) = g.theta_bounds(i, j);
        assert!(th >= t0 - 1e-12 && th <= t1 + 1e-12);
        assert!(z >= k as f64 * g.dz - 1e-12 && z <= (k + 1) as f64 * g.dz + 1e-12);
    }
}

#[test]
fn ijk_round_trips() {
    let g = paper_grid();
    for idx in 0..g.num_cells() {
        let (i, j, k) = g.ijk(idx);
        assert_eq!(g.index(i, j, k), idx);
    }
}

/// `locate_near` gives `locate`'s cell for any hint: the right one, a neighbour, another
/// layer, nonsense; points spread over the column and points within 1e-12 of cell edges.
#[test]
fn locate_near_agrees_with_locate_for_any_hint() {
    let g = paper_grid();
    let mut rnd = uniform(777);
    let (mut taken, mut total) = (0, 0);
    for n in 0..40_000 {
        let (mut r, mut th, z) = (g.radius * 1.02 * rnd().sqrt(), 2.0 * PI * rnd(), g.height * rnd());
        if n % 4 == 1 {
            // on an angular edge of its annulus, up to 1e-12 off
            let i = ((r / g.dr) as usize).min(g.nr - 1);
            let w = g.dtheta(i);
            th = (th / w).round() * w + (rnd() - 0.5) * 2e-12;
        } else if n % 4 == 2 {
            // on a radial edge
            r = ((r / g.dr).round() * g.dr + (rnd() - 0.5) * 2e-12).max(0.0);
        }
        let (x, y) = (r * th.cos(), r * th.sin());
        let exact = g.locate(x, y, z);
        let hints = [
            exact,
            exact + 1,
            exact.wrapping_sub(1),
            exact + g.cells_per_layer(),
            (rnd() * g.num_cells() as f64) as usize,
            usize::MAX,
        ];
        for h in hints {
            assert_eq!(g.locate_near(x, y, z, h), exact, "point ({x}, {y}, {z}) with hint {h}");
            total += 1;
            taken += g.hint_holds(x, y, z, h) as usize;
        }
    }
    // The shortcut serves the right hint of the 20,000 points placed off the edges (and of
    // the edge points moved onto the axis or the wall, which bound nothing); a wrong hint that
    // passed it would have failed the comparison above.
    assert!(taken > 19_900 && total == 240_000, "shortcut taken {taken} times");
}
