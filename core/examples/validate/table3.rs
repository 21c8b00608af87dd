//! Paper Table 3 / Fig. 5 (section 3.2): 26 particles of d = 1.2 mm wholly inside one cell; the
//! voidage of that cell and its 8 neighbours by every method, beside the exact overlap and the
//! paper's values. Cell mapping: see `fluidbed_core::coupling::voidage::table3`.

use fluidbed_core::case::BoxSplit;
use fluidbed_core::coupling::voidage::{
    table3, voidage_from_solid, Direct, ExactCylindrical, Grouping, SquareGrid, VoidageMethod,
};
use std::f64::consts::PI;

pub fn run() {
    let g = table3::grid();
    let cells = table3::cells(&g);
    let pos = table3::particles(&g, 2014);
    let a = table3::DIAMETER / 2.0;
    let total = pos.len() as f64 * 4.0 / 3.0 * PI * a * a * a;

    let mut methods: Vec<(String, Box<dyn VoidageMethod>)> =
        vec![("direct".into(), Box::new(Direct::new(&g))), ("grouping".into(), Box::new(Grouping::new(&g)))];
    for (split, tag) in [(BoxSplit::Cuboid, "cuboid"), (BoxSplit::Exact, "exact")] {
        for (c, dl) in table3::BOX_SIDES.iter().enumerate() {
            methods.push((format!("sg_{tag}_{}", c + 1), Box::new(SquareGrid::new(&g, *dl, split, 1.0))));
        }
    }
    methods.push(("exact_cylindrical".into(), Box::new(ExactCylindrical::new(&g))));
    // the exact overlap: the exact-cylindrical split converged in z (48 nodes per layer)
    methods.push(("exact".into(), Box::new(ExactCylindrical::with_nodes(&g, 48))));

    let mut solid = vec![0.0; g.num_cells()];
    let mut eps = vec![0.0; g.num_cells()];
    let mut columns: Vec<(String, Vec<f64>)> = Vec::new();
    let mut volume_rel_err = 0.0f64;
    for (name, m) in methods.iter_mut() {
        m.solid_volume(&pos, a, &mut solid);
        volume_rel_err = volume_rel_err.max((solid.iter().sum::<f64>() / total - 1.0).abs());
        voidage_from_solid(&g, &solid, &mut eps);
        columns.push((name.clone(), cells.iter().map(|&c| eps[c]).collect()));
    }

    println!(
        "Table 3 set-up: {} particles, d = {} mm, grid R = 22 mm, dr = dz = 4.4 mm, n0 = 3;",
        pos.len(),
        table3::DIAMETER * 1e3
    );
    println!(
        "cell 1 = (i 2, j 1, k 1); V_cell = {:.2} mm³, particle volume {:.2} mm³",
        g.cell_volume() * 1e9,
        total * 1e9
    );
    println!("\nThis code (voidage):");
    print!("| cell |");
    for (n, _) in &columns {
        print!(" {n} |");
    }
    println!();
    print!("|---|");
    for _ in &columns {
        print!("---|");
    }
    println!();
    for k in 0..9 {
        print!("| {} |", k + 1);
        for (_, v) in &columns {
            print!(" {:.3} |", v[k]);
        }
        println!();
    }
    println!("\nPaper Table 3 (direct, grouping, sg cuboid 1-3, sg exact 1-3):");
    for (k, row) in table3::PAPER.iter().enumerate() {
        let r: Vec<String> = row.iter().map(|v| format!("{v:.3}")).collect();
        println!("| {} | {} |", k + 1, r.join(" | "));
    }

    let col = |name: &str| columns.iter().find(|c| c.0 == name).map(|c| c.1.clone()).expect("column");
    let exact = col("exact")[0];
    let figure = col("sg_cuboid_3")[0];
    let sg_above_below_min =
        columns.iter().filter(|c| c.0.starts_with("sg_")).flat_map(|c| [c.1[7], c.1[8]]).fold(f64::INFINITY, f64::min);
    let cell1: serde_json::Map<String, serde_json::Value> =
        columns.iter().map(|(n, v)| (n.clone(), serde_json::json!(v[0]))).collect();
    let j = serde_json::json!({
        "name": "table3",
        "figure": figure,
        "reference": exact,
        "rel_err": (figure - exact).abs() / exact,
        "volume_rel_err": volume_rel_err,
        "sg_above_below_min": sg_above_below_min,
        "cell1": cell1,
    });
    println!("{j}");
}
