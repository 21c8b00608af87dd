//! The passes compiled for each path give the same bits as the portable ones, on random fields
//! with drag-free cells, flux reversals and both outlets.

use super::*;
use crate::cfd::geometry::FaceGeometry;
use crate::cfd::params::GasParams;
use crate::grid::CylGrid;
use rand::{Rng, SeedableRng};

/// Random state, primitives and axial faces of a 4-annulus, 6-layer column.
struct Fields {
    geo: FaceGeometry,
    params: GasParams,
    per: usize,
    nz: usize,
    dz: f64,
    eps: Vec<f64>,
    force: Vec<[f64; 3]>,
    face: Vec<f64>,
    q: Vec<[f64; 4]>,
    prim: [Vec<f64>; 10],
    axial: Vec<[f64; 7]>,
}

fn fields(outlet: Outlet, seed: u64) -> Fields {
    let (dr, dz, nz) = (0.004, 0.003, 6);
    let grid = CylGrid::new(4.0 * dr, nz as f64 * dz, dr, dz, 3);
    let geo = FaceGeometry::new(&grid);
    let (per, n) = (grid.cells_per_layer(), grid.num_cells());
    let params = GasParams {
        sound_speed: 343.0,
        viscosity: 1.8e-5,
        bulk_viscosity: 1e-4,
        gravity: 9.81,
        superficial_velocity: 0.5,
        ramp_time: 0.1,
        inlet_voidage: 1.0,
        outlet_relaxation: 0.02,
        outlet_pressure: 1.2 * 343.0 * 343.0,
        cfl_factor: 0.9,
        outlet,
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut u = |a: f64, b: f64| rng.gen_range(a..b);
    let eps: Vec<f64> = (0..n).map(|_| u(0.36, 1.0)).collect();
    // Every fifth cell drag-free (β = 0: the other branch of the face rate).
    let force: Vec<[f64; 3]> =
        (0..n).map(|c| if c % 5 == 0 { [0.0; 3] } else { [u(-50.0, 50.0), u(-50.0, 50.0), u(0.0, 6000.0)] }).collect();
    let face: Vec<f64> = (0..n + nz * geo.faces.len()).map(|_| u(-0.01, 0.01)).collect();
    // Velocities of both signs, so that axial fluxes reverse.
    let q: Vec<[f64; 4]> = (0..n)
        .map(|c| {
            let m = 1.2 * eps[c] * u(0.99, 1.01);
            [m, m * u(-0.3, 0.3), m * u(-0.3, 0.3), m * u(-0.5, 1.5)]
        })
        .collect();
    let prim = std::array::from_fn(|_| vec![0.0; n]);
    Fields { geo, params, per, nz, dz, eps, force, face, q, prim, axial: vec![[0.0; 7]; n] }
}

impl Fields {
    fn input(&self) -> RhsInput<'_> {
        RhsInput {
            geo: &self.geo,
            params: &self.params,
            per: self.per,
            nz: self.nz,
            dz: self.dz,
            eps: &self.eps,
            force: &self.force,
            face_flux: &self.face,
            time: 0.05,
            jet: None,
        }
    }
    fn view(&self) -> PrimView<'_> {
        let [ux, uy, uz, p, div, gx, gy, gz, beta, beta_over_eps2] = &self.prim;
        PrimView { ux, uy, uz, p, div, gx, gy, gz, beta, beta_over_eps2 }
    }
}

/// The passes of one right-hand side on one path; every output's bits.
type Passes = (
    fn(&RhsInput, &[[f64; 4]], usize, &mut [f64], &mut [f64], &mut [f64], &mut [f64], &mut [f64], &mut [f64]),
    fn(&RhsInput, &PrimView, usize, &mut [f64], &mut [f64], &mut [f64], &mut [f64]),
    fn(&RhsInput, &[[f64; 4]], &PrimView, usize, &mut [[f64; 7]], &mut [f64]),
    fn(&RhsInput, &[[f64; 4]], &PrimView, &[[f64; 7]], usize, &mut [[f64; 4]], &mut [f64]),
);

fn run(f: &mut Fields, passes: Passes) -> Vec<u64> {
    let (per, nz, nf) = (f.per, f.nz, f.geo.faces.len());
    let n = per * nz;
    let mut prim = std::mem::take(&mut f.prim);
    for k in 0..nz {
        let r = k * per..(k + 1) * per;
        let [ux, uy, uz, p, _, _, _, _, beta, bz] = &mut prim;
        (passes.0)(
            &f.input(),
            &f.q,
            k,
            &mut ux[r.clone()],
            &mut uy[r.clone()],
            &mut uz[r.clone()],
            &mut p[r.clone()],
            &mut beta[r.clone()],
            &mut bz[r],
        );
    }
    f.prim = prim.clone();
    for k in 0..nz {
        let r = k * per..(k + 1) * per;
        let [_, _, _, _, div, gx, gy, gz, _, _] = &mut prim;
        (passes.1)(&f.input(), &f.view(), k, &mut div[r.clone()], &mut gx[r.clone()], &mut gy[r.clone()], &mut gz[r]);
    }
    f.prim = prim;
    let (mut axial, mut rate) = (vec![[0.0; 7]; n], vec![0.0; n + nz * nf]);
    for k in 0..nz - 1 {
        let r = k * per..(k + 1) * per;
        (passes.2)(&f.input(), &f.q, &f.view(), k, &mut axial[r.clone()], &mut rate[r]);
    }
    f.axial = axial;
    let mut out = vec![[0.0; 4]; n];
    for k in 0..nz {
        let fr = n + k * nf..n + (k + 1) * nf;
        (passes.3)(&f.input(), &f.q, &f.view(), &f.axial, k, &mut out[k * per..(k + 1) * per], &mut rate[fr]);
    }
    let prim_bits = f.prim.iter().flatten().copied();
    let axial_bits = f.axial.iter().flatten().copied();
    prim_bits.chain(axial_bits).chain(out.into_iter().flatten()).chain(rate).map(f64::to_bits).collect()
}

#[test]
fn every_code_path_gives_the_same_bits() {
    let portable: Passes = (primitives_body, gradients_body, axial_body, residual_body);
    let mut paths: Vec<(&str, Passes)> =
        vec![("dispatched", (primitives_layer, gradients_layer, axial_layer, residual_layer))];
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        // The four passes compiled for one path. SAFETY: pushed only when the CPU has its features.
        macro_rules! on_path {
            ($path:ident) => {
                (
                    |a, b, c, d, e, f, g, h, i| unsafe { primitives_paths::$path(a, b, c, d, e, f, g, h, i) },
                    |a, b, c, d, e, f, g| unsafe { gradients_paths::$path(a, b, c, d, e, f, g) },
                    |a, b, c, d, e, f| unsafe { axial_paths::$path(a, b, c, d, e, f) },
                    |a, b, c, d, e, f, g| unsafe { residual_paths::$path(a, b, c, d, e, f, g) },
                )
            };
        }
        if has!("avx2") {
            paths.push(("avx2", on_path!(avx2)));
        }
        if has!("avx512f") && has!("avx512vl") && has!("avx512dq") {
            paths.push(("avx512", on_path!(avx512)));
        }
    }
    for outlet in [Outlet::Characteristic, Outlet::Wall] {
        for seed in 0..4 {
            let want = run(&mut fields(outlet, seed), portable);
            assert!(want.iter().all(|&b| f64::from_bits(b).is_finite()), "a finite right-hand side");
            for (name, passes) in &paths {
                assert!(
                    run(&mut fields(outlet, seed), *passes) == want,
                    "{name}, {outlet:?}, seed {seed}: the bits differ"
                );
            }
        }
    }
}
