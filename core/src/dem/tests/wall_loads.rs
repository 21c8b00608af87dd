//! The walls' vertical loads (`DemSystem::wall_loads`) against statics: a sphere at rest on the
//! plate is carried by it (load m g), and a sphere pressed against the tube by a horizontal force
//! F while it slides down feels the Coulomb friction μF upwards (Amontons; F is small enough,
//! μF < 2/7 m g, that the sphere cannot roll instead); and over a falling heap the loads and
//! gravity account for the change of momentum.

use super::{test_case, with_damping};
use crate::dem::DemSystem;

#[test]
fn plate_carries_a_resting_sphere_and_the_tube_resists_sliding_by_mu_f() {
    let (mu, g) = (0.3, 9.81);
    let case = with_damping(test_case(0.02, 0.05, false, g, 1.25e-6), 0.3, 0.3, mu);
    let (r, m) = (case.particles.diameter_m / 2.0, case.particle_mass_kg());
    let wall_r = case.column.diameter_m / 2.0;
    // resting on the plate near the axis
    let mut rest = DemSystem::new(&case, vec![[0.0, 0.0, r]], vec![[0.0; 3]]);
    for _ in 0..20_000 {
        rest.step();
    }
    let [plate, tube, lid] = rest.wall_loads();
    assert!((plate / (m * g) - 1.0).abs() < 1e-3, "plate load {plate}, m g = {}", m * g);
    assert_eq!((tube, lid), (0.0, 0.0));
    // pressed on the tube by F = m g / 2 well above the plate, falling
    let f = 0.5 * m * g;
    let mut slide = DemSystem::new(&case, vec![[wall_r - r, 0.0, 0.03]], vec![[0.0, 0.0, -0.1]]);
    for _ in 0..4_000 {
        slide.external_forces_mut()[0] = [f, 0.0, 0.0];
        slide.step();
    }
    let [plate, tube, _] = slide.wall_loads();
    assert!(slide.velocities()[0][2] < 0.0, "still sliding down");
    assert_eq!(plate, 0.0);
    assert!((tube / (mu * f) - 1.0).abs() < 1e-2, "tube load {tube}, μF = {}", mu * f);
}

/// Newton's second law for the whole particle set: pair forces cancel, so over a window the
/// change of total vertical momentum equals h Σ (plate + tube loads − N m g), up to AB3's
/// end terms (a few steps' worth of force). Particles thrown sideways fall onto the plate and
/// hit the tube, with friction and damping.
#[test]
fn wall_loads_account_for_the_momentum_change_of_a_falling_heap() {
    let (mu, g, dt) = (0.3, 9.81, 1.25e-6);
    let case = with_damping(test_case(0.01, 0.03, false, g, dt), 0.2, 0.2, mu);
    let (d, m) = (case.particles.diameter_m, case.particle_mass_kg());
    let (mut pos, mut vel) = (Vec::new(), Vec::new());
    for k in 0..4 {
        for j in 0..5 {
            for i in 0..5 {
                let s = 1.5 * d;
                pos.push([(i as f64 - 2.0) * s, (j as f64 - 2.0) * s, 0.002 + k as f64 * s]);
                // sideways and down, different for every particle (deterministic)
                let q = (i + 5 * j + 25 * k) as f64;
                vel.push([0.3 * (q * 0.7).sin(), 0.3 * (q * 1.3).cos(), -0.2]);
            }
        }
    }
    let n = pos.len() as f64;
    let mut sys = DemSystem::new(&case, pos, vel);
    for _ in 0..10 {
        sys.step(); // past the Heun / AB2 start
    }
    let p0 = sys.momentum()[2];
    let (mut impulse, mut tube_seen) = (0.0, 0.0f64);
    for _ in 0..40_000 {
        let [plate, tube, lid] = sys.wall_loads();
        tube_seen = tube_seen.max(tube.abs());
        impulse += dt * (plate + tube + lid - n * m * g);
        sys.step();
    }
    let dp = sys.momentum()[2] - p0;
    let scale = n * m * g * 40_000.0 * dt;
    assert!(dp > 0.5 * scale, "the heap landed: Δp = {dp}, N m g T = {scale}");
    assert!(tube_seen > 0.0, "some particles hit the tube");
    assert!((dp - impulse).abs() < 1e-4 * scale, "Δp = {dp}, wall and gravity impulse = {impulse}");
}
