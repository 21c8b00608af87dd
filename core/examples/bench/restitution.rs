//! The DEM step against the error it costs (`bench -- restitution`): the normal restitution of a
//! sphere of the paper's particles hitting the plate at 0.3 and 3 m/s, no gravity, at steps from
//! t_c/10 to t_c/50 of the undamped Hertz contact time at that speed and at the shipped 1.25 µs,
//! against the analytic e(α) = exp(−πα/√(5 − α²)) (PHYSICS.md 2.4). Cost of a run is ∝ 1/dt.

use fluidbed_core::case::{restitution_from_alpha, Bed, ExplicitBed};
use fluidbed_core::dem::plate_impact;
use serde_json::json;

pub fn run() {
    let mut case = crate::coupled::shipped_case("bubbling-44mm.json");
    case.gravity_m_s2 = 0.0;
    case.gas = None;
    case.column.diameter_m = 0.02;
    case.column.height_m = 0.04;
    case.bed = Bed::Explicit(ExplicitBed { positions_m: vec![[0.0, 0.0, 0.01]], velocities_m_s: None });
    let p = &case.particles;
    let alpha = p.normal_damping.alpha();
    let expect = restitution_from_alpha(alpha);
    let (r, m) = (p.diameter_m / 2.0, p.density_kg_m3 * std::f64::consts::PI * p.diameter_m.powi(3) / 6.0);
    let e_star = p.youngs_modulus_pa / (2.0 * (1.0 - p.poisson_ratio * p.poisson_ratio));
    for v0 in [0.3, 3.0] {
        // Undamped Hertz contact time on the plate (m* = m, R* = R; PHYSICS.md 2.4).
        let tc = 2.868 * (m * m / (r * e_star * e_star * v0)).powf(0.2);
        for (label, dt) in
            [("t_c/10", tc / 10.0), ("t_c/20", tc / 20.0), ("t_c/50", tc / 50.0), ("shipped 1.25 µs", 1.25e-6)]
        {
            let e = plate_impact(&case, dt, v0).restitution;
            println!(
                "{}",
                json!({"bench": "restitution", "impact_m_s": v0, "step": label, "dt_s": dt, "t_c_s": tc,
                "steps_per_contact": tc / dt, "e": e, "e_analytic": expect, "error": e - expect})
            );
        }
    }
}
