//! A poured bed: particles never leave the tube or sink through the plate, and the settled
//! random packing has a solid fraction of 0.58-0.64 away from the walls (random close/loose
//! packing of frictional spheres, e.g. Scott & Kilgour 1969: 0.64; Onoda & Liniger 1990: 0.55-0.60).

use super::test_case;
use crate::dem::bed::{build_bed, cache_key, generate};
use crate::dem::DemSystem;

/// Solid fraction inside r < r_max, z0 < z < z1 by sampling a regular lattice of points.
fn solid_fraction(x: &[[f64; 3]], r: f64, r_max: f64, z0: f64, z1: f64) -> f64 {
    let h = r / 6.0;
    let d = 2.0 * r;
    let n = (2.0 * r_max / d).ceil() as usize + 1;
    let nz = ((z1 - z0) / d).ceil() as usize + 3;
    let mut cells = vec![Vec::new(); n * n * nz];
    let cell = |p: &[f64; 3]| -> Option<usize> {
        let cx = ((p[0] + r_max) / d).floor();
        let cy = ((p[1] + r_max) / d).floor();
        let cz = ((p[2] - (z0 - d)) / d).floor();
        let ok = cx >= 0.0 && cy >= 0.0 && cz >= 0.0 && (cx as usize) < n && (cy as usize) < n && (cz as usize) < nz;
        ok.then(|| ((cz as usize) * n + cy as usize) * n + cx as usize)
    };
    for p in x {
        for dz in [-1.0, 0.0, 1.0] {
            for dy in [-1.0, 0.0, 1.0] {
                for dx in [-1.0, 0.0, 1.0] {
                    if let Some(c) = cell(&[p[0] + dx * d, p[1] + dy * d, p[2] + dz * d]) {
                        if !cells[c].contains(p) {
                            cells[c].push(*p);
                        }
                    }
                }
            }
        }
    }
    let (mut inside, mut total) = (0usize, 0usize);
    let m = (2.0 * r_max / h) as i64;
    for kz in 0..((z1 - z0) / h) as i64 {
        for ky in -m / 2..=m / 2 {
            for kx in -m / 2..=m / 2 {
                let q = [kx as f64 * h, ky as f64 * h, z0 + (kz as f64 + 0.5) * h];
                if q[0] * q[0] + q[1] * q[1] > r_max * r_max {
                    continue;
                }
                total += 1;
                let c = cell(&q).expect("sample point inside grid");
                if cells[c].iter().any(|p| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>() < r * r) {
                    inside += 1;
                }
            }
        }
    }
    inside as f64 / total as f64
}

#[test]
fn poured_bed_stays_in_the_column_and_packs_randomly() {
    // Narrow column (16 d), softer particles (E = 12 MPa) and a 4 µs step keep this fast; the
    // packing of frictional spheres hardly depends on E at these tiny overlaps.
    let mut case = test_case(0.0192, 0.05, false, 9.81, 4e-6);
    case.particles.youngs_modulus_pa = 1.2e7;
    let d = case.particles.diameter_m;
    let (r, rt) = (d / 2.0, case.column.diameter_m / 2.0);
    let mut worst_wall: f64 = f64::NEG_INFINITY;
    let mut worst_coulomb: f64 = f64::NEG_INFINITY;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let (x, _) = pool
        .install(|| {
            generate(
                &case,
                Some(2500),
                None,
                5,
                Some(&mut |s: &DemSystem| {
                    for p in s.positions() {
                        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
                        worst_wall = worst_wall.max(rho - rt).max(-p[2]);
                    }
                    worst_coulomb = worst_coulomb.max(s.max_coulomb_excess());
                }),
            )
        })
        .unwrap();
    assert_eq!(x.len(), 2500);
    assert!(worst_wall < -0.9 * r, "a particle centre came within {} of the wall", -worst_wall);
    // Relative, in squared forces; the pair law runs in single precision (PHYSICS.md 2.3's limit
    // holds to its round-off: 6.2e-7 seen here, 3e-7 in |F_t|).
    assert!(worst_coulomb <= 1e-5, "Coulomb limit broken: {worst_coulomb}");
    let mut z: Vec<f64> = x.iter().map(|p| p[2]).collect();
    z.sort_by(f64::total_cmp);
    let top = z[(0.98 * z.len() as f64) as usize];
    let phi = solid_fraction(&x, r, rt - 2.0 * d, 2.0 * d, top - 2.0 * d);
    assert!((0.58..=0.64).contains(&phi), "solid fraction {phi}");
}

#[test]
fn generated_bed_is_cached_and_reproducible() {
    let mut case = test_case(0.0096, 0.05, false, 9.81, 4e-6);
    case.particles.youngs_modulus_pa = 1.2e7;
    case.bed =
        crate::case::Bed::Generated(crate::case::GeneratedBed { settled_height_m: None, count: Some(150), seed: 9 });
    let dir = std::env::temp_dir().join(format!("fluidbed-bed-cache-{}", std::process::id()));
    let a = build_bed(&case, Some(&dir)).unwrap();
    assert!(dir.join(format!("bed-{:016x}.bin", cache_key(&case))).exists());
    let b = build_bed(&case, Some(&dir)).unwrap(); // from the cache
    let c = build_bed(&case, None).unwrap(); // poured again
    assert_eq!(a, b);
    assert_eq!(a, c);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn settled_height_mode_fills_the_column_to_the_requested_height() {
    // Height mode: pour enough particles, cut at H, relax. The bed top (highest particle top)
    // must end within one diameter of H, and every particle inside the tube and above the plate.
    let mut case = test_case(0.0192, 0.05, false, 9.81, 4e-6);
    case.particles.youngs_modulus_pa = 1.2e7;
    let d = case.particles.diameter_m;
    let (r, rt, h) = (d / 2.0, case.column.diameter_m / 2.0, 0.008);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let (x, _) = pool.install(|| generate(&case, None, Some(h), 3, None)).unwrap();
    let top = x.iter().map(|p| p[2] + r).fold(0.0, f64::max);
    assert!((top - h).abs() <= d, "bed top {top} m, requested {h} m");
    // A full column: the count is near φ π R_t² H / V_p for a random packing (φ ≈ 0.6).
    let expect = 0.6 * std::f64::consts::PI * rt * rt * h / case.particle_volume_m3();
    assert!((x.len() as f64 / expect - 1.0).abs() < 0.15, "{} particles, expected about {expect:.0}", x.len());
    for p in &x {
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        assert!(rho + r - rt < 0.02 * d && p[2] - r > -0.02 * d, "particle at {p:?} outside the tube");
    }
}
