//! Packed bed (issue: coupling): frozen particles, U = 0.15, 0.20, 0.25 m/s. ΔP/L across the
//! bed must be within 3% of the Beetstra-implied value at the bed's measured mean voidage
//! (PHYSICS.md 11) and within 10% of Ergun (PHYSICS.md 10), each plus the gas head ρ_g g.

use crate::common::*;
use serde_json::json;

pub fn run(small: bool) -> serde_json::Value {
    let mut worst = (0.0f64, 0.0, 0.0);
    let mut worst_ergun = 0.0f64;
    let mut rows = Vec::new();
    for u in [0.15, 0.20, 0.25] {
        // `FLUIDBED_PACKED_BED_CASE=FILE` runs another case file (its U is set here).
        let mut case = match std::env::var("FLUIDBED_PACKED_BED_CASE") {
            Ok(path) => load_case_path(&path),
            Err(_) => load_case("packed-bed.json"),
        };
        if small {
            // A narrower, shallower bed for `cargo test`: same physics, fewer particles.
            case.column.diameter_m = 0.0264;
            case.column.height_m = 0.0352;
            case.bed = fluidbed_core::case::Bed::Generated(fluidbed_core::case::GeneratedBed {
                settled_height_m: Some(0.0176),
                count: None,
                seed: 1,
            });
        }
        let g = case.gas.as_mut().unwrap();
        g.superficial_velocity_m_s = u;
        g.ramp_time_s = 0.01;
        case.end_time_s = 0.04;
        case.outputs.snapshot_interval_s = 0.01;
        let (mu, d) = (g.viscosity_pa_s, case.particles.diameter_m);
        let (sim, snaps) = run_case(case, &format!("packed-bed U={u}"));
        let s = snaps.last().unwrap();
        let top = bed_top_m(&sim);
        let dz = s.grid.dz_m;
        // Layers wholly inside the bed (top at least d below the surface), away from the plate.
        let (k1, k2) = (1usize, ((top - d) / dz).floor() as usize - 1);
        assert!(k2 > k1, "bed too shallow for the grid");
        let (grad, eps) = gradient_and_voidage(s, k1, k2);
        let rho =
            layers(s, &s.pressure_pa.clone().unwrap())[k1] / sim.case().gas.as_ref().unwrap().sound_speed_m_s().powi(2);
        // the gas's own weight adds ρ_g g to the gradient (model A, PHYSICS.md 11)
        let gas_head = rho * sim.case().gravity_m_s2;
        let want = beetstra_gradient(eps, u, d, mu, rho) + gas_head;
        let erg = ergun(eps, u, d, mu, rho) + gas_head;
        let (e_b, e_e) = (grad / want - 1.0, grad / erg - 1.0);
        // The previous snapshot shows whether the flow is steady.
        let prev = &snaps[snaps.len() - 2];
        let (grad_prev, _) = gradient_and_voidage(prev, k1, k2);
        eprintln!("U = {u}: layers {k1}..{k2}, mean ε = {eps:.4}, ΔP/L = {grad:.1} Pa/m (previous {grad_prev:.1}); Beetstra {want:.1} ({:+.2}%), Ergun {erg:.1} ({:+.2}%)", e_b * 100.0, e_e * 100.0);
        // The whole bed, plate to top, against its weight: the end layers (the plate's ordered
        // layer, the partly filled cell at the surface) carry weight with less drag.
        let weight = bed_weight_per_area(sim.case(), sim.dem().len(), rho);
        let whole = s.pressure_drop_pa.unwrap_or(f64::NAN) / weight;
        let fmt = |v: Vec<f64>, k: usize| v.iter().take(k).map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(" ");
        let nk = ((top / dz).ceil() as usize + 1).min(s.grid.nz);
        let lp = layers(s, s.pressure_pa.as_ref().unwrap());
        eprintln!(
            "  whole bed: ΔP = {:.3} of its weight; layer ε: {}; layer ΔP (Pa): {}",
            whole,
            fmt(layers(s, s.voidage.as_ref().unwrap()), nk),
            fmt(lp.windows(2).map(|w| w[0] - w[1]).collect(), nk)
        );
        rows.push(json!({"whole_bed_dp_over_weight": whole, "u_m_s": u, "voidage": eps, "dp_dz_pa_m": grad, "beetstra_pa_m": want, "ergun_pa_m": erg, "rel_err": e_b, "ergun_rel_err": e_e}));
        if e_b.abs() >= worst.0.abs() {
            worst = (e_b, grad, want);
        }
        worst_ergun = worst_ergun.max(e_e.abs());
    }
    json!({"name": "packed-bed", "figure": worst.1, "reference": worst.2, "rel_err": worst.0, "ergun_rel_err_max": worst_ergun, "points": rows})
}
