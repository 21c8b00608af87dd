//! The walls' vertical loads (`DemSystem::wall_loads`) against statics: a sphere at rest on the
//! plate is carried by it (load m g), and a sphere pressed against the tube by a horizontal force
//! F while it slides down feels the Coulomb friction μF upwards (Amontons; F is small enough,
//! μF < 2/7 m g, that the sphere cannot roll instead).

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
