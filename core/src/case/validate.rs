//! Case validation: every problem at once, each with its JSON pointer, the value and the
//! allowed range; physics checks (contact time, bed size, cell size) as well as ranges.

use super::*;
use serde::Serialize;
use serde_json::Value;

#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    Error,
    Warning,
}

/// One problem with a case.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Problem {
    /// JSON pointer (RFC 6901) of the offending field, e.g. `/particles/diameter_m`.
    pub path: String,
    /// The value given (null when missing).
    pub value: Value,
    /// The allowed range or form.
    pub allowed: String,
    pub message: String,
    pub severity: Severity,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {} (got {}; allowed: {})", self.path, self.message, self.value, self.allowed)
    }
}

/// Errors refuse the case; warnings are reported and the case runs.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ValidationReport {
    pub errors: Vec<Problem>,
    pub warnings: Vec<Problem>,
}

impl ValidationReport {
    pub fn is_ok(&self) -> bool {
        self.errors.is_empty()
    }
    fn push(
        &mut self,
        severity: Severity,
        path: &str,
        value: Value,
        allowed: impl Into<String>,
        message: impl Into<String>,
    ) {
        let p = Problem { path: path.into(), value, allowed: allowed.into(), message: message.into(), severity };
        match severity {
            Severity::Error => self.errors.push(p),
            Severity::Warning => self.warnings.push(p),
        }
    }
    pub(super) fn error(
        &mut self,
        path: &str,
        value: impl Into<Value>,
        allowed: impl Into<String>,
        message: impl Into<String>,
    ) {
        self.push(Severity::Error, path, value.into(), allowed, message)
    }
    pub(super) fn warn(
        &mut self,
        path: &str,
        value: impl Into<Value>,
        allowed: impl Into<String>,
        message: impl Into<String>,
    ) {
        self.push(Severity::Warning, path, value.into(), allowed, message)
    }
    /// Error unless lo <= x <= hi (with open ends when the flags say so); NaN is always an error.
    #[allow(clippy::too_many_arguments)]
    fn range(&mut self, path: &str, x: f64, lo: f64, lo_open: bool, hi: f64, hi_open: bool, what: &str) {
        let ok_lo = if lo_open { x > lo } else { x >= lo };
        let ok_hi = if hi_open { x < hi } else { x <= hi };
        if !(ok_lo && ok_hi && x.is_finite()) {
            let allowed =
                format!("{}{}, {}{}", if lo_open { "(" } else { "[" }, lo, hi, if hi_open { ")" } else { "]" });
            self.error(path, json_num(x), allowed, format!("{what} out of range"));
        }
    }
}

fn json_num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map(Value::Number).unwrap_or(Value::String(format!("{x}")))
}

/// Particles outside the column listed one by one; the rest are counted in one problem (a
/// 16-MiB bed of a million stray particles would otherwise answer with a million errors).
const MAX_LISTED_POSITIONS: usize = 20;

/// Top-level sections a case must state; everything else has the paper's defaults.
const REQUIRED: [&str; 3] = ["column", "particles", "bed"];

impl Case {
    /// Parse a JSON value into a case, reporting every structural problem (missing section,
    /// wrong type, unknown field) with its JSON pointer, then every range and physics problem.
    pub fn parse_value(v: &Value) -> Result<(Case, ValidationReport), ValidationReport> {
        let mut report = ValidationReport::default();
        let Some(obj) = v.as_object() else {
            report.error("", v.clone(), "a JSON object", "a case must be a JSON object");
            return Err(report);
        };
        for key in REQUIRED {
            if !obj.contains_key(key) {
                report.error(&format!("/{key}"), Value::Null, "an object", format!("missing required section `{key}`"));
            }
        }
        // Deserialize each section on its own so that errors in several sections all show.
        for (key, val) in obj {
            let wrapped = Value::Object([(key.clone(), val.clone())].into_iter().collect());
            if let Err(e) = serde_path_to_error::deserialize::<_, PartialCase>(wrapped) {
                let path = pointer_of(e.path());
                let value = pointer_value(v, &path);
                report.error(&path, value, "see the case schema (GET /v1/schema/case)", e.inner().to_string());
            }
        }
        if !report.is_ok() {
            return Err(report);
        }
        // What a section alone accepts and the case does not (a null `end_time_s` or `name`:
        // optional in `PartialCase`, not in `Case`) is named by its pointer too.
        let case: Case = match serde_path_to_error::deserialize(v.clone()) {
            Ok(c) => c,
            Err(e) => {
                let path = pointer_of(e.path());
                let value = pointer_value(v, &path);
                report.error(&path, value, "see the case schema (GET /v1/schema/case)", e.inner().to_string());
                return Err(report);
            }
        };
        let report = case.validate();
        if report.is_ok() {
            Ok((case, report))
        } else {
            Err(report)
        }
    }

    /// Parse JSON text (a syntax error is reported at path "" with its line and column).
    pub fn parse_str(s: &str) -> Result<(Case, ValidationReport), ValidationReport> {
        match super::strict_json::parse(s) {
            Ok(v) => Case::parse_value(&v),
            Err(super::strict_json::StrictJsonError::DuplicateKey { pointer, message }) => {
                let mut r = ValidationReport::default();
                r.error(&pointer, Value::Null, "each key once", message);
                Err(r)
            }
            Err(super::strict_json::StrictJsonError::Syntax(e)) => {
                let mut r = ValidationReport::default();
                r.error("", Value::Null, "valid JSON", format!("malformed JSON: {e}"));
                Err(r)
            }
        }
    }

    /// Every range and physics problem of an already-typed case.
    pub fn validate(&self) -> ValidationReport {
        let mut r = ValidationReport::default();
        let c = &self.column;
        r.range("/column/diameter_m", c.diameter_m, 0.0, true, 5.0, false, "column diameter");
        r.range("/column/height_m", c.height_m, 0.0, true, 50.0, false, "column height");
        let p = &self.particles;
        let d = p.diameter_m;
        r.range(
            "/particles/diameter_m",
            d,
            0.0,
            true,
            (c.diameter_m / 4.0).max(0.0),
            false,
            "particle diameter (at most a quarter of the column diameter)",
        );
        r.range("/particles/density_kg_m3", p.density_kg_m3, 0.0, true, 1e5, false, "particle density");
        r.range("/particles/youngs_modulus_pa", p.youngs_modulus_pa, 1e3, false, 1e13, false, "Young's modulus");
        r.range("/particles/poisson_ratio", p.poisson_ratio, 0.0, false, 0.5, true, "Poisson ratio");
        r.range("/particles/sliding_friction", p.sliding_friction, 0.0, false, 10.0, false, "sliding friction");
        for (name, damp) in [("normal_damping", p.normal_damping), ("tangential_damping", p.tangential_damping)] {
            match damp {
                Damping::TsujiAlpha(a) => {
                    r.range(&format!("/particles/{name}/tsuji_alpha"), a, 0.0, false, 2.0, false, "Tsuji damping α")
                }
                Damping::Restitution(e) => r.range(
                    &format!("/particles/{name}/restitution"),
                    e,
                    0.0,
                    true,
                    1.0,
                    false,
                    "restitution coefficient",
                ),
            }
        }
        r.range("/gravity_m_s2", self.gravity_m_s2, 0.0, false, 1000.0, false, "gravity");
        r.range("/end_time_s", self.end_time_s, 0.0, true, 1e6, false, "end time");
        self.validate_bed(&mut r);
        self.validate_dem(&mut r);
        let o = &self.outputs;
        r.range(
            "/outputs/snapshot_interval_s",
            o.snapshot_interval_s,
            self.dem.time_step_s.max(0.0),
            false,
            1e6,
            false,
            "snapshot interval (at least one DEM step)",
        );
        r.range(
            "/outputs/checkpoint_interval_s",
            o.checkpoint_interval_s,
            0.0,
            false,
            1e6,
            false,
            "checkpoint interval",
        );
        if self.end_time_s / o.snapshot_interval_s.max(1e-300) > 1e6 {
            r.error(
                "/outputs/snapshot_interval_s",
                json_num(o.snapshot_interval_s),
                format!(">= {}", self.end_time_s / 1e6),
                "more than a million snapshots",
            );
        }
        if let Some(g) = &self.gas {
            self.validate_gas(g, &mut r);
        }
        self.validate_analysis(&mut r);
        let n = self.coupling.interval_steps;
        if !(1..=1000).contains(&n) {
            r.error("/coupling/interval_steps", n, "[1, 1000]", "DEM steps between couplings out of range");
        } else if self.gas.is_some() && !self.dem.frozen {
            let (limit, why) = tested_hold(&self.coupling);
            if n as f64 * self.dem.time_step_s > limit * (1.0 + 1e-9) {
                r.warn(
                    "/coupling/interval_steps",
                    n,
                    format!(
                        "<= {} at this DEM step ({} µs between couplings)",
                        (limit / self.dem.time_step_s + 1e-9).floor(),
                        limit * 1e6
                    ),
                    why,
                );
            }
        }
        let m = self.coupling.drag_voidage_sublayers;
        if !(1..=8).contains(&m) {
            r.error("/coupling/drag_voidage_sublayers", m, "[1, 8]", "sub-layers of the drag voidage out of range");
        }
        self.validate_run(&mut r);
        r.errors.extend(super::bounds::check(self));
        r
    }

    /// The analysis window, its sampling (at most 10⁷ samples: its series grow with them) and heights.
    fn validate_analysis(&self, r: &mut ValidationReport) {
        let a = &self.analysis;
        r.range("/analysis/from_s", a.from_s, 0.0, false, 1e6, false, "analysis window start");
        let dt = self.dem.time_step_s.max(0.0);
        r.range(
            "/analysis/sample_interval_s",
            a.sample_interval_s,
            dt,
            false,
            1e6,
            false,
            "analysis sample interval (at least one DEM step)",
        );
        if a.sample_interval_s > 0.0 && self.end_time_s / a.sample_interval_s > 1e7 {
            r.error(
                "/analysis/sample_interval_s",
                json_num(a.sample_interval_s),
                format!(">= {}", self.end_time_s / 1e7),
                "more than ten million analysis samples",
            );
        }
        let h = self.column.height_m;
        if let Some([lo, hi]) = a.rise_heights_m {
            r.range("/analysis/rise_heights_m/0", lo, 0.0, false, h, false, "lower rise-velocity height");
            r.range("/analysis/rise_heights_m/1", hi, 0.0, false, h, false, "upper rise-velocity height");
            if lo >= hi {
                r.error(
                    "/analysis/rise_heights_m",
                    json_num(hi),
                    format!("> {lo}"),
                    "the upper height must be above the lower",
                );
            }
        }
        if a.profile_heights_m.len() > 100 {
            r.error(
                "/analysis/profile_heights_m",
                a.profile_heights_m.len(),
                "<= 100 heights",
                "too many profile heights",
            );
        }
        for (i, &z) in a.profile_heights_m.iter().enumerate().take(100) {
            r.range(&format!("/analysis/profile_heights_m/{i}"), z, 0.0, false, h, false, "profile height");
        }
        r.range("/analysis/bubble_voidage", a.bubble_voidage, 0.0, true, 1.0, true, "bubble voidage threshold");
    }

    fn validate_bed(&self, r: &mut ValidationReport) {
        let (d, rad, h) = (self.particles.diameter_m, self.column.diameter_m / 2.0, self.column.height_m);
        let area = std::f64::consts::PI * rad * rad;
        match &self.bed {
            Bed::Generated(g) => match (g.settled_height_m, g.count) {
                (Some(hb), None) => {
                    r.range(
                        "/bed/generated/settled_height_m",
                        hb,
                        d,
                        false,
                        h,
                        true,
                        "settled bed height (at least d, below the column top)",
                    );
                }
                (None, Some(n)) => {
                    if n == 0 || n > 20_000_000 {
                        r.error("/bed/generated/count", n, "[1, 20000000]", "particle count out of range");
                    }
                    // A random packing holds at most ~0.64 solids; the bed must fit in the column.
                    let hb = n as f64 * self.particle_volume_m3() / (0.6 * area);
                    if hb >= h {
                        r.error(
                            "/bed/generated/count",
                            n,
                            format!(
                                "a bed below the column top: at most {:.0}",
                                0.6 * area * h / self.particle_volume_m3()
                            ),
                            format!("{n} particles settle to about {hb:.4} m, above the column height {h} m"),
                        );
                    }
                }
                _ => r.error(
                    "/bed/generated",
                    serde_json::to_value(g).unwrap_or(Value::Null),
                    "exactly one of settled_height_m or count",
                    "give a settled height or a particle count, not both or neither",
                ),
            },
            Bed::Explicit(e) => {
                if e.positions_m.is_empty() {
                    r.error("/bed/explicit/positions_m", 0, "at least one particle", "no particles");
                }
                let mut outside = 0usize;
                for (i, x) in e.positions_m.iter().enumerate() {
                    let rr = (x[0] * x[0] + x[1] * x[1]).sqrt();
                    if !(rr <= rad - d / 2.0 + 1e-12
                        && x[2] >= d / 2.0 - 1e-12
                        && x[2] <= h
                        && x.iter().all(|v| v.is_finite()))
                    {
                        outside += 1;
                        if outside > MAX_LISTED_POSITIONS {
                            continue;
                        }
                        r.error(
                            &format!("/bed/explicit/positions_m/{i}"),
                            serde_json::to_value(x).unwrap_or(Value::Null),
                            format!("r <= {} m, {} m <= z <= {} m", rad - d / 2.0, d / 2.0, h),
                            "particle outside the column",
                        );
                    }
                }
                if outside > MAX_LISTED_POSITIONS {
                    r.error(
                        "/bed/explicit/positions_m",
                        outside,
                        format!("r <= {} m, {} m <= z <= {} m", rad - d / 2.0, d / 2.0, h),
                        format!("{outside} particles outside the column (the first {MAX_LISTED_POSITIONS} listed)"),
                    );
                }
                if let Some(v) = &e.velocities_m_s {
                    if v.len() != e.positions_m.len() {
                        r.error(
                            "/bed/explicit/velocities_m_s",
                            v.len(),
                            format!("{} entries, one per position", e.positions_m.len()),
                            "velocity count differs from position count",
                        );
                    }
                }
            }
        }
    }

    fn validate_dem(&self, r: &mut ValidationReport) {
        let dt = self.dem.time_step_s;
        r.range("/dem/time_step_s", dt, 0.0, true, 1e-2, false, "DEM time step");
        r.range("/dem/skin_fraction", self.dem.skin_fraction, 0.01, false, 2.0, false, "Verlet skin / d");
        if self.dem.threads > 1024 {
            r.error("/dem/threads", self.dem.threads, "[0, 1024]", "thread count out of range");
        }
    }

    /// `gas.inlet_jet`: whole inner annuli of the grid, a velocity in the bed's range, an ordered window.
    fn validate_inlet_jet(&self, j: &super::InletJet, r: &mut ValidationReport) {
        let (rad, dr) = (self.column.diameter_m / 2.0, self.grid.dr_m);
        let annuli = if dr > 0.0 && rad > 0.0 { (rad / dr).round().max(1.0) as usize } else { 1 };
        if j.annuli < 1 || j.annuli > annuli {
            r.error(
                "/gas/inlet_jet/annuli",
                j.annuli,
                format!("[1, {annuli}] (the grid's annuli of dr = {dr} m)"),
                "jet annuli out of range",
            );
        }
        r.range(
            "/gas/inlet_jet/superficial_velocity_m_s",
            j.superficial_velocity_m_s,
            0.0,
            false,
            100.0,
            false,
            "jet superficial velocity",
        );
        r.range("/gas/inlet_jet/from_s", j.from_s, 0.0, false, 1e6, false, "jet start");
        if let Some(until) = j.until_s {
            if !(until.is_finite() && until > j.from_s) {
                r.error(
                    "/gas/inlet_jet/until_s",
                    json_num(until),
                    format!("> from_s = {}", j.from_s),
                    "the jet must end after it starts",
                );
            }
        }
    }

    fn validate_gas(&self, g: &Gas, r: &mut ValidationReport) {
        r.range(
            "/gas/superficial_velocity_m_s",
            g.superficial_velocity_m_s,
            0.0,
            false,
            100.0,
            false,
            "superficial velocity",
        );
        r.range("/gas/ramp_time_s", g.ramp_time_s, 0.0, false, 1e4, false, "ramp time");
        r.range("/gas/temperature_k", g.temperature_k, 1.0, false, 5000.0, false, "temperature");
        r.range(
            "/gas/specific_gas_constant_j_kg_k",
            g.specific_gas_constant_j_kg_k,
            1.0,
            false,
            1e5,
            false,
            "specific gas constant",
        );
        r.range("/gas/viscosity_pa_s", g.viscosity_pa_s, 0.0, true, 1.0, false, "viscosity");
        r.range("/gas/bulk_viscosity_pa_s", g.bulk_viscosity_pa_s, 0.0, false, 1.0, false, "bulk viscosity");
        r.range("/gas/outlet_pressure_pa", g.outlet_pressure_pa, 1.0, false, 1e8, false, "outlet pressure");
        r.range("/gas/inlet_voidage", g.inlet_voidage, 0.0, true, 1.0, false, "inlet voidage");
        r.range("/gas/outlet_relaxation", g.outlet_relaxation, 0.0, false, 10.0, false, "outlet relaxation σ");
        r.range("/gas/drag_voidage_min", g.drag_voidage_min, 0.01, false, 0.9, false, "drag voidage clamp");
        r.range("/gas/cfl_factor", g.cfl_factor, 0.0, true, 1.0, false, "CFL safety factor");
        r.range(
            "/gas/acoustic_speed_factor",
            g.acoustic_speed_factor,
            0.01,
            false,
            1.0,
            false,
            "acoustic speed factor",
        );
        if let Some(dt) = g.time_step_s {
            // The gas sub-cycles: its step is a whole number of DEM steps, within the acoustic
            // CFL limit inside AB3's stability region (cfd::stability).
            r.range("/gas/time_step_s", dt, 0.0, true, 1.0, false, "gas time step");
            let dem = self.dem.time_step_s;
            if dt > 0.0 && dem > 0.0 {
                let n = dt / dem;
                if n < 1.0 - 1e-9 || (n - n.round()).abs() > 1e-6 * n {
                    r.error(
                        "/gas/time_step_s",
                        json_num(dt),
                        format!("a whole multiple of the DEM step {dem:e} s, e.g. {:e} s", dem * n.round().max(1.0)),
                        "the gas step must be a whole number of DEM steps",
                    );
                }
            }
            if let Some(limit) = crate::cfd::case_stable_time_step(self) {
                if dt > limit {
                    r.error(
                        "/gas/time_step_s",
                        json_num(dt),
                        format!("<= {limit:.4e} s (acoustic CFL limit with AB3, cfl_factor {})", g.cfl_factor),
                        format!("gas time step {dt:e} s exceeds the largest stable step {limit:.4e} s"),
                    );
                }
            }
        }
        let rad = self.column.diameter_m / 2.0;
        let gr = &self.grid;
        r.range("/grid/dr_m", gr.dr_m, 0.0, true, rad.max(0.0), false, "radial spacing");
        if gr.dr_m > 0.0 {
            let n = rad / gr.dr_m;
            if (n - n.round()).abs() > 1e-6 * n.max(1.0) {
                r.error(
                    "/grid/dr_m",
                    json_num(gr.dr_m),
                    format!(
                        "the column radius {rad} m divided by a whole number, e.g. {:.6}",
                        rad / n.round().max(1.0)
                    ),
                    "dr does not divide the radius into whole annuli",
                );
            }
        }
        if gr.n0 < 3 || gr.n0 > 64 {
            r.error("/grid/n0", gr.n0, "[3, 64]", "cells in the central annulus out of range");
        }
        if let Some(j) = &g.inlet_jet {
            self.validate_inlet_jet(j, r);
        }
        let dz = self.grid_dz_m();
        if let Some(dz) = gr.dz_m {
            r.range("/grid/dz_m", dz, 0.0, true, self.column.height_m, false, "axial spacing");
            let n = self.column.height_m / dz;
            if dz > 0.0 && (n - n.round()).abs() > 1e-6 * n.max(1.0) {
                r.error(
                    "/grid/dz_m",
                    json_num(dz),
                    format!(
                        "the column height divided by a whole number, e.g. {:.6}",
                        self.column.height_m / n.round().max(1.0)
                    ),
                    "dz does not divide the column into whole layers",
                );
            }
        }
        let d = self.particles.diameter_m;
        if gr.dr_m > 0.0 && (d >= gr.dr_m || d >= dz) {
            r.error(
                "/particles/diameter_m",
                json_num(d),
                format!("< min(dr, dz) = {} m", gr.dr_m.min(dz)),
                "particle larger than a fluid cell: volume averaging needs cells larger than the particles",
            );
        }
        if let Voidage::SquareGrid { box_side_m, cube_side_factor, .. } = &self.voidage {
            if let Some(b) = box_side_m {
                r.range("/voidage/box_side_m", *b, 0.0, true, self.column.diameter_m, false, "box side");
                if *b < d {
                    r.warn(
                        "/voidage/box_side_m",
                        json_num(*b),
                        format!(">= d = {d} m"),
                        "boxes smaller than a particle: the split is less smooth",
                    );
                }
            }
            r.range("/voidage/cube_side_factor", *cube_side_factor, 0.1, false, 2.0, false, "cuboid side / d");
        }
    }
}

/// The longest time between couplings (interval × DEM step) measured without the coupling's own
/// oscillation in a moving bed, for these coupling settings, and what happened beyond it
/// (docs/BENCHMARKS.md, "Longer intervals"); a longer one is a warning.
fn tested_hold(c: &super::Coupling) -> (f64, &'static str) {
    use super::{GasDrag, GasVoidage};
    if c.gas_voidage == GasVoidage::Held {
        (25e-6, "the gas's voidage held between couplings longer than tested: its steps at each coupling set off an oscillation (at 50 µs a bubbling bed's pressure drop fluctuated 4× the reference's); \"interpolated\" avoids them (docs/BENCHMARKS.md, \"Longer intervals\")")
    } else if c.gas_drag == GasDrag::Held {
        (50e-6, "the drag on the gas held longer than its relaxation time in a bed near U_mf (≈60 µs): the gas overshoots at each coupling; \"implicit\" is stable at any interval (docs/BENCHMARKS.md, \"Longer intervals\")")
    } else {
        (100e-6, "more time between couplings than tested (docs/BENCHMARKS.md, \"Longer intervals\")")
    }
}

/// The JSON pointer of a serde path (`bed.explicit.positions_m[3]` -> `/bed/explicit/positions_m/3`).
fn pointer_of(p: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for seg in p.iter() {
        match seg {
            Segment::Seq { index } => out.push_str(&format!("/{index}")),
            Segment::Map { key } | Segment::Enum { variant: key } => {
                out.push_str(&format!("/{}", key.replace('~', "~0").replace('/', "~1")))
            }
            Segment::Unknown => {}
        }
    }
    out
}

/// The value at a JSON pointer, or null.
fn pointer_value(v: &Value, path: &str) -> Value {
    v.pointer(path).cloned().unwrap_or(Value::Null)
}

/// A case whose sections are all optional: used to type-check one section at a time.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct PartialCase {
    name: Option<String>,
    column: Option<Column>,
    particles: Option<Particles>,
    bed: Option<Bed>,
    gravity_m_s2: Option<f64>,
    dem: Option<Dem>,
    end_time_s: Option<f64>,
    outputs: Option<Outputs>,
    gas: Option<Option<Gas>>,
    grid: Option<Grid>,
    voidage: Option<Voidage>,
    coupling: Option<super::Coupling>,
    analysis: Option<super::AnalysisSpec>,
}
