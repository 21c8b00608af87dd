//! The stability watchdog: cheap checks inside the step loop that stop a run with a clear message
//! (what, where, when, which parameter to change) instead of letting it produce garbage. The only
//! per-step check reads a maximum the DEM pass computed anyway (the largest overlap); the passes
//! over particles or cells run every `DEM_CHECK_EVERY` DEM / `GAS_CHECK_EVERY` gas steps, and the
//! details (which particle, which cell) are looked up only once something is wrong.

use super::SimError;
use crate::case::Case;
use crate::cfd::GasSolver;
use crate::dem::DemSystem;
use crate::grid::CylGrid;

/// Largest tolerated overlap as a fraction of d (a sound Hertz run stays near 1%).
pub const MAX_OVERLAP_FRACTION: f64 = 0.1;

/// Gas steps between the gas checks (a NaN or a limit passed shows within this many steps; a full
/// check every step was a tenth of the gas solver's time).
pub const GAS_CHECK_EVERY: u64 = 16;

/// DEM steps between the passes over every particle (finite state, inside the walls, speed).
pub const DEM_CHECK_EVERY: u64 = 100;

/// A particle faster than this many times the case's largest expected impact speed stops the run
/// (unless a collision at that speed would still keep the overlap within bounds).
pub const SPEED_FACTOR: f64 = 10.0;

/// Gas density below this fraction of the outlet density: the pressure has collapsed.
pub const COLLAPSED_DENSITY_FRACTION: f64 = 1e-2;

/// Largest tolerated gas mass-budget error, (in − out − change) / mass held (cfd/mass_budget.rs):
/// a conservative scheme closes it to round-off (≈ 1e-14 after a million DEM steps of the 44-mm
/// bed); beyond this the fluxes no longer conserve mass.
pub const MASS_BALANCE_TOLERANCE: f64 = 1e-9;

/// How far (as a fraction of d) a centre may pass a wall before the particle has left the column:
/// its overlap with the wall would be beyond anything the contact law can push back.
const ESCAPE_FRACTION: f64 = 0.5;

/// What the checks compare with, from the case (computed once per run).
#[derive(Clone, Debug)]
pub struct Limits {
    tube_radius: f64,
    height: f64,
    lid: bool,
    radius: f64,
    max_speed: f64,
    min_gas_density: f64,
}

impl Limits {
    pub fn of(case: &Case) -> Limits {
        let d = case.particles.diameter_m;
        Limits {
            tube_radius: case.column.diameter_m / 2.0,
            height: case.column.height_m,
            lid: case.column.lid,
            radius: d / 2.0,
            max_speed: (SPEED_FACTOR * case.largest_impact_speed_m_s()).max(overlap_speed(case)),
            min_gas_density: case.gas.as_ref().map_or(0.0, |g| COLLAPSED_DENSITY_FRACTION * g.outlet_density_kg_m3()),
        }
    }
}

/// Head-on impact speed of two particles whose Hertz overlap peaks at MAX_OVERLAP_FRACTION·d
/// (δ_max ∝ v^(4/5): `Case::impact_overlap_fraction` at 1 m/s scaled).
fn overlap_speed(case: &Case) -> f64 {
    (MAX_OVERLAP_FRACTION / case.impact_overlap_fraction(1.0)).powf(1.25)
}

fn when(t: f64, step: u64) -> String {
    format!("t = {t:.6e} s (DEM step {step})")
}

fn at(x: [f64; 3]) -> String {
    format!("({:.4e}, {:.4e}, {:.4e}) m", x[0], x[1], x[2])
}

/// Every `GAS_CHECK_EVERY` gas steps: finite state, positive and not collapsed density, the
/// step within the acoustic/AB3 limit, and the gas mass budget closed.
pub fn check_gas(gas: &GasSolver, lim: &Limits, dt: f64, t: f64, step: u64) -> Result<(), SimError> {
    gas.check_finite().map_err(|m| {
        SimError::Unstable(format!(
            "{m} ({}); lower gas.time_step_s (or gas.cfl_factor) or gas.superficial_velocity_m_s",
            when(t, step)
        ))
    })?;
    let grid = gas.grid();
    let (rho, c) =
        (0..grid.num_cells()).map(|c| (gas.density(c), c)).fold(
            (f64::INFINITY, 0),
            |a, b| {
                if b.0 < a.0 {
                    b
                } else {
                    a
                }
            },
        );
    if rho < lim.min_gas_density {
        return Err(SimError::Unstable(format!(
            "gas density collapsed to {rho:.4e} kg/m³ (below {:.0}% of the outlet density) in {} at {}; lower gas.time_step_s or gas.superficial_velocity_m_s",
            COLLAPSED_DENSITY_FRACTION * 100.0,
            cell_name(grid, c),
            when(t, step)
        )));
    }
    // The chosen step is cfl_factor times the limit; stop only past the limit itself.
    let stable = gas.stable_dt() / gas.params().cfl_factor.clamp(1e-3, 1.0);
    if dt > stable * (1.0 + 1e-9) {
        return Err(SimError::Unstable(format!(
            "gas step {dt:.3e} s exceeds the acoustic/AB3 limit {stable:.3e} s at {} (gas velocity grew); set gas.time_step_s below {stable:.3e} or lower gas.superficial_velocity_m_s",
            when(t, step)
        )));
    }
    let b = gas.mass_balance();
    let err = b.relative_error();
    if err.is_nan() || err.abs() > MASS_BALANCE_TOLERANCE {
        return Err(SimError::Unstable(format!(
            "gas mass balance off by {err:.3e} of the mass held (beyond {MASS_BALANCE_TOLERANCE:.0e}): in − out {:.6e} kg, change {:.6e} kg, held {:.6e} kg, at {}; the solver lost mass conservation, which no case setting causes: report it with the job's checkpoint",
            b.net_inflow,
            b.change,
            b.held,
            when(t, step)
        )));
    }
    Ok(())
}

fn cell_name(grid: &CylGrid, c: usize) -> String {
    let (i, j, k) = grid.ijk(c);
    format!("cell {c} (i={i}, j={j}, k={k}) at {}", at(grid.centre_xyz(c)))
}

/// Every DEM step: the largest overlap of the step (computed by the pass); every
/// `DEM_CHECK_EVERY` steps one pass over the particles.
pub fn check_dem(dem: &DemSystem, lim: &Limits, steps: u64, t: f64) -> Result<(), SimError> {
    let ov = dem.max_overlap_fraction();
    if ov.is_nan() || ov > MAX_OVERLAP_FRACTION {
        let (k, ov) = dem.deepest_overlap().unwrap_or((0, ov));
        let id = dem.ids().get(k).copied().unwrap_or(0);
        let x = dem.positions().get(k).copied().unwrap_or([f64::NAN; 3]);
        return Err(SimError::Unstable(format!(
            "particle overlap {:.2}% of d exceeds {:.0}% at particle {id} at {} at {}; lower dem.time_step_s or raise particles.youngs_modulus_pa",
            ov * 100.0,
            MAX_OVERLAP_FRACTION * 100.0,
            at(x),
            when(t, steps)
        )));
    }
    if steps.is_multiple_of(DEM_CHECK_EVERY) {
        check_particles(dem, lim, steps, t)?;
    }
    Ok(())
}

/// One pass over the particles (a sum, maxima and minima); the details only on failure.
fn check_particles(dem: &DemSystem, lim: &Limits, steps: u64, t: f64) -> Result<(), SimError> {
    let (x, v, w) = (dem.positions(), dem.velocities(), dem.angular_velocities());
    let (mut sum, mut r2, mut zmin, mut zmax, mut v2) = (0.0, 0.0f64, f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for ((p, u), o) in x.iter().zip(v).zip(w) {
        sum += p[0] + p[1] + p[2] + u[0] + u[1] + u[2] + o[0] + o[1] + o[2];
        r2 = r2.max(p[0] * p[0] + p[1] * p[1]);
        zmin = zmin.min(p[2]);
        zmax = zmax.max(p[2]);
        v2 = v2.max(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    }
    let slack = ESCAPE_FRACTION * 2.0 * lim.radius;
    let r_out = lim.tube_radius - lim.radius + slack;
    let escaped =
        r2 > r_out * r_out || zmin < lim.radius - slack || (lim.lid && zmax > lim.height - lim.radius + slack);
    if sum.is_finite() && !escaped && v2 <= lim.max_speed * lim.max_speed {
        return Ok(());
    }
    let name = |k: usize| format!("particle {} at {}", dem.ids()[k], at(x[k]));
    let stop = |m: String| Err(SimError::Unstable(m));
    for k in 0..x.len() {
        let finite = |a: &[f64; 3]| a.iter().all(|c| c.is_finite());
        let what =
            [(x, "position"), (v, "velocity"), (w, "angular velocity")].into_iter().find(|(a, _)| !finite(&a[k]));
        if let Some((_, what)) = what {
            return stop(format!(
                "{} has a non-finite {what} at {}; lower dem.time_step_s (contacts too stiff for the step) or, with gas, gas.superficial_velocity_m_s",
                name(k),
                when(t, steps)
            ));
        }
    }
    for (k, &p) in x.iter().enumerate() {
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let wall = if rho > r_out {
            Some("the tube wall")
        } else if p[2] < lim.radius - slack {
            Some("the distributor plate")
        } else if lim.lid && p[2] > lim.height - lim.radius + slack {
            Some("the lid")
        } else {
            None
        };
        if let Some(wall) = wall {
            return stop(format!(
                "{} has left the column through {wall} (r = {rho:.4e} m, column radius {} m) at {}; lower dem.time_step_s or raise particles.youngs_modulus_pa",
                name(k),
                lim.tube_radius,
                when(t, steps)
            ));
        }
    }
    let (k, s) =
        v.iter().map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()).enumerate().fold((0, 0.0), |a, b| {
            if b.1 > a.1 {
                b
            } else {
                a
            }
        });
    stop(format!(
        "{} moves at {s:.3e} m/s, beyond the bound {:.3e} m/s ({SPEED_FACTOR}× the case's largest expected impact speed, or the speed whose impact overlaps {:.0}% of d) at {}; lower dem.time_step_s or gas.superficial_velocity_m_s",
        name(k),
        lim.max_speed,
        MAX_OVERLAP_FRACTION * 100.0,
        when(t, steps)
    ))
}

#[cfg(test)]
#[path = "watchdog_tests.rs"]
mod tests;
