//! The stability watchdog: cheap checks every step that stop a run with a clear message
//! (what, where, when, which parameter to change) instead of letting it produce garbage.

use super::SimError;
use crate::cfd::GasSolver;
use crate::dem::DemSystem;

/// Largest tolerated overlap as a fraction of d (a sound Hertz run stays near 1%).
pub const MAX_OVERLAP_FRACTION: f64 = 0.1;

/// Gas steps between the gas checks (a NaN or a limit passed shows within this many steps; a full
/// check every step was a tenth of the gas solver's time).
pub const GAS_CHECK_EVERY: u64 = 16;

pub fn check_gas(gas: &GasSolver, dt: f64, t: f64) -> Result<(), SimError> {
    gas.check_finite().map_err(|m| {
        SimError::Unstable(format!("gas at t = {t:.6} s: {m}; lower gas.time_step_s or the superficial velocity"))
    })?;
    // The chosen step is cfl_factor times the limit; stop only past the limit itself.
    let stable = gas.stable_dt() / gas.params().cfl_factor.clamp(1e-3, 1.0);
    if dt > stable * (1.0 + 1e-9) {
        return Err(SimError::Unstable(format!(
            "gas step {dt:.3e} s exceeds the acoustic/AB3 limit {stable:.3e} s at t = {t:.6} s (gas velocity grew); set gas.time_step_s below {stable:.3e}"
        )));
    }
    Ok(())
}

pub fn check_dem(dem: &DemSystem, steps: u64, t: f64) -> Result<(), SimError> {
    let ov = dem.max_overlap_fraction();
    if ov.is_nan() || ov > MAX_OVERLAP_FRACTION {
        return Err(SimError::Unstable(format!(
            "particle overlap {:.1}% of d at t = {t:.6} s exceeds {:.0}%; lower dem.time_step_s or raise particles.youngs_modulus_pa",
            ov * 100.0,
            MAX_OVERLAP_FRACTION * 100.0
        )));
    }
    if steps.is_multiple_of(100) {
        if let Some(k) = dem.positions().iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(SimError::Unstable(format!(
                "particle {} has a non-finite position at t = {t:.6} s; lower dem.time_step_s",
                dem.ids()[k]
            )));
        }
    }
    Ok(())
}
