//! The batched pair kernel (fast path) evaluates exactly the scalar contact law of
//! `contact::contact_force` (PHYSICS.md 2.2-2.3): same forces, torques and history, bit for bit.

use super::{test_case, with_damping};
use crate::dem::contact::contact_force;
use crate::dem::pair_batch::Batch;
use crate::dem::DemParams;
use rand::{Rng, SeedableRng};

#[test]
fn batched_pair_kernel_equals_the_scalar_contact_law() {
    let case = with_damping(test_case(0.02, 0.02, false, 9.81, 1e-6), 0.1, 0.05, 0.3);
    let p = DemParams::new(&case);
    let r = p.radius;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    let mut u = |s: f64| (rng.gen::<f64>() * 2.0 - 1.0) * s;
    let n = 40;
    // Particle 2l and 2l+1 touch with a random overlap and random motion; random histories.
    let mut x = Vec::new();
    for l in 0..n {
        let dir = [u(1.0), u(1.0), u(1.0)];
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        let dist = 2.0 * r * (1.0 - 0.01 * rng_frac(l));
        x.push([0.0, 0.0, 0.0]);
        x.push([dir[0] / len * dist, dir[1] / len * dist, dir[2] / len * dist]);
    }
    let v: Vec<[f64; 3]> = (0..2 * n).map(|_| [u(1.0), u(1.0), u(1.0)]).collect();
    let w: Vec<[f64; 3]> = (0..2 * n).map(|_| [u(500.0), u(500.0), u(500.0)]).collect();
    let shear0: Vec<[f64; 3]> = (0..n).map(|_| [u(1e-6), u(1e-6), u(1e-6)]).collect();
    let mut batch = Batch::new();
    for l in 0..n {
        let (i, j) = (2 * l, 2 * l + 1);
        let dx = [x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]];
        batch.set(l, l, i, j, dx, dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
    }
    batch.m = n;
    let mut shear = shear0.clone();
    batch.evaluate::<true>(&p.pair, r, p.dt, &v, &w, &mut shear, 0);
    let mut slid = 0;
    for l in 0..n {
        let (i, j) = (2 * l, 2 * l + 1);
        let dx = [x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]];
        let dist = (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]).sqrt();
        let inv = 1.0 / dist;
        let nrm = [dx[0] * inv, dx[1] * inv, dx[2] * inv];
        let vrel = [v[i][0] - v[j][0], v[i][1] - v[j][1], v[i][2] - v[j][2]];
        let ws = [r * (w[i][0] + w[j][0]), r * (w[i][1] + w[j][1]), r * (w[i][2] + w[j][2])];
        let mut s = shear0[l];
        let cf = contact_force::<true>(&p.pair, 2.0 * r - dist, nrm, vrel, ws, &mut s, p.dt);
        assert_eq!([batch.f[0][l], batch.f[1][l], batch.f[2][l]], cf.f, "force of pair {l}");
        assert_eq!([batch.c[0][l], batch.c[1][l], batch.c[2][l]], cf.c, "torque of pair {l}");
        assert_eq!(shear[l], s, "history of pair {l}");
        slid += (cf.excess > -1e-30) as usize;
    }
    assert!(slid > 0 && slid < n, "both sticking and sliding pairs exercised ({slid} of {n} slid)");
}

fn rng_frac(l: usize) -> f64 {
    ((l * 37 % 41) as f64 + 0.5) / 41.0
}
