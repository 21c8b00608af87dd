//! `stress -- packed-100k`: the packed bed of cases/packed-bed.json (29,774 particles, U = 0.2
//! m/s, below U_mf) for 100,000 DEM steps with each voidage method, the particles free to move
//! (not frozen), so that a method whose voidage jumps as a centre crosses a cell face shows it
//! in time as the paper's Fig. 3 does in space. Per method:
//! - cell-to-cell jumps: `analysis::roughness` of the final interstitial U_z in the bed;
//! - temporal fluctuation: the standard deviation in time of each bed cell's U_z, sampled every
//!   500 steps over the second half, averaged over the bed cells, over the bed's mean U_z;
//! - a PNG of that standard deviation on the axial plane (docs/img/packed100k_uz_std_<method>.png).
//!
//! A JSON line per method, then `{"stress":"packed-100k",…}`.

use fluidbed_core::analysis::roughness;
use fluidbed_core::case::{Case, Voidage};
use fluidbed_core::output::plot::{axial_slice, FieldLabels};
use fluidbed_core::sim::Simulation;
use serde_json::{json, Value};
use std::path::PathBuf;
use std::time::Instant;

const STEPS: u64 = 100_000;
const SAMPLE_EVERY: u64 = 500;

fn case() -> Case {
    let path = format!("{}/../cases/packed-bed.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut c = Case::parse_str(&text).unwrap_or_else(|r| panic!("{path}: {:?}", r.errors)).0;
    c.dem.frozen = false;
    c.gas.as_mut().expect("gas").ramp_time_s = 0.01;
    c.end_time_s = 1.0;
    c.outputs.snapshot_interval_s = 1.0;
    c.outputs.fields = vec![];
    c
}

fn one(name: &str, voidage: Voidage) -> Value {
    let mut c = case();
    c.voidage = voidage;
    let bed = PathBuf::from(std::env::var("FLUIDBED_BED_CACHE").unwrap_or_else(|_| "target/fluidbed-bed-cache".into()));
    let mut sim = Simulation::new(c, Some(&bed)).expect("the packed bed builds");
    let grid = sim.grid().clone();
    let n = grid.num_cells();
    let (mut sum, mut sq, mut samples) = (vec![0.0; n], vec![0.0; n], 0.0);
    let t0 = Instant::now();
    while sim.steps() < STEPS {
        let left = (SAMPLE_EVERY - sim.steps() % SAMPLE_EVERY).min(STEPS - sim.steps());
        let before = sim.steps();
        sim.advance(left).unwrap_or_else(|e| panic!("{name}: {e}"));
        if sim.steps() == before {
            continue;
        }
        if sim.steps() >= STEPS / 2 && sim.steps().is_multiple_of(SAMPLE_EVERY) {
            let gas = sim.gas().expect("gas");
            for c in 0..n {
                let u = gas.velocity_cyl(c)[2];
                sum[c] += u;
                sq[c] += u * u;
            }
            samples += 1.0;
        }
    }
    let wall = t0.elapsed().as_secs_f64();
    // The bed: layers wholly below the 99th-percentile particle top, less one diameter.
    let mut z: Vec<f64> = sim.dem().positions().iter().map(|p| p[2]).collect();
    z.sort_by(|a, b| a.total_cmp(b));
    let top = z[(z.len() as f64 * 0.99) as usize] + sim.dem().radius();
    let k_bed = ((top - sim.case().particles.diameter_m) / grid.dz).floor() as usize - 1;
    let gas = sim.gas().expect("gas");
    let uz: Vec<f64> = (0..n).map(|c| gas.velocity_cyl(c)[2]).collect();
    let jumps = roughness(&grid, &uz, k_bed);
    let std: Vec<f64> = (0..n).map(|c| (sq[c] / samples - (sum[c] / samples).powi(2)).max(0.0).sqrt()).collect();
    let bed_cells = (grid.cells_per_layer()..(k_bed + 1) * grid.cells_per_layer()).collect::<Vec<_>>();
    let mean_u = bed_cells.iter().map(|&c| sum[c] / samples).sum::<f64>() / bed_cells.len() as f64;
    let mean_std = bed_cells.iter().map(|&c| std[c]).sum::<f64>() / bed_cells.len() as f64;
    let fluctuation = mean_std / mean_u;
    let title = format!(
        "{name}: std of U_z over t = {:.3}–{:.3} s",
        STEPS as f64 / 2.0 * sim.case().dem.time_step_s,
        sim.time()
    );
    let labels = FieldLabels { title: &title, quantity: "std of interstitial U_z in time [m/s]", lo: 0.0, hi: 0.02 };
    let path = format!("docs/img/packed100k_uz_std_{name}.png");
    let img = axial_slice(&grid, &std, &labels).expect("figure");
    std::fs::create_dir_all("docs/img").expect("docs/img");
    std::fs::write(&path, img.encode()).expect("write png");
    let line = json!({"stress": "packed-100k", "method": name, "particles": sim.dem().len(), "steps": sim.steps(),
        "samples": samples, "bed_layers": k_bed, "roughness": jumps, "temporal_fluctuation": fluctuation,
        "mean_uz_m_s": mean_u, "wall_s": wall, "png": path});
    println!("{line}");
    line
}

pub fn run() {
    let methods = Voidage::fig3_methods();
    let lines: Vec<(&str, Value)> = methods.into_iter().map(|(name, v)| (name, one(name, v))).collect();
    let pick = |key: &str| -> serde_json::Map<String, Value> {
        lines.iter().map(|(name, l)| (name.to_string(), l[key].clone())).collect()
    };
    println!(
        "{}",
        json!({"stress": "packed-100k", "steps": STEPS, "roughness": pick("roughness"),
            "temporal_fluctuation": pick("temporal_fluctuation"), "wall_s": pick("wall_s")})
    );
}
