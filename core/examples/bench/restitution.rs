//! The DEM step against the error it costs (`bench -- restitution`): the normal restitution of a
//! sphere of the paper's particles hitting the plate at 0.3 and 3 m/s, no gravity, at steps from
//! t_c/10 to t_c/50 of the undamped Hertz contact time at that speed and at the shipped 1.25 µs,
//! against the analytic e(α) = exp(−πα/√(5 − α²)) (PHYSICS.md 2.4). Cost of a run is ∝ 1/dt.

use fluidbed_core::case::{restitution_from_alpha, Bed, Case, ExplicitBed};
use fluidbed_core::dem::DemSystem;
use serde_json::json;

/// The measured e at step `dt` and speed `v0`.
fn measured_e(case: &Case, dt: f64, v0: f64) -> f64 {
    let mut c = case.clone();
    c.dem.time_step_s = dt;
    let r = c.particles.diameter_m / 2.0;
    let gap = 10.0 * v0 * dt;
    let mut sys = DemSystem::new(&c, vec![[0.0, 0.0, r + gap]], vec![[0.0, 0.0, -v0]]);
    let (mut touched, mut apart) = (false, 0);
    for _ in 0..1_000_000 {
        sys.step();
        let sep = sys.positions()[0][2] - r;
        touched |= sep < 0.0;
        apart = if touched && sep > 0.0 { apart + 1 } else { 0 };
        if apart == 5 {
            break;
        }
    }
    sys.velocities()[0][2] / v0
}

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
            let e = measured_e(&case, dt, v0);
            println!(
                "{}",
                json!({"bench": "restitution", "impact_m_s": v0, "step": label, "dt_s": dt, "t_c_s": tc,
                "steps_per_contact": tc / dt, "e": e, "e_analytic": expect, "error": e - expect})
            );
        }
    }
}
