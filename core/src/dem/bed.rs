//! Bed generation: random sequential (non-overlapping) insertion in the tube from a seeded
//! ChaCha RNG, pouring under gravity and settling until the kinetic energy is small; cached on
//! disk keyed by a hash of everything that determines the result (the thread count does not:
//! the pour uses a fixed work split).
//!
//! For a settled height H we pour more than enough particles (count from an estimated packing
//! fraction of 0.60, plus 15 %), settle, then remove every particle whose top is above H
//! (centre above H − R) and relax again.
//!
//! Speed (the pour is most of a first run): the pour uses softer particles, E_pour =
//! max(E/100, 1000 ρ (1 m/s)²) — the floor keeps the Hertz overlap of a 1 m/s impact below about
//! 6 % of d, as δ/R depends only on ρv²/E — and the step dt_pour = t_c(E_pour, 1 m/s)/20 (Hertz
//! contact time, PHYSICS.md 2.4; E/100 makes t_c and the step 100^0.4 ≈ 6.3 times larger). Damping
//! is strong: normal e = 0.3 and a viscous rate of 20 /s on v and ω (terminal speed g/20 ≈ 0.5 m/s,
//! so impacts stay gentle). Particles are inserted at a solid fraction of 0.34, close to their
//! final height. Once still, the contacts are stiffened in steps of √10 in E (each with its own
//! t_c/20 step, the last with the case's step) so the overlaps shrink without a jolt, and a final
//! relaxation uses the case's own contact law and no extra damping.

use super::contact::V3;
use super::system::DemSystem;
use super::DemParams;
use crate::case::{Bed, Case, Damping, CHECK_IMPACT_SPEED_M_S};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// Estimated random packing fraction used to turn a height into a count.
const PACKING_ESTIMATE: f64 = 0.60;
/// Packing fraction of the random insertion (random sequential addition jams near 0.38).
const INSERT_FRACTION: f64 = 0.34;
/// Softening of the pour: E_pour = max(E / POUR_SOFTENING, POUR_E_FLOOR_RHO_V2 · ρ · (1 m/s)²).
const POUR_SOFTENING: f64 = 100.0;
const POUR_E_FLOOR_RHO_V2: f64 = 1000.0;
/// Extra viscous damping rate (1/s) while pouring and stiffening.
const POUR_DAMPING: f64 = 20.0;
/// Factor in E per stiffening stage after the pour.
const STIFFEN_STEP: f64 = 3.1622776601683795; // √10
/// Extra viscous damping rate (1/s) while stiffening (the bed is already jammed).
const STIFFEN_DAMPING: f64 = 100.0;
/// Pour step = Hertz contact time at 1 m/s over this.
const POUR_STEPS_PER_CONTACT: f64 = 20.0;
/// Settled when the mean kinetic energy per particle is below ½ m v² with this v (m/s).
const POUR_SPEED: f64 = 2e-3;
const RELAX_SPEED: f64 = 1e-3;
/// Give up after this much simulated time in one phase.
const MAX_PHASE_TIME_S: f64 = 5.0;
/// Fixed work split while pouring, so the bed does not depend on the thread count.
const BED_CHUNKS: usize = 8;
/// Bump when the algorithm changes (invalidates cached beds).
const ALGORITHM_VERSION: u32 = 2;

/// Asked between steps of the pour: true stops it at once (a cancel, a server stop).
pub type Stop<'a> = &'a (dyn Fn() -> bool + Sync);

/// What a stopped pour returns as its error.
pub const STOPPED: &str = "bed preparation stopped";

/// The settled bed for `case` (positions, velocities); explicit beds are returned as given.
pub fn build_bed(case: &Case, cache_dir: Option<&Path>) -> Result<(Vec<V3>, Vec<V3>), String> {
    build_bed_until(case, cache_dir, &|| false)
}

/// `build_bed` that gives up with [`STOPPED`] as soon as `stop` says so.
pub fn build_bed_until(case: &Case, cache_dir: Option<&Path>, stop: Stop) -> Result<(Vec<V3>, Vec<V3>), String> {
    let g = match &case.bed {
        Bed::Explicit(e) => {
            let v = e.velocities_m_s.clone().unwrap_or_else(|| vec![[0.0; 3]; e.positions_m.len()]);
            return Ok((e.positions_m.clone(), v));
        }
        Bed::Generated(g) => g,
    };
    let key = cache_key(case);
    let file = cache_dir.map(|d| d.join(format!("bed-{key:016x}.bin")));
    if let Some(f) = &file {
        if let Ok(bytes) = std::fs::read(f) {
            if let Some(bed) = decode(&bytes) {
                return Ok(bed);
            }
        }
    }
    let bed = generate_until(case, g.count, g.settled_height_m, g.seed, None, stop)?;
    if let (Some(f), Some(dir)) = (&file, cache_dir) {
        std::fs::create_dir_all(dir).map_err(|e| format!("bed cache {}: {e}", dir.display()))?;
        let tmp = f.with_extension(format!("tmp{}", std::process::id()));
        std::fs::write(&tmp, encode(&bed)).map_err(|e| format!("bed cache {}: {e}", tmp.display()))?;
        std::fs::rename(&tmp, f).map_err(|e| format!("bed cache {}: {e}", f.display()))?;
    }
    Ok(bed)
}

/// Pour and settle; `observe`, if given, sees the system after every step with the
/// contacts' Coulomb excess measured (`DemSystem::set_audit`; tests use it).
#[cfg(test)]
pub fn generate(
    case: &Case,
    count: Option<usize>,
    height: Option<f64>,
    seed: u64,
    observe: Option<&mut dyn FnMut(&DemSystem)>,
) -> Result<(Vec<V3>, Vec<V3>), String> {
    generate_until(case, count, height, seed, observe, &|| false)
}

fn generate_until(
    case: &Case,
    count: Option<usize>,
    height: Option<f64>,
    seed: u64,
    mut observe: Option<&mut dyn FnMut(&DemSystem)>,
    stop: Stop,
) -> Result<(Vec<V3>, Vec<V3>), String> {
    let rt = case.column.diameter_m / 2.0;
    let area = std::f64::consts::PI * rt * rt;
    let n = match (count, height) {
        (Some(c), _) => c,
        (None, Some(h)) => ((PACKING_ESTIMATE * area * h / case.particle_volume_m3()) * 1.15).ceil() as usize,
        (None, None) => return Err("bed.generated needs settled_height_m or count".into()),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x = insert_random(case, n, &mut rng, stop)?;
    // Pour soft and damped (fast settling); no lid while pouring.
    let e_real = case.particles.youngs_modulus_pa;
    let e_floor = POUR_E_FLOOR_RHO_V2 * case.particles.density_kg_m3;
    let e_pour = (e_real / POUR_SOFTENING).max(e_floor).min(e_real);
    let mut sys = DemSystem::with_params(pour_params(case, e_pour, false), x, vec![[0.0; 3]; n]);
    settle(&mut sys, POUR_SPEED, &mut observe, stop)?;
    if let (None, Some(h)) = (count, height) {
        let r = case.particles.diameter_m / 2.0;
        let x = sys.positions();
        let top = x.iter().map(|p| p[2]).fold(0.0, f64::max);
        if top < h - r {
            return Err(format!("poured bed reaches only {top:.4} m, below the requested {h} m"));
        }
        let keep: Vec<usize> = (0..x.len()).filter(|&i| x[i][2] <= h - r).collect();
        let (x, v) = (keep.iter().map(|&i| x[i]).collect(), keep.iter().map(|&i| sys.velocities()[i]).collect());
        sys = DemSystem::with_params(pour_params(case, e_pour, false), x, v);
    }
    // Stiffen in steps of STIFFEN_STEP in E, still damped, each until still.
    let mut e = e_pour;
    while e < e_real {
        e = (e * STIFFEN_STEP).min(e_real);
        let last = e >= e_real;
        let mut p = pour_params(case, e, last);
        p.extra_damping = STIFFEN_DAMPING;
        sys.set_params(p);
        // The last stage settles to the final threshold while still damped (the case's own
        // damping may be weak, e ≈ 0.97, and would ring for long).
        settle(&mut sys, if last { RELAX_SPEED } else { POUR_SPEED }, &mut observe, stop)?;
    }
    // Final relaxation with the case's own parameters.
    let mut p = DemParams::new(case);
    p.lid = false;
    p.work_chunks = BED_CHUNKS;
    sys.set_params(p);
    settle(&mut sys, RELAX_SPEED, &mut observe, stop)?;
    Ok((sys.positions().to_vec(), sys.velocities().to_vec()))
}

/// Pour parameters at Young's modulus `e`: normal e = 0.3, extra viscous damping, no lid, fixed
/// work split, step t_c(e)/20 (the case's own step when `last`).
fn pour_params(case: &Case, e: f64, last: bool) -> DemParams {
    let mut c = case.clone();
    c.particles.youngs_modulus_pa = e;
    c.particles.normal_damping = Damping::Restitution(0.3);
    if !last {
        let dt = c.hertz_contact_time_s(CHECK_IMPACT_SPEED_M_S) / POUR_STEPS_PER_CONTACT;
        c.dem.time_step_s = dt.max(case.dem.time_step_s);
    }
    let mut p = DemParams::new(&c);
    p.lid = false;
    p.extra_damping = POUR_DAMPING;
    p.work_chunks = BED_CHUNKS;
    p
}

/// Step until the mean kinetic energy per particle falls below ½ m `speed`², checked every 200 steps.
fn settle(
    sys: &mut DemSystem,
    speed: f64,
    observe: &mut Option<&mut dyn FnMut(&DemSystem)>,
    stop: Stop,
) -> Result<(), String> {
    sys.set_audit(observe.is_some());
    let dt = sys.params().dt;
    let limit = 0.5 * sys.params().mass * speed * speed * sys.len() as f64;
    let max_steps = (MAX_PHASE_TIME_S / dt) as u64;
    for s in 1..=max_steps {
        if stop() {
            return Err(STOPPED.into());
        }
        sys.step();
        if let Some(f) = observe.as_mut() {
            f(sys);
        }
        if s % 200 == 0 && sys.kinetic_energy() < limit {
            if std::env::var_os("FLUIDBED_POUR_TRACE").is_some() {
                eprintln!("settle: {} particles, dt {:.3e}, {s} steps, {:.4} s", sys.len(), dt, s as f64 * dt);
            }
            return Ok(());
        }
    }
    Err(format!("bed did not settle within {MAX_PHASE_TIME_S} s of simulated time"))
}

/// Random sequential addition of `n` non-overlapping spheres in the tube, bottom up: the
/// insertion column is tall enough for a packing fraction of INSERT_FRACTION.
fn insert_random(case: &Case, n: usize, rng: &mut ChaCha8Rng, stop: Stop) -> Result<Vec<V3>, String> {
    let d = case.particles.diameter_m;
    let r = d / 2.0;
    let reach = case.column.diameter_m / 2.0 - r * 1.01;
    if reach <= 0.0 {
        return Err("column narrower than a particle".into());
    }
    let height = n as f64 * case.particle_volume_m3() / (INSERT_FRACTION * std::f64::consts::PI * reach * reach);
    // Hash grid of cell side d: overlap checks against the 27 surrounding cells.
    let nxy = ((2.0 * reach / d).ceil() as usize).max(1);
    let nz = ((height / d).ceil() as usize + 2).max(1);
    let mut cells: Vec<Vec<u32>> = vec![Vec::new(); nxy * nxy * nz];
    let cell = |p: &V3| -> [usize; 3] {
        let c = |v: f64, m: usize| ((v / d).floor().max(0.0) as usize).min(m - 1);
        [c(p[0] + reach, nxy), c(p[1] + reach, nxy), c(p[2], nz)]
    };
    let mut out: Vec<V3> = Vec::with_capacity(n);
    let mut tries = 0usize;
    while out.len() < n {
        tries += 1;
        if tries & 4095 == 0 && stop() {
            return Err(STOPPED.into());
        }
        if tries > 2000 * n + 100_000 {
            return Err("random insertion could not place all particles".into());
        }
        let rho = reach * rng.gen::<f64>().sqrt();
        let th = std::f64::consts::TAU * rng.gen::<f64>();
        let z = r * 1.01 + (height - 2.02 * r).max(0.0) * rng.gen::<f64>();
        let p = [rho * th.cos(), rho * th.sin(), z];
        let c = cell(&p);
        let mut free = true;
        'scan: for kz in c[2].saturating_sub(1)..=(c[2] + 1).min(nz - 1) {
            for ky in c[1].saturating_sub(1)..=(c[1] + 1).min(nxy - 1) {
                for kx in c[0].saturating_sub(1)..=(c[0] + 1).min(nxy - 1) {
                    for &q in &cells[(kz * nxy + ky) * nxy + kx] {
                        let o = out[q as usize];
                        if (o[0] - p[0]).powi(2) + (o[1] - p[1]).powi(2) + (o[2] - p[2]).powi(2) < d * d {
                            free = false;
                            break 'scan;
                        }
                    }
                }
            }
        }
        if free {
            cells[(c[2] * nxy + c[1]) * nxy + c[0]].push(out.len() as u32);
            out.push(p);
        }
    }
    Ok(out)
}

/// FNV-1a of everything that determines a generated bed (stable across Rust releases).
pub fn cache_key(case: &Case) -> u64 {
    let what = serde_json::json!({
        "version": ALGORITHM_VERSION,
        "diameter_m": case.column.diameter_m,
        "particles": case.particles,
        "bed": case.bed,
        "gravity": case.gravity_m_s2,
        "dt": case.dem.time_step_s,
        "skin": case.dem.skin_fraction,
    })
    .to_string();
    fnv1a(&what)
}

/// FNV-1a hash of a text (stable across Rust releases, unlike `DefaultHasher`): names cached
/// results after what made them.
pub fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf29ce484222325u64, |h, b| (h ^ b as u64).wrapping_mul(0x100000001b3))
}

const MAGIC: &[u8; 8] = b"FBBED001";

fn encode((x, v): &(Vec<V3>, Vec<V3>)) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    out.extend_from_slice(&(x.len() as u64).to_le_bytes());
    for a in x.iter().chain(v) {
        for c in a {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    out
}

fn decode(b: &[u8]) -> Option<(Vec<V3>, Vec<V3>)> {
    if b.len() < 16 || &b[..8] != MAGIC {
        return None;
    }
    let n = u64::from_le_bytes(b[8..16].try_into().ok()?) as usize;
    if b.len() != 16 + n * 48 {
        return None;
    }
    let f = |k: usize| f64::from_le_bytes(b[16 + 8 * k..24 + 8 * k].try_into().unwrap());
    let vec = |o: usize| (0..n).map(|i| [f(o + 3 * i), f(o + 3 * i + 1), f(o + 3 * i + 2)]).collect();
    Some((vec(0), vec(3 * n)))
}

#[cfg(test)]
mod stop_tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn a_pour_stops_when_asked() {
        let case: Case = serde_json::from_value(serde_json::json!({
            "column": { "diameter_m": 0.02, "height_m": 0.05 }, "particles": {},
            "bed": { "generated": { "count": 500 } }
        }))
        .unwrap();
        let asked = AtomicUsize::new(0);
        let stop = || asked.fetch_add(1, Ordering::SeqCst) >= 50;
        assert_eq!(build_bed_until(&case, None, &stop), Err(STOPPED.to_string()));
        assert_eq!(asked.load(Ordering::SeqCst), 51, "stopped at the first question answered yes");
    }
}
