//! The gas finds its way sideways: a porous zone whose two parts differ in voidage (inner annuli
//! against the outer one, or one half of the angles against the other) under a uniform inflow.
//! Far from the zone's ends the flow is axial in each part and the pressure is uniform across
//! each layer, so every part carries the superficial velocity of one common gradient G
//! (model A, PHYSICS.md 1.1 and 11): U_i = G ε_i d² / (18 μ φ_i F(ε_i, Re_i)), Re_i = ρ U_i d/μ,
//! with the parts' area-weighted U_i summing to the inflow U0. Tests the radial and angular
//! faces' fluxes and pressure forces of the equal-volume grid. A jet through the inner annuli
//! into a uniform zone spreads to the area-weighted mean velocity in every cell.

use super::support::{beetstra_f, fixed_bed_gas, solver, step_through_fixed_bed};
use crate::case::Gas;

const MU: f64 = 1.8e-5;
const D: f64 = 1.2e-3;

/// U of a part at gradient G: the fixed point of U = G ε d²/(18 μ φ F(ε, ρUd/μ)).
fn part_velocity(g: f64, eps: f64, rho: f64) -> f64 {
    let phi = 1.0 - eps;
    let mut u = g * eps * D * D / (18.0 * MU * phi * beetstra_f(eps, 0.0));
    for _ in 0..200 {
        u = g * eps * D * D / (18.0 * MU * phi * beetstra_f(eps, rho * u * D / MU));
    }
    u
}

/// The parts' analytic superficial velocities: G by bisection on Σ w_i U_i = U0.
fn analytic(parts: &[(f64, f64)], u0: f64, rho: f64) -> Vec<f64> {
    let mean = |g: f64| parts.iter().map(|&(w, e)| w * part_velocity(g, e, rho)).sum::<f64>();
    let (mut lo, mut hi) = (0.0, 1e7);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mean(mid) < u0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    parts.iter().map(|&(_, e)| part_velocity(0.5 * (lo + hi), e, rho)).collect()
}

/// Runs the zone with ε = `eps[part]` for the cells `part_of` puts in part 0 or 1 (and the inlet
/// jet, if any) and returns the measured and analytic superficial velocities of both parts in the
/// middle of the zone.
fn redistributed(
    eps_parts: [f64; 2],
    part_of: impl Fn(&crate::grid::CylGrid, usize) -> usize,
    inlet_jet: Option<crate::case::InletJet>,
) -> ([f64; 2], [f64; 2]) {
    let u0 = 0.2;
    let (nz, dz) = (60, 0.0025);
    let gas = Gas { inlet_jet: inlet_jet.clone(), ..fixed_bed_gas(u0, MU) };
    // D = 30 mm, 3 annuli of 3, 9 and 15 cells; no gravity: the drop is the resistance alone.
    let mut s = solver(gas, 0.0, 3, 0.005, nz, dz);
    let (per, grid) = (s.grid().cells_per_layer(), s.grid().clone());
    let (k_lo, k_hi) = (10, 50); // the zone: z from 25 to 125 mm
    let part: Vec<usize> = (0..per).map(|c| part_of(&grid, c)).collect();
    let eps: Vec<f64> = (0..s.grid().num_cells())
        .map(|c| if (k_lo..k_hi).contains(&(c / per)) { eps_parts[part[c % per]] } else { 1.0 })
        .collect();
    s.set_initial_voidage(&eps);
    let dt = s.stable_dt();
    for _ in 0..20_000 {
        step_through_fixed_bed(&mut s, &eps, D, MU, dt);
    }
    // Superficial velocity of each part: its mass flux over the inflow's density, layers 25–35
    // (40 mm from either end of the zone).
    let (mut flux, mut n) = ([0.0; 2], [0.0; 2]);
    let mut rho_mean = 0.0;
    for k in 25..35 {
        for c in 0..per {
            let i = k * per + c;
            flux[part[c]] += s.density(i) * eps[i] * s.velocity_cyl(i)[2];
            n[part[c]] += 1.0;
            rho_mean += s.density(i);
        }
    }
    rho_mean /= (10 * per) as f64;
    let measured = [flux[0] / n[0] / rho_mean, flux[1] / n[1] / rho_mean];
    let w = n[0] / (n[0] + n[1]);
    // A jet raises the mean inflow by its cells' share of the inlet.
    let u0 = inlet_jet.as_ref().map_or(u0, |j| {
        let jet = crate::cfd::InletJet::new(j, &grid).cells;
        u0 + (j.superficial_velocity_m_s - u0) * jet as f64 / per as f64
    });
    let want = analytic(&[(w, eps_parts[0]), (1.0 - w, eps_parts[1])], u0, rho_mean);
    (measured, [want[0], want[1]])
}

fn assert_close(label: &str, (got, want): ([f64; 2], [f64; 2])) {
    eprintln!("{label}: U = {:.4} / {:.4} m/s, analytic {:.4} / {:.4}", got[0], got[1], want[0], want[1]);
    for q in 0..2 {
        assert!(
            (got[q] / want[q] - 1.0).abs() < 0.03,
            "{label}: part {q} carries {} m/s, analytic {}",
            got[q],
            want[q]
        );
    }
}

#[test]
fn gas_redistributes_radially_to_the_looser_outer_annulus() {
    // Inner two annuli (12 cells) ε = 0.4, outer annulus (15 cells) ε = 0.6.
    let r = redistributed([0.4, 0.6], |g, c| usize::from(c >= g.cells_in_annulus(0) + g.cells_in_annulus(1)), None);
    assert_close("radial split", r);
}

#[test]
fn gas_redistributes_across_angles_to_the_looser_half() {
    // Cells whose centre has x > 0 at ε = 0.4, the others at ε = 0.6.
    let r = redistributed([0.4, 0.6], |g, c| usize::from(g.centre_xyz(c)[0] <= 0.0), None);
    assert_close("angular split", r);
}

#[test]
fn a_jet_through_the_inner_annulus_spreads_to_the_mean_velocity() {
    // ε = 0.4 everywhere in the zone; the central annulus (3 of 27 inlet cells) blows 2 m/s, the
    // rest 0.2 m/s: 40 mm into the zone every cell carries the mean, 0.4 m/s.
    let jet = crate::case::InletJet { annuli: 1, superficial_velocity_m_s: 2.0, from_s: 0.0, until_s: None };
    let r = redistributed([0.4, 0.4], |g, c| usize::from(c >= g.cells_in_annulus(0)), Some(jet));
    assert!((r.1[0] - 0.4).abs() < 1e-9, "mean inflow {}", r.1[0]);
    assert_close("jet", r);
}
