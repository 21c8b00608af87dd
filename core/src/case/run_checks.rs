//! Checks of a case against what its run will meet, before it starts: the DEM step against the
//! Hertz contact time at the largest impact speed the case should see, the inlet against the
//! particles' terminal velocity (a warning: the bed is blown out) and against Mach 0.3, overlaps
//! of an explicit bed, and cells narrower than a particle around the axis.

use super::validate::ValidationReport;
use super::{Bed, Case};
use crate::sim::MAX_OVERLAP_FRACTION;
use serde_json::Value;
use std::collections::HashMap;

/// Largest inlet Mach number (interstitial inlet speed over the sound speed) a case may ask for:
/// beyond it the gas is no longer nearly incompressible and the inlet's characteristics fail.
pub const MAX_INLET_MACH: f64 = 0.3;

/// Overlap (fraction of d) of an explicit bed that is reported as a warning; beyond
/// `MAX_OVERLAP_FRACTION` the watchdog would stop the run at its first step, so it is an error.
pub const WARN_INITIAL_OVERLAP_FRACTION: f64 = 0.01;

/// Most overlapping pairs listed one by one (the rest are counted in the last problem).
const MAX_LISTED_PAIRS: usize = 5;

/// Overlapping pairs counted before the scan stops: coincident particles would make it quadratic
/// (issue 22: 300,000 particles at one point took minutes to refuse).
const MAX_COUNTED_PAIRS: usize = 10_000;

/// Most DEM steps a run may take (end_time / dt): a run beyond it would never finish.
pub const MAX_DEM_STEPS: f64 = 1e12;

impl Case {
    /// The largest impact speed the case should see (m/s): 1 m/s, a particle falling the
    /// column's height √(2gH), the superficial velocity (particles carried by the gas), and the
    /// fastest initial velocity of an explicit bed.
    pub fn largest_impact_speed_m_s(&self) -> f64 {
        let fall = (2.0 * self.gravity_m_s2.max(0.0) * self.column.height_m.max(0.0)).sqrt();
        let gas = self.gas.as_ref().map_or(0.0, |g| g.superficial_velocity_m_s.abs());
        let given = match &self.bed {
            Bed::Explicit(e) => e.velocities_m_s.iter().flatten().map(|v| norm(*v)).fold(0.0, f64::max),
            Bed::Generated(_) => 0.0,
        };
        [super::CHECK_IMPACT_SPEED_M_S, fall, gas, given].into_iter().filter(|v| v.is_finite()).fold(0.0, f64::max)
    }

    /// Terminal velocity of an isolated particle in the gas at the outlet density (PHYSICS.md,
    /// Schiller–Naumann: (π/6)d³(ρ_p−ρ_g)g = (π/8)C_d ρ_g d² u_t², C_d = 24/Re (1 + 0.15 Re^0.687)
    /// up to Re = 1000, 0.44 above), by bisection. `None` without gas or with unusable values.
    pub fn terminal_velocity_m_s(&self) -> Option<f64> {
        let g = self.gas.as_ref()?;
        let (d, rho_p, mu, grav) =
            (self.particles.diameter_m, self.particles.density_kg_m3, g.viscosity_pa_s, self.gravity_m_s2);
        let rho_g = g.outlet_density_kg_m3();
        let ok = |x: f64| x.is_finite() && x > 0.0;
        if !(ok(d) && ok(rho_p) && ok(mu) && ok(grav) && ok(rho_g)) || rho_p <= rho_g {
            return None;
        }
        let weight = d * (rho_p - rho_g) * grav * 4.0 / 3.0; // = C_d ρ_g u²
        let excess = |u: f64| {
            let re = rho_g * u * d / mu;
            let cd = if re <= 1000.0 { 24.0 / re * (1.0 + 0.15 * re.powf(0.687)) } else { 0.44 };
            cd * rho_g * u * u - weight
        };
        let (mut lo, mut hi) = (0.0, 1.0);
        while excess(hi) < 0.0 && hi < 1e6 {
            hi *= 2.0;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if excess(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(0.5 * (lo + hi))
    }

    /// Peak Hertz overlap over d of a head-on impact of two particles at speed v (PHYSICS.md 2.4:
    /// δ_max = (15 m* v² / (16 √R* E*))^(2/5)).
    pub fn impact_overlap_fraction(&self, v: f64) -> f64 {
        let p = &self.particles;
        let (m_star, r_star) = (self.particle_mass_kg() / 2.0, p.diameter_m / 4.0);
        let e_star = p.youngs_modulus_pa / (2.0 * (1.0 - p.poisson_ratio * p.poisson_ratio));
        (15.0 * m_star * v * v / (16.0 * r_star.sqrt() * e_star)).powf(0.4) / p.diameter_m
    }

    /// The run checks of the module comment, added to `r`.
    pub(super) fn validate_run(&self, r: &mut ValidationReport) {
        self.check_contact_time(r);
        self.check_impact_overlap(r);
        self.check_step_count(r);
        if let Some(g) = &self.gas {
            let u = g.superficial_velocity_m_s;
            if let Some(ut) = self.terminal_velocity_m_s() {
                if u > ut {
                    r.warn(
                        "/gas/superficial_velocity_m_s",
                        json_num(u),
                        format!("<= the particles' terminal velocity u_t = {ut:.3} m/s (Schiller–Naumann)"),
                        format!(
                            "superficial velocity above the terminal velocity of a single particle: the bed will be blown out{}",
                            if self.column.lid { " against the lid" } else { " of the column" }
                        ),
                    );
                }
            }
            // The Mach number of the solver's gas: its pressure waves travel at f·a; a jet's too.
            let (a, eps) = (g.acoustic_speed_m_s(), g.inlet_voidage);
            let jet =
                g.inlet_jet.as_ref().map(|j| ("/gas/inlet_jet/superficial_velocity_m_s", j.superficial_velocity_m_s));
            for (path, u) in std::iter::once(("/gas/superficial_velocity_m_s", u)).chain(jet) {
                if !(a.is_finite() && a > 0.0 && eps > 0.0 && u.is_finite()) {
                    continue;
                }
                let limit = MAX_INLET_MACH * a * eps;
                if u / eps > MAX_INLET_MACH * a {
                    let raise = if g.acoustic_speed_factor < 1.0 {
                        ", or raise /gas/acoustic_speed_factor toward 1"
                    } else {
                        ""
                    };
                    r.error(
                        path,
                        json_num(u),
                        format!(
                            "<= {limit:.2} m/s (inlet Mach number U/(ε_inlet·f·a) <= {MAX_INLET_MACH}, f·a = {a:.1} m/s{raise})"
                        ),
                        format!("inlet Mach number {:.2} above {MAX_INLET_MACH}", u / eps / a),
                    );
                }
            }
            self.check_cell_arc(r);
        }
        if let Bed::Explicit(e) = &self.bed {
            self.check_overlaps(&e.positions_m, r);
        }
    }

    /// dt ≤ t_c/10 at the largest impact speed (an error), ≤ t_c/20 recommended (a warning).
    fn check_contact_time(&self, r: &mut ValidationReport) {
        let dt = self.dem.time_step_s;
        let v = self.largest_impact_speed_m_s();
        let tc = self.hertz_contact_time_s(v);
        if !(tc.is_finite() && dt > 0.0) {
            return;
        }
        if dt > tc / 10.0 {
            r.error(
                "/dem/time_step_s",
                json_num(dt),
                format!("<= t_c/10 = {:.3e} s (Hertz contact time t_c = {tc:.3e} s at impact speed {v:.2} m/s)", tc / 10.0),
                "DEM step too large for the Hertz contact time: lower dem.time_step_s or raise particles.youngs_modulus_pa",
            );
        } else if dt > tc / 20.0 {
            r.warn(
                "/dem/time_step_s",
                json_num(dt),
                format!("<= t_c/20 = {:.3e} s recommended (t_c at {v:.2} m/s)", tc / 20.0),
                "DEM step above t_c/20: contacts resolved by fewer than 20 steps",
            );
        }
    }

    /// A warning when an impact at the largest expected speed would overlap beyond the watchdog's
    /// bound: the run will likely be stopped; the E that keeps it within the bound.
    fn check_impact_overlap(&self, r: &mut ValidationReport) {
        let v = self.largest_impact_speed_m_s();
        let f = self.impact_overlap_fraction(v);
        if f.is_finite() && f > MAX_OVERLAP_FRACTION {
            // δ ∝ E^(-2/5): E must grow by (f / f_max)^(5/2).
            let e = self.particles.youngs_modulus_pa * (f / MAX_OVERLAP_FRACTION).powf(2.5);
            r.warn(
                "/particles/youngs_modulus_pa",
                json_num(self.particles.youngs_modulus_pa),
                format!(
                    ">= {e:.3e} Pa to keep an impact at {v:.2} m/s within {:.0}% of d",
                    MAX_OVERLAP_FRACTION * 100.0
                ),
                format!(
                    "an impact at {v:.2} m/s overlaps {:.0}% of d (Hertz): the watchdog stops runs beyond {:.0}%",
                    f * 100.0,
                    MAX_OVERLAP_FRACTION * 100.0
                ),
            );
        }
    }

    fn check_step_count(&self, r: &mut ValidationReport) {
        let n = self.end_time_s / self.dem.time_step_s;
        if n.is_finite() && n > MAX_DEM_STEPS {
            r.error(
                "/end_time_s",
                json_num(self.end_time_s),
                format!(
                    "<= {:.3e} s ({MAX_DEM_STEPS:.0e} DEM steps of {:e} s)",
                    MAX_DEM_STEPS * self.dem.time_step_s,
                    self.dem.time_step_s
                ),
                format!("the run would take {n:.3e} DEM steps"),
            );
        }
    }

    /// Every cell of the equal-volume grid is π·dr/n0 wide along θ: at least one particle wide.
    fn check_cell_arc(&self, r: &mut ValidationReport) {
        let (d, dr, n0) = (self.particles.diameter_m, self.grid.dr_m, self.grid.n0);
        if !(dr > 0.0 && (3..=64).contains(&n0)) {
            return;
        }
        let arc = std::f64::consts::PI * dr / n0 as f64;
        if d >= arc {
            r.error(
                "/grid/n0",
                n0,
                format!(
                    "n0 < π·dr/d = {:.2} (cells π·dr/n0 wide along θ, wider than d = {d} m), or a larger dr",
                    arc * n0 as f64 / d
                ),
                format!("cells only {arc:.3e} m wide along θ, narrower than a particle"),
            );
        }
    }

    /// Pairs of an explicit bed closer than d (a cell hash of side d: O(n)).
    fn check_overlaps(&self, x: &[[f64; 3]], r: &mut ValidationReport) {
        let d = self.particles.diameter_m;
        // Keys stay far from i64's range (a bed that far out is refused as outside the column).
        let in_range = |v: &f64| v.is_finite() && (v / d).abs() < 1e12;
        if !(d > 0.0 && d.is_finite()) || x.len() < 2 || !x.iter().flatten().all(in_range) {
            return;
        }
        let key = |p: &[f64; 3]| [0, 1, 2].map(|a| (p[a] / d).floor() as i64);
        let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, p) in x.iter().enumerate() {
            cells.entry(key(p)).or_default().push(i);
        }
        let (mut worst, mut count, mut listed) = (0.0f64, 0usize, 0usize);
        'scan: for (i, p) in x.iter().enumerate() {
            let k = key(p);
            for dk in 0..27i64 {
                let c = [k[0] + dk % 3 - 1, k[1] + (dk / 3) % 3 - 1, k[2] + dk / 9 - 1];
                for &j in cells.get(&c).into_iter().flatten().filter(|&&j| j > i) {
                    let gap = norm([0, 1, 2].map(|a| x[j][a] - p[a]));
                    let ov = (d - gap) / d;
                    if ov <= WARN_INITIAL_OVERLAP_FRACTION {
                        continue;
                    }
                    worst = worst.max(ov);
                    count += 1;
                    if count > MAX_COUNTED_PAIRS {
                        break 'scan;
                    }
                    if listed < MAX_LISTED_PAIRS {
                        listed += 1;
                        let msg = format!(
                            "particles {i} and {j} overlap by {:.1}% of d (centres {gap:.3e} m apart, d = {d} m)",
                            ov * 100.0
                        );
                        let path = format!("/bed/explicit/positions_m/{j}");
                        let allowed = format!("centres at least {:.3e} m apart", d * (1.0 - MAX_OVERLAP_FRACTION));
                        let value = serde_json::to_value(x[j]).unwrap_or(Value::Null);
                        if ov > MAX_OVERLAP_FRACTION {
                            r.error(&path, value, allowed, msg);
                        } else {
                            r.warn(&path, value, allowed, msg + ": a strong push at the first step");
                        }
                    }
                }
            }
        }
        if count > listed {
            let path = "/bed/explicit/positions_m";
            let msg = if count > MAX_COUNTED_PAIRS {
                format!("more than {MAX_COUNTED_PAIRS} overlapping pairs, the worst {:.1}% of d", worst * 100.0)
            } else {
                format!("{count} overlapping pairs in all, the worst {:.1}% of d", worst * 100.0)
            };
            let allowed = format!("overlaps of at most {:.0}% of d", MAX_OVERLAP_FRACTION * 100.0);
            if worst > MAX_OVERLAP_FRACTION {
                r.error(path, count, allowed, msg);
            } else {
                r.warn(path, count, allowed, msg);
            }
        }
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn json_num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map(Value::Number).unwrap_or(Value::String(format!("{x}")))
}
