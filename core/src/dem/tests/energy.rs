//! Without damping (and without friction, which dissipates by sliding) the contact law is
//! conservative: kinetic + Hertz elastic (2/5 K_n δ^{5/2}) + gravity potential stays constant
//! over many collisions with each other, the tube, the plate and the lid.

use super::{test_case, with_damping};
use crate::dem::DemSystem;
use rand::{Rng, SeedableRng};

/// `n` non-overlapping particles at random in a tube of radius `rt` and height `h`.
pub fn random_gas(n: usize, rt: f64, h: f64, r: f64, speed: f64, seed: u64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut x: Vec<[f64; 3]> = Vec::new();
    while x.len() < n {
        let p = [
            (rng.gen::<f64>() * 2.0 - 1.0) * rt,
            (rng.gen::<f64>() * 2.0 - 1.0) * rt,
            r + rng.gen::<f64>() * (h - 2.0 * r),
        ];
        let inside = (p[0] * p[0] + p[1] * p[1]).sqrt() < rt - 1.05 * r;
        if inside && x.iter().all(|q| (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>() > 4.4 * r * r) {
            x.push(p);
        }
    }
    let v = (0..n).map(|_| [0; 3].map(|_| (rng.gen::<f64>() * 2.0 - 1.0) * speed)).collect();
    (x, v)
}

#[test]
fn energy_is_conserved_without_damping() {
    let (col_d, h, g) = (0.008, 0.008, 9.81);
    let case = with_damping(test_case(col_d, h, true, g, 2.5e-7), 0.0, 0.0, 0.0);
    let r = case.particles.diameter_m / 2.0;
    let (x, v) = random_gas(40, col_d / 2.0, h, r, 0.5, 3);
    let mut sys = DemSystem::new(&case, x, v);
    let m = case.particle_mass_kg();
    let total = |s: &DemSystem| {
        s.kinetic_energy() + s.elastic_energy() + s.positions().iter().map(|p| m * g * p[2]).sum::<f64>()
    };
    let e0 = total(&sys);
    let mut contacts_seen = 0usize;
    let mut worst: f64 = 0.0;
    for s in 0..40_000 {
        sys.step();
        if sys.max_overlap_fraction() > 0.0 {
            contacts_seen += 1;
        }
        if s % 100 == 0 {
            worst = worst.max((total(&sys) - e0).abs() / e0);
        }
    }
    assert!(contacts_seen > 10_000, "too few contact steps ({contacts_seen}) to test anything");
    assert!(worst < 1e-4, "relative energy error {worst}");
}
