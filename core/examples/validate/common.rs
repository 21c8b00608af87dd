//! Shared pieces of the validation runs: loading the paper's cases, running with progress,
//! and reading pressure gradients and voidage off the layer means of a snapshot.

use fluidbed_core::case::Case;
use fluidbed_core::sim::{Simulation, Snapshot};
use std::path::PathBuf;
use std::time::Instant;

/// The key a long run is kept under in target/validate-cache: the case's JSON as it was written
/// before `coupling.pressure_force` and `coupling.gas_drag` were written (left out when "held"),
/// so the runs made before keep their keys.
pub fn cache_key(case: &Case) -> u64 {
    let json = serde_json::to_string(case).expect("case to JSON");
    // Keys that were added with "held" as their only value keep the runs made before them.
    fluidbed_core::dem::fnv1a(&json.replace(r#","pressure_force":"held""#, "").replace(r#","gas_drag":"held""#, ""))
}

/// A case from the project's cases/ folder.
pub fn load_case(file: &str) -> Case {
    load_case_path(&format!("{}/../cases/{file}", env!("CARGO_MANIFEST_DIR")))
}

/// A case file anywhere.
pub fn load_case_path(path: &str) -> Case {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    Case::parse_str(&text).unwrap_or_else(|r| panic!("{path}: {:?}", r.errors)).0
}

/// Settled beds are cached here so the validations pour each bed once.
pub fn bed_cache() -> PathBuf {
    let dir = std::env::var_os("FLUIDBED_BED_CACHE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("target/fluidbed-bed-cache"));
    std::fs::create_dir_all(&dir).expect("bed cache dir");
    dir
}

/// Build and run a case to its end, keeping every snapshot; progress goes to stderr.
pub fn run_case(case: Case, label: &str) -> (Simulation, Vec<Snapshot>) {
    let t0 = Instant::now();
    let mut sim = Simulation::new(case, Some(&bed_cache())).unwrap_or_else(|e| panic!("{label}: {e}"));
    eprintln!(
        "[{label}] {} particles, plan {:?} (built in {:.1} s)",
        sim.dem().len(),
        sim.plan(),
        t0.elapsed().as_secs_f64()
    );
    let mut snaps = Vec::new();
    let t1 = Instant::now();
    while !sim.is_finished() {
        match sim.advance(u64::MAX) {
            Ok(Some(s)) => {
                if s.index % 10 == 0 {
                    eprintln!(
                        "[{label}] t = {:.3} s, ΔP = {:?} Pa, wall {:.0} s",
                        s.time_s,
                        s.pressure_drop_pa.map(|x| x.round()),
                        t1.elapsed().as_secs_f64()
                    );
                }
                snaps.push(s);
            }
            Ok(None) => {}
            Err(e) => panic!("[{label}] {e}"),
        }
    }
    (sim, snaps)
}

/// Layer means of a cell field.
pub fn layers(s: &Snapshot, field: &[f64]) -> Vec<f64> {
    let per = field.len() / s.grid.nz;
    field.chunks(per).map(|l| l.iter().sum::<f64>() / per as f64).collect()
}

/// Pressure gradient −dp/dz between the centres of layers k1 < k2, and the voidage averaged over
/// the same span (half weight to the two end layers), from layer means.
pub fn gradient_and_voidage(s: &Snapshot, k1: usize, k2: usize) -> (f64, f64) {
    let p = layers(s, s.pressure_pa.as_ref().expect("pressure field"));
    let e = layers(s, s.voidage.as_ref().expect("voidage field"));
    let dz = s.grid.dz_m;
    let grad = (p[k1] - p[k2]) / ((k2 - k1) as f64 * dz);
    let mut w = 0.0;
    let mut sum = 0.0;
    for (k, &ek) in e.iter().enumerate().take(k2 + 1).skip(k1) {
        let wk = if k == k1 || k == k2 { 0.5 } else { 1.0 };
        w += wk;
        sum += wk * ek;
    }
    (grad, sum / w)
}

/// Ergun (PHYSICS.md 10): Δp/L = 150 μ φ² U/(ε³ d²) + 1.75 ρ φ U²/(ε³ d).
pub fn ergun(eps: f64, u: f64, d: f64, mu: f64, rho: f64) -> f64 {
    let phi = 1.0 - eps;
    150.0 * mu * phi * phi * u / (eps.powi(3) * d * d) + 1.75 * rho * phi * u * u / (eps.powi(3) * d)
}

/// Beetstra-implied fixed-bed gradient (PHYSICS.md 11 test): Δp/L = 18 μ φ F(ε, Re) U/(ε d²), Re = ρ U d/μ.
pub fn beetstra_gradient(eps: f64, u: f64, d: f64, mu: f64, rho: f64) -> f64 {
    let re = rho * u * d / mu;
    18.0 * mu * (1.0 - eps) * fluidbed_core::coupling::beetstra_f(eps, re) * u / (eps * d * d)
}

/// Bed weight per area less buoyancy: N m g (1 − ρ_g/ρ_p) / A (PHYSICS.md 10).
pub fn bed_weight_per_area(case: &Case, n: usize, rho_g: f64) -> f64 {
    let area = std::f64::consts::PI * (case.column.diameter_m / 2.0).powi(2);
    n as f64 * case.particle_mass_kg() * case.gravity_m_s2 * (1.0 - rho_g / case.particles.density_kg_m3) / area
}

/// The layer holding the top of the bed: the highest particle centre below which 99% lie.
pub fn bed_top_m(sim: &Simulation) -> f64 {
    let mut z: Vec<f64> = sim.dem().positions().iter().map(|p| p[2]).collect();
    z.sort_by(|a, b| a.partial_cmp(b).unwrap());
    z[(z.len() as f64 * 0.99) as usize] + sim.dem().radius()
}

/// Run a case file to its end and report where the wall time went.
pub fn timed_case(path: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let case = Case::parse_str(&text).unwrap_or_else(|r| panic!("{path}: {:?}", r.errors)).0;
    let t0 = Instant::now();
    let (sim, snaps) = run_case(case, path);
    let t = sim.timers();
    serde_json::json!({"name": "case", "case": path, "particles": sim.dem().len(), "steps": sim.steps(), "snapshots": snaps.len(),
        "wall_s": t0.elapsed().as_secs_f64(), "dem_s": t.dem(), "neighbours_s": t.neighbours, "output_s": t.output, "gas_s": t.gas, "voidage_s": t.voidage, "exchange_s": t.exchange,
        "last_dp_pa": snaps.last().and_then(|s| s.pressure_drop_pa),
        "last_layer_pressure_pa": snaps.last().and_then(|s| s.pressure_pa.as_ref().map(|p| layers(s, p)))})
}

/// What the pressure drop of a fluidized bed should be: the bed weight per area less buoyancy
/// (PHYSICS.md 10) and, since ΔP is read from the plate to z = (nz − 1) dz
/// (`analysis::bed_pressure_drop`), the hydrostatic head ρ_g g z of the gas between the points.
pub fn expected_dp(case: &fluidbed_core::case::Case, particles: usize) -> (f64, f64) {
    let rho_g = case.gas.as_ref().expect("gas section").outlet_density_kg_m3();
    let grid = fluidbed_core::sim::fluid_grid(case);
    (bed_weight_per_area(case, particles, rho_g), rho_g * case.gravity_m_s2 * (grid.nz - 1) as f64 * grid.dz)
}

/// Write `bytes` to `path` through a temporary file, so a stopped run never leaves half a file.
pub fn write_atomically(path: &str, bytes: &[u8]) {
    let tmp = format!("{path}.tmp");
    std::fs::write(&tmp, bytes).unwrap_or_else(|e| panic!("{tmp}: {e}"));
    std::fs::rename(&tmp, path).unwrap_or_else(|e| panic!("{path}: {e}"));
}
