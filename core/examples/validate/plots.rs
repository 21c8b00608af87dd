//! PNG figures for docs/VALIDATION.md, drawn with the solver's own encoders (core/src/output).

pub use fluidbed_core::output::plot::TraceLabels;
use fluidbed_core::output::plot::{self, FieldLabels};
use fluidbed_core::sim::Snapshot;

fn save(img: Result<fluidbed_core::output::png::Image, plot::PlotError>, path: &str) {
    let img = img.expect("figure drawn");
    if let Some(dir) = std::path::Path::new(path).parent() {
        std::fs::create_dir_all(dir).expect("figure dir");
    }
    std::fs::write(path, img.encode()).expect("write png");
    eprintln!("wrote {path}");
}

const DP_OVER_TIME: TraceLabels =
    TraceLabels { title: "Bed pressure drop", x: "time t [s]", y: "pressure drop ΔP [Pa]" };

/// ΔP against time.
pub fn pressure_trace(points: &[(f64, f64)], path: &str) {
    let t: Vec<f64> = points.iter().map(|x| x.0).collect();
    let y: Vec<f64> = points.iter().map(|x| x.1).collect();
    save(plot::trace(&t, &y, &DP_OVER_TIME), path);
}

/// ΔP against U from the minimum-fluidization sweep, with the weight and U_mf marked.
pub fn umf_curve(points: &[(f64, f64)], weight: f64, umf: f64, path: &str) {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    let labels = TraceLabels {
        title: "Minimum fluidization: ΔP against U (bed weight and U_mf in red)",
        x: "superficial gas velocity U [m/s]",
        y: "pressure drop ΔP [Pa]",
    };
    series_marked(&p, Some(weight), Some(umf), &labels, path);
}

/// ΔP against time with a red horizontal line at `level` (e.g. its expected or mean value).
pub fn dp_with_level(points: &[(f64, f64)], level: f64, path: &str) {
    series_marked(points, Some(level), None, &DP_OVER_TIME, path);
}

/// A time series (t, y) titled by `labels`, with a red horizontal line at `level`.
pub fn series_with_level(points: &[(f64, f64)], level: f64, labels: &TraceLabels, path: &str) {
    series_marked(points, Some(level), None, labels, path);
}

fn series_marked(points: &[(f64, f64)], level: Option<f64>, at: Option<f64>, labels: &TraceLabels, path: &str) {
    let t: Vec<f64> = points.iter().map(|x| x.0).collect();
    let y: Vec<f64> = points.iter().map(|x| x.1).collect();
    save(plot::trace_marked(&t, &y, level, at, labels), path);
}

/// A cell field on the vertical plane through the axis; `quantity` names it with its unit.
pub fn slice(s: &Snapshot, field: &[f64], quantity: &str, lo: f64, hi: f64, path: &str) {
    let title = format!("t = {:.4} s", s.time_s);
    save(plot::axial_slice(&s.grid.grid(), field, &FieldLabels { title: &title, quantity, lo, hi }), path);
}

/// The voidage on the axial plane of a snapshot, on the colour range of the bed pictures (0.35–1).
pub fn voidage_slice(s: &Snapshot, eps: &[f64], path: &str) {
    slice(s, eps, "voidage ε [-]", 0.35, 1.0, path);
}
