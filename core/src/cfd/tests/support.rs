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

/// Beetstra, van der Hoef & Kuipers (2007) F = F0 + F1 (PHYSICS.md 1.1).
pub fn beetstra_f(eps: f64, re: f64) -> f64 {
    let phi = 1.0 - eps;
    let f0 = 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * phi.sqrt());
    if re <= 0.0 {
        return f0;
    }
    let f1 = 0.413 * re / (24.0 * eps * eps) * (1.0 / eps + 3.0 * eps * phi + 8.4 * re.powf(-0.343))
        / (1.0 + 10f64.powf(3.0 * phi) * re.powf(-(1.0 + 4.0 * phi) / 2.0));
    f0 + f1
}

/// One gas step through a bed at rest of voidage `eps` per cell (model A, PHYSICS.md 11):
/// I = −β_A u, β_A = 18μεφF(ε, Re)/d², Re = ρε|u|d/μ, Beetstra's F; panics on a non-finite state.
pub fn step_through_fixed_bed(s: &mut GasSolver, eps: &[f64], d: f64, mu: f64, dt: f64) {
    for (c, &e) in eps.iter().enumerate() {
        let (rho, u) = (s.density(c), s.velocity_cyl(c));
        let speed = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        let beta = 18.0 * mu * e * (1.0 - e) * beetstra_f(e, rho * e * speed * d / mu) / (d * d);
        s.interaction_force_mut()[c] = [-beta * u[0], -beta * u[1], -beta * u[2]];
    }
    s.step(dt);
    s.check_finite().unwrap_or_else(|e| panic!("{e}"));
}

/// The gas of the fixed-bed tests: inflow `u0` after a 2-ms ramp, viscosity `mu`, the zone above the
/// inlet (ε_in = 1), an outlet relaxed at σ = 0.25.
pub fn fixed_bed_gas(u0: f64, mu: f64) -> Gas {
    Gas {
        superficial_velocity_m_s: u0,
        ramp_time_s: 2e-3,
        inlet_voidage: 1.0,
        viscosity_pa_s: mu,
        outlet_relaxation: 0.25,
        ..Default::default()
    }
}
