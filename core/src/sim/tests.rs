use super::*;
use crate::case::{Bed, ExplicitBed, Gas};

/// A case with an explicit bed: particles on a cubic lattice of spacing `s`·d filling the column
/// up to `bed_h`, at rest.
pub(super) fn lattice_case(diameter: f64, height: f64, bed_h: f64, s: f64, gas: Option<Gas>) -> Case {
    let d = 0.0012;
    let r = diameter / 2.0;
    let a = s * d;
    let mut pos = Vec::new();
    let n = (r / a).ceil() as i64;
    let mut z = d / 2.0;
    while z <= bed_h - d / 2.0 {
        for ix in -n..=n {
            for iy in -n..=n {
                let (x, y) = (ix as f64 * a, iy as f64 * a);
                if (x * x + y * y).sqrt() <= r - d / 2.0 {
                    pos.push([x, y, z]);
                }
            }
        }
        z += a;
    }
    let text = format!(
        r#"{{"column":{{"diameter_m":{diameter},"height_m":{height}}},"particles":{{}},"bed":{{"generated":{{}}}}}}"#
    );
    let mut c: Case = serde_json::from_str(&text).unwrap();
    c.bed = Bed::Explicit(ExplicitBed { positions_m: pos, velocities_m_s: None });
    c.gas = gas;
    c
}

#[test]
fn small_packed_bed_matches_beetstra_at_its_voidage() {
    // PHYSICS.md 11: a fixed bed, model A: Δp/L = 18 μ φ F(ε, Re) U / (ε d²), Re = ρ U d / μ.
    let u = 0.2;
    let gas = Gas { superficial_velocity_m_s: u, ramp_time_s: 0.005, ..Gas::default() };
    let mut case = lattice_case(0.044, 0.0308, 0.0176, 1.08, Some(gas));
    case.dem.frozen = true;
    // the exact split: this test is about drag, gas and exchange, not the voidage method's error
    case.voidage = crate::case::Voidage::ExactCylindrical;
    case.end_time_s = 0.02;
    case.outputs.snapshot_interval_s = 0.01;
    case.outputs.fields = vec![Field::Voidage, Field::Pressure];
    assert!(case.validate().is_ok(), "{:?}", case.validate().errors);
    let mut snaps: Vec<Snapshot> = Vec::new();
    let mut sim = Simulation::new(case, None).unwrap();
    sim.run(&mut snaps).unwrap();
    let s = snaps.last().unwrap();
    let g = sim.grid();
    let p = crate::analysis::layer_means(g, s.pressure_pa.as_ref().unwrap());
    let e = crate::analysis::layer_means(g, s.voidage.as_ref().unwrap());
    // layers 1..2 lie inside the bed (0..17.6 mm, 4.4-mm layers), away from plate and surface
    let (k1, k2) = (1, 2);
    let grad = (p[k1] - p[k2]) / g.dz;
    let eps = 0.5 * (e[k1] + e[k2]);
    let (mu, d) = (1.8e-5, 0.0012);
    let rho = p[k1] / sim.case().gas.as_ref().unwrap().sound_speed_m_s().powi(2);
    let re = rho * u * d / mu;
    // model A's gradient plus the gas head ρ_g g
    let want = 18.0 * mu * (1.0 - eps) * crate::coupling::beetstra_f(eps, re) * u / (eps * d * d) + rho * 9.81;
    assert!((grad / want - 1.0).abs() < 0.03, "ΔP/L {grad:.1} Pa/m vs Beetstra {want:.1} at ε = {eps:.4}");
}

#[test]
fn checkpoint_restore_continues_bit_identically() {
    let gas = Gas { superficial_velocity_m_s: 0.8, ramp_time_s: 0.001, ..Gas::default() };
    // a loose lattice (spacing 1.3 d) falling and fluidised in a narrow column
    let mut case = lattice_case(0.0132, 0.0264, 0.008, 1.3, Some(gas));
    case.grid.dr_m = 0.0022;
    case.end_time_s = 0.002;
    case.outputs.snapshot_interval_s = 0.0005;
    case.outputs.fields = vec![Field::Voidage, Field::Pressure, Field::Particles];
    assert!(case.validate().is_ok(), "{:?}", case.validate().errors);
    let mut full: Vec<Snapshot> = Vec::new();
    let mut a = Simulation::new(case.clone(), None).unwrap();
    assert!(a.plan().coupling && a.plan().particles_move);
    a.run(&mut full).unwrap();

    let mut part: Vec<Snapshot> = Vec::new();
    let mut b = Simulation::new(case, None).unwrap();
    while part.len() < 3 {
        if let Some(s) = b.advance(u64::MAX).unwrap() {
            part.push(s);
        }
    }
    let bytes = b.checkpoint();
    drop(b);
    // A checkpoint of another format, or none at all, is refused with a message that says so.
    let mut other = bytes.clone();
    other[8] ^= 0x40;
    let refused = |b: &[u8]| Simulation::restore(b).err().map(|e| e.to_string()).unwrap_or_default();
    let (f, g) = (super::CHECKPOINT_FORMAT ^ 0x40, super::CHECKPOINT_FORMAT);
    assert!(refused(&other).contains(&format!("checkpoint format {f}")), "{}", refused(&other));
    assert!(refused(&other).contains(&format!("reads format {g}")), "{}", refused(&other));
    assert!(refused(&bytes[8..]).contains("not a fluidbed checkpoint"), "{}", refused(&bytes[8..]));
    let mut c = Simulation::restore(&bytes).unwrap();
    c.run(&mut part).unwrap();
    assert_eq!(full.len(), part.len());
    assert_eq!(full.len(), 5, "snapshots at 0, 0.5, 1, 1.5, 2 ms");
    let (x, y) = (full.last().unwrap(), part.last().unwrap());
    assert_eq!(x.particles, y.particles, "particle state after restore differs");
    assert_eq!(x.pressure_pa, y.pressure_pa);
    // the particles really moved: the test is not trivially satisfied
    let moved = x.particles.as_ref().unwrap().velocities_m_s.iter().any(|v| v[2].abs() > 1e-3);
    assert!(moved);
}

#[test]
fn dem_only_run_takes_snapshots_on_schedule_and_keeps_particle_volume() {
    let mut case = lattice_case(0.0132, 0.0264, 0.006, 1.2, None);
    case.end_time_s = 0.001;
    case.outputs.snapshot_interval_s = 0.0003;
    case.outputs.fields = vec![Field::Voidage, Field::Particles];
    let n = match &case.bed {
        Bed::Explicit(e) => e.positions_m.len(),
        _ => unreachable!(),
    };
    let mut snaps: Vec<Snapshot> = Vec::new();
    let mut sim = Simulation::new(case.clone(), None).unwrap();
    assert!(!sim.plan().gas && !sim.plan().coupling);
    sim.run(&mut snaps).unwrap();
    // 0, 0.3, 0.6, 0.9 ms and the end at 1 ms
    let times: Vec<f64> = snaps.iter().map(|s| s.time_s).collect();
    assert_eq!(snaps.len(), 5, "{times:?}");
    assert!((times[4] - 0.001).abs() < 1e-12 && (times[1] - 0.0003).abs() < 1e-12);
    let vc = sim.grid().cell_volume();
    for s in &snaps {
        let solid: f64 = s.voidage.as_ref().unwrap().iter().map(|e| (1.0 - e) * vc).sum();
        let want = n as f64 * case.particle_volume_m3();
        assert!((solid / want - 1.0).abs() < 1e-12, "solid volume {solid} vs {want}");
        assert!(s.pressure_pa.is_none() && s.pressure_drop_pa.is_none());
    }
}
