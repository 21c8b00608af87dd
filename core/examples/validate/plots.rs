//! PNG figures for docs/VALIDATION.md, drawn with the solver's own encoders (core/src/output).

use fluidbed_core::output::plot;
use fluidbed_core::sim::Snapshot;

fn save(img: &fluidbed_core::output::png::Image, path: &str) {
    if let Some(dir) = std::path::Path::new(path).parent() {
        std::fs::create_dir_all(dir).expect("figure dir");
    }
    std::fs::write(path, img.encode()).expect("write png");
    eprintln!("wrote {path}");
}

/// ΔP against time.
pub fn pressure_trace(points: &[(f64, f64)], path: &str) {
    let t: Vec<f64> = points.iter().map(|x| x.0).collect();
    let y: Vec<f64> = points.iter().map(|x| x.1).collect();
    save(&plot::trace(&t, &y), path);
}

/// ΔP against U from the minimum-fluidization sweep, with the weight and U_mf marked.
pub fn umf_curve(points: &[(f64, f64)], weight: f64, umf: f64, path: &str) {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    series_marked(&p, Some(weight), Some(umf), path);
}

/// A time series (t, y) with a red horizontal line at `level` (e.g. its expected or mean value).
pub fn series_with_level(points: &[(f64, f64)], level: f64, path: &str) {
    series_marked(points, Some(level), None, path);
}

fn series_marked(points: &[(f64, f64)], level: Option<f64>, at: Option<f64>, path: &str) {
    let t: Vec<f64> = points.iter().map(|x| x.0).collect();
    let y: Vec<f64> = points.iter().map(|x| x.1).collect();
    save(&plot::trace_marked(&t, &y, level, at), path);
}

/// A cell field on the vertical plane through the axis.
pub fn slice(s: &Snapshot, field: &[f64], lo: f64, hi: f64, path: &str) {
    save(&plot::axial_slice(&s.grid.grid(), field, lo, hi), path);
}
