//! Voidage methods: accuracy against the exact overlap and cost per particle per step, on random
//! packings at mean voidage 0.4, 0.6 and 0.9 in the 44-mm grid (R = 22 mm, dr = dz = 4.4 mm,
//! n0 = 3, 10 layers). Centres are uniform in the column (r ≤ R − a, a ≤ z ≤ H − a); spheres may
//! overlap — every method is linear in the particles, so overlaps change nothing in the comparison
//! and let the dense case reach ε = 0.4. Reference: exact-cylindrical split with 48 Gauss nodes
//! per layer (converged; checked against lattice sampling in the unit tests).

use fluidbed_core::case::BoxSplit;
use fluidbed_core::coupling::voidage::{
    voidage_from_solid, Direct, ExactCylindrical, Grouping, SquareGrid, VoidageMethod,
};
use fluidbed_core::grid::CylGrid;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;
use std::time::Instant;

fn methods(g: &CylGrid) -> Vec<(String, Box<dyn VoidageMethod>)> {
    let mut m: Vec<(String, Box<dyn VoidageMethod>)> =
        vec![("direct".into(), Box::new(Direct::new(g))), ("grouping".into(), Box::new(Grouping::new(g)))];
    for (split, tag) in [(BoxSplit::Cuboid, "cuboid"), (BoxSplit::Exact, "exact")] {
        for (c, dl) in [4.4e-3, 2.2e-3, 1.375e-3].iter().enumerate() {
            m.push((format!("square_grid {tag} config {}", c + 1), Box::new(SquareGrid::new(g, *dl, split, 1.0))));
        }
    }
    let h_eq = (PI / 6.0f64).powf(1.0 / 3.0);
    m.push((
        "square_grid cuboid config 3, h = 0.806 d".into(),
        Box::new(SquareGrid::new(g, 1.375e-3, BoxSplit::Cuboid, h_eq)),
    ));
    for n in [2, 3, 4, 6] {
        m.push((format!("exact_cylindrical {n} nodes"), Box::new(ExactCylindrical::with_nodes(g, n))));
    }
    m
}

pub fn packing(g: &CylGrid, eps: f64, a: f64, seed: u64) -> Vec<[f64; 3]> {
    let vp = 4.0 / 3.0 * PI * a * a * a;
    let n = ((1.0 - eps) * PI * g.radius * g.radius * g.height / vp).round() as usize;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let r = (g.radius - a) * rng.gen::<f64>().sqrt();
            let t = rng.gen_range(0.0..2.0 * PI);
            [r * t.cos(), r * t.sin(), rng.gen_range(a..g.height - a)]
        })
        .collect()
}

pub fn run() {
    let g = CylGrid::new(0.022, 0.044, 0.0044, 0.0044, 3);
    let a = 0.6e-3;
    let threads = rayon::current_num_threads();
    let names: Vec<String> = methods(&g).into_iter().map(|m| m.0).collect();
    let mut rows: Vec<Vec<(f64, f64)>> = vec![Vec::new(); names.len()];
    let mut eps_ref = vec![0.0; g.num_cells()];
    let mut eps = vec![0.0; g.num_cells()];
    let mut solid = vec![0.0; g.num_cells()];
    for (pi, &target) in [0.4, 0.6, 0.9].iter().enumerate() {
        let pos = packing(&g, target, a, 100 + pi as u64);
        let t = Instant::now();
        ExactCylindrical::with_nodes(&g, 48).solid_volume(&pos, a, &mut solid);
        voidage_from_solid(&g, &solid, &mut eps_ref);
        let mean: f64 = eps_ref.iter().sum::<f64>() / eps_ref.len() as f64;
        eprintln!(
            "ε = {target}: {} particles, mean voidage {mean:.3}, reference {:.1} s",
            pos.len(),
            t.elapsed().as_secs_f64()
        );
        for (k, (name, mut m)) in methods(&g).into_iter().enumerate() {
            m.solid_volume(&pos, a, &mut solid);
            voidage_from_solid(&g, &solid, &mut eps);
            let l1 = eps.iter().zip(&eps_ref).map(|(x, y)| (x - y).abs()).sum::<f64>() / eps.len() as f64;
            // time: repeat until ≥ 0.3 s
            let mut reps = 0usize;
            let t = Instant::now();
            while reps < 3 || t.elapsed().as_secs_f64() < 0.3 {
                m.solid_volume(&pos, a, &mut solid);
                reps += 1;
            }
            let ns = t.elapsed().as_secs_f64() * 1e9 / (reps * pos.len()) as f64;
            println!(
                "{}",
                serde_json::json!({"bench":"voidage","method":name,"voidage":target,"particles":pos.len(),"l1":l1,"ns_per_particle":ns,"threads":threads})
            );
            rows[k].push((l1, ns));
        }
    }
    println!("\n| method | L1 ε=0.4 | L1 ε=0.6 | L1 ε=0.9 | ns/particle ε=0.4 | ε=0.6 | ε=0.9 |");
    println!("|---|---|---|---|---|---|---|");
    for (name, r) in names.iter().zip(&rows) {
        println!(
            "| {name} | {:.2e} | {:.2e} | {:.2e} | {:.0} | {:.0} | {:.0} |",
            r[0].0, r[1].0, r[2].0, r[0].1, r[1].1, r[2].1
        );
    }
    let best = names
        .iter()
        .zip(&rows)
        .min_by(|x, y| x.1[1].0.partial_cmp(&y.1[1].0).unwrap())
        .map(|(n, r)| (n.clone(), r[1]))
        .unwrap();
    println!(
        "{}",
        serde_json::json!({"name":"voidage","most_accurate_at_0.6":best.0,"l1":best.1.0,"ns_per_particle":best.1.1,"threads":threads})
    );
}
