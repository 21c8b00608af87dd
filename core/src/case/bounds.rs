//! Bounds on what a case implies before anything is allocated: particles (from a settled height
//! too), fluid cells, voidage boxes, snapshot bytes and an estimate of the run's peak memory.
//! `validate()` refuses cases beyond the fixed bounds here; a server also compares
//! [`CaseSize::memory_bytes`] with its own per-job limit ([`CaseSize::memory_problem`]).

use super::validate::{Problem, Severity};
use super::{Bed, Case, Field, Voidage};
use serde_json::Value;

/// Most particles a run may hold (counted as poured: a settled height pours 15 % more).
pub const MAX_PARTICLES: f64 = 20e6;
/// Most fluid cells (`n0 · N_r² · N_z`); the grid is built for DEM-only runs too (voidage maps).
pub const MAX_CELLS: f64 = 20e6;
/// Most boxes of the square-grid voidage method (`nb² · N_z`).
pub const MAX_BOXES: f64 = 50e6;
/// Largest single snapshot as stored (raw f64 fields).
pub const MAX_SNAPSHOT_BYTES: f64 = 2.0 * (1u64 << 30) as f64;
/// Longest job name, in bytes.
pub const MAX_NAME_BYTES: usize = 200;

/// Estimated peak bytes per particle while pouring and running: state, AB3 histories, near list
/// and contact histories (the DEM's arrays measure ≈ 460 B per particle at 205k particles, a whole
/// coupled run 654 B; docs/BENCHMARKS.md "Scaling").
const BYTES_PER_PARTICLE: f64 = 600.0;
/// Per fluid cell with gas: the conserved state, its AB3 histories, face fluxes, stage copies and
/// the coupling buffers (about 50 f64).
const BYTES_PER_GAS_CELL: f64 = 500.0;
/// Per fluid cell without gas: voidage and coupling buffers only.
const BYTES_PER_DEM_CELL: f64 = 128.0;
/// Per square-grid box: its solid volume and a few (cell, fraction) entries.
const BYTES_PER_BOX: f64 = 48.0;
/// A snapshot exists about three times at once (the fields, their encoding, the event payload).
const SNAPSHOT_COPIES: f64 = 3.0;

/// Packing estimate and overpour of the bed generator (`dem::bed`): count = ⌈0.60·A·H/V_p·1.15⌉.
const PACKING_ESTIMATE: f64 = 0.60;
const OVERPOUR: f64 = 1.15;

/// What a case implies, in counts and bytes (f64 so that absurd cases do not overflow).
#[derive(Clone, Debug, PartialEq)]
pub struct CaseSize {
    /// Particles at the largest point of the run (the pour for a settled height).
    pub particles: f64,
    pub cells: f64,
    /// Square-grid boxes (0 for other voidage methods).
    pub boxes: f64,
    pub snapshot_bytes: f64,
    pub snapshots: f64,
    /// Estimated peak memory of the job.
    pub memory_bytes: f64,
}

impl CaseSize {
    pub fn of(case: &Case) -> CaseSize {
        let rad = case.column.diameter_m / 2.0;
        let area = std::f64::consts::PI * rad * rad;
        let particles = match &case.bed {
            Bed::Generated(g) => match (g.count, g.settled_height_m) {
                (Some(n), _) => n as f64,
                (None, Some(h)) => (PACKING_ESTIMATE * area * h / case.particle_volume_m3() * OVERPOUR).ceil(),
                (None, None) => 0.0,
            },
            Bed::Explicit(e) => e.positions_m.len() as f64,
        };
        let (dr, dz) = (case.grid.dr_m, case.grid_dz_m());
        let nr = (rad / dr).round().max(1.0);
        let nz = (case.column.height_m / dz).round().max(1.0);
        let cells = if dr > 0.0 && dz > 0.0 { case.grid.n0 as f64 * nr * nr * nz } else { f64::INFINITY };
        let boxes = match &case.voidage {
            Voidage::SquareGrid { box_side_m, .. } => {
                let dl =
                    box_side_m.unwrap_or_else(|| default_box_side(case.column.diameter_m, case.particles.diameter_m));
                let nb = (case.column.diameter_m / dl).ceil() + 2.0;
                if dl > 0.0 {
                    nb * nb * nz
                } else {
                    f64::INFINITY
                }
            }
            _ => 0.0,
        };
        let gas = case.gas.is_some();
        let fields = &case.outputs.fields;
        let per_cell = |f: Field, n: f64| if fields.contains(&f) { 8.0 * n } else { 0.0 };
        let snapshot_bytes = per_cell(Field::Voidage, cells)
            + if gas { per_cell(Field::Pressure, cells) + per_cell(Field::GasVelocity, 3.0 * cells) } else { 0.0 }
            + per_cell(Field::Particles, 6.0 * particles);
        let snapshots = (case.end_time_s / case.outputs.snapshot_interval_s).ceil() + 1.0;
        let per_fluid_cell = if gas { BYTES_PER_GAS_CELL } else { BYTES_PER_DEM_CELL };
        let memory_bytes = particles * BYTES_PER_PARTICLE
            + cells * per_fluid_cell
            + boxes * BYTES_PER_BOX
            + SNAPSHOT_COPIES * snapshot_bytes;
        CaseSize { particles, cells, boxes, snapshot_bytes, snapshots, memory_bytes }
    }

    /// The field that most of the memory estimate comes from (its JSON pointer).
    fn largest_term(&self, case: &Case) -> &'static str {
        let gas = case.gas.is_some();
        let terms = [
            (self.particles * BYTES_PER_PARTICLE, particles_pointer(case)),
            (self.cells * if gas { BYTES_PER_GAS_CELL } else { BYTES_PER_DEM_CELL }, "/grid/dr_m"),
            (self.boxes * BYTES_PER_BOX, "/voidage/box_side_m"),
            (SNAPSHOT_COPIES * self.snapshot_bytes, "/outputs/fields"),
        ];
        terms.iter().fold((f64::NEG_INFINITY, ""), |a, t| if t.0 > a.0 { *t } else { a }).1
    }

    /// A problem when the estimated memory exceeds `limit_bytes` (a server's per-job limit).
    pub fn memory_problem(&self, case: &Case, limit_bytes: u64) -> Option<Problem> {
        beyond(self.memory_bytes, limit_bytes as f64).then(|| {
            problem(
                self.largest_term(case),
                Value::Null,
                format!("a case of at most {} of memory on this server (--max-job-memory)", gib(limit_bytes as f64)),
                format!(
                    "the run would need about {} ({:.3e} particles, {:.3e} cells, {:.3e} boxes, {} per snapshot)",
                    gib(self.memory_bytes),
                    self.particles,
                    self.cells,
                    self.boxes,
                    gib(self.snapshot_bytes)
                ),
            )
        })
    }
}

/// `coupling::voidage::default_box_side` in closed form (no loop, whatever d is): D / n with n the
/// power of two where D/(2n) <= d < D/n.
fn default_box_side(column_diameter: f64, d: f64) -> f64 {
    let n = ((column_diameter / d).log2().ceil().exp2() / 2.0).max(1.0);
    column_diameter / n
}

fn particles_pointer(case: &Case) -> &'static str {
    match &case.bed {
        Bed::Generated(g) if g.count.is_some() => "/bed/generated/count",
        Bed::Generated(_) => "/bed/generated/settled_height_m",
        Bed::Explicit(_) => "/bed/explicit/positions_m",
    }
}

/// x above `max`, or not a number (an absurd case may give NaN or ∞).
fn beyond(x: f64, max: f64) -> bool {
    !matches!(x.partial_cmp(&max), Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal))
}

fn gib(bytes: f64) -> String {
    format!("{:.3} GiB", bytes / (1u64 << 30) as f64)
}

fn problem(path: &str, value: Value, allowed: String, message: String) -> Problem {
    Problem { path: path.into(), value, allowed, message, severity: Severity::Error }
}

fn value_at(case: &Case, pointer: &str) -> Value {
    serde_json::to_value(case).ok().and_then(|v| v.pointer(pointer).cloned()).unwrap_or(Value::Null)
}

/// Every fixed bound the case breaks, each naming the field to change.
pub fn check(case: &Case) -> Vec<Problem> {
    let s = CaseSize::of(case);
    let mut out = Vec::new();
    if case.name.len() > MAX_NAME_BYTES {
        out.push(problem(
            "/name",
            Value::String(format!("{} bytes", case.name.len())),
            format!("at most {MAX_NAME_BYTES} bytes"),
            "job name too long".into(),
        ));
    }
    if beyond(s.particles, MAX_PARTICLES) {
        let p = particles_pointer(case);
        out.push(problem(
            p,
            value_at(case, p).as_array().map_or_else(|| value_at(case, p), |a| a.len().into()),
            format!("a bed of at most {MAX_PARTICLES:.0} particles"),
            format!("the bed would hold about {:.3e} particles", s.particles),
        ));
    }
    if beyond(s.cells, MAX_CELLS) {
        out.push(problem(
            "/grid/dr_m",
            value_at(case, "/grid/dr_m"),
            format!("a grid of at most {MAX_CELLS:.0} cells (n0·N_r²·N_z): a larger dr, dz or smaller n0"),
            format!("the grid would have {:.3e} cells", s.cells),
        ));
    }
    if beyond(s.boxes, MAX_BOXES) {
        out.push(problem(
            "/voidage/box_side_m",
            value_at(case, "/voidage/box_side_m"),
            format!("at most {MAX_BOXES:.0} boxes (nb²·N_z): larger boxes or a larger dz"),
            format!("the square grid would have {:.3e} boxes", s.boxes),
        ));
    }
    if beyond(s.snapshot_bytes, MAX_SNAPSHOT_BYTES) {
        out.push(problem(
            "/outputs/fields",
            value_at(case, "/outputs/fields"),
            format!("snapshots of at most {}", gib(MAX_SNAPSHOT_BYTES)),
            format!("one snapshot would take {}", gib(s.snapshot_bytes)),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn case(v: Value) -> Case {
        serde_json::from_value(v).expect("case parses")
    }

    #[test]
    fn the_counts_follow_the_generator_and_the_grid() {
        let c = case(json!({
            "column": { "diameter_m": 0.044, "height_m": 0.12 }, "particles": {},
            "bed": { "generated": { "settled_height_m": 0.03 } }, "gas": {}, "grid": { "dr_m": 0.0044, "n0": 3 }
        }));
        let s = CaseSize::of(&c);
        // 0.60·π·0.022²·0.03 / (π·0.0012³/6) · 1.15 (dem::bed) and 3·5²·27 cells.
        let expected = (0.60 * 0.022f64.powi(2) * 0.03 * 6.0 / 0.0012f64.powi(3) * 1.15).ceil();
        assert_eq!(s.particles, expected);
        assert_eq!(s.cells, 3.0 * 25.0 * 27.0);
        assert!(check(&c).is_empty());
        assert!(s.memory_problem(&c, 8 << 30).is_none());
        assert!(s.memory_problem(&c, 1 << 20).is_some());
    }

    #[test]
    fn absurd_cases_name_their_field_without_overflowing() {
        let c = case(json!({
            "column": { "diameter_m": 5.0, "height_m": 50.0 }, "particles": {},
            "bed": { "generated": { "settled_height_m": 10.0 } }, "grid": { "dr_m": 0.0025, "n0": 64 }
        }));
        let paths: Vec<String> = check(&c).into_iter().map(|p| p.path).collect();
        assert!(paths.contains(&"/bed/generated/settled_height_m".to_string()), "{paths:?}");
        assert!(paths.contains(&"/grid/dr_m".to_string()), "{paths:?}");
        let zero = case(
            json!({ "column": {}, "particles": { "diameter_m": 0.0 }, "bed": { "generated": { "count": 10 } }, "grid": { "dr_m": 0.0 } }),
        );
        assert!(check(&zero).iter().any(|p| p.path == "/grid/dr_m"));
    }
}
