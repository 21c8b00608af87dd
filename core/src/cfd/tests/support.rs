//! Small cases and grids for the gas tests.

use crate::case::{Case, Gas};
use crate::cfd::GasSolver;
use crate::grid::CylGrid;

/// A case with the given gas section, gravity and a column of radius R and height H.
pub fn case_with(gas: Gas, gravity: f64, radius: f64, height: f64) -> Case {
    let json = format!(
        r#"{{"column":{{"diameter_m":{},"height_m":{}}},"particles":{{}},"bed":{{"generated":{{"settled_height_m":0.002}}}}}}"#,
        2.0 * radius,
        height
    );
    let mut c: Case = serde_json::from_str(&json).expect("case");
    c.gas = Some(gas);
    c.gravity_m_s2 = gravity;
    c
}

/// A solver on an nr × nz grid of spacing dr, dz (n0 = 3).
pub fn solver(gas: Gas, gravity: f64, nr: usize, dr: f64, nz: usize, dz: f64) -> GasSolver {
    let (radius, height) = (nr as f64 * dr, nz as f64 * dz);
    let case = case_with(gas, gravity, radius, height);
    GasSolver::new(&case, CylGrid::new(radius, height, dr, dz, 3))
}

/// Mean over a layer of a per-cell quantity.
pub fn layer_mean(s: &GasSolver, k: usize, f: impl Fn(usize) -> f64) -> f64 {
    let per = s.grid().cells_per_layer();
    (0..per).map(|c| f(k * per + c)).sum::<f64>() / per as f64
}
