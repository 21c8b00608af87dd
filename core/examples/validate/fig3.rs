//! Paper Fig. 3: steady flow through the packed bed with the direct, grouping and square-grid
//! voidage methods (and exact_cylindrical). The direct method's voidage jumps from cell to cell
//! and so does the gas velocity; the square grid's field is smooth. Writes one PNG of the
//! vertical gas velocity (and one of voidage) per method.

use crate::common::*;
use fluidbed_core::case::{Field, Voidage};
use serde_json::json;

pub fn run() -> serde_json::Value {
    let methods = Voidage::fig3_methods();
    let mut out = serde_json::Map::new();
    let mut eps_of = std::collections::BTreeMap::new();
    for (name, method) in methods {
        let mut case = load_case("packed-bed.json");
        case.voidage = method;
        case.gas.as_mut().unwrap().ramp_time_s = 0.01;
        case.end_time_s = 0.04;
        case.outputs.fields = vec![Field::Voidage, Field::Pressure, Field::GasVelocity];
        let (sim, snaps) = run_case(case, &format!("fig3 {name}"));
        let s = snaps.last().unwrap();
        let uz: Vec<f64> = s.gas_velocity_m_s.as_ref().unwrap().iter().map(|v| v[2]).collect();
        let eps = s.voidage.clone().unwrap();
        let top = bed_top_m(&sim);
        // the highest layer wholly inside the bed
        let k_bed = ((top - sim.case().particles.diameter_m) / s.grid.dz_m).floor() as usize - 1;
        let r = fluidbed_core::analysis::roughness(&s.grid.grid(), &uz, k_bed);
        let (_, mean_eps) = gradient_and_voidage(s, 1, k_bed);
        eprintln!("{name}: bed voidage {mean_eps:.4}, U_z roughness {r:.3}");
        crate::plots::slice(
            s,
            &uz,
            "interstitial gas velocity U_z [m/s]",
            0.0,
            0.8,
            &format!("docs/img/fig3_uz_{name}.png"),
        );
        crate::plots::slice(s, &eps, "voidage ε [-]", 0.3, 1.0, &format!("docs/img/fig3_voidage_{name}.png"));
        out.insert(format!("roughness_{name}"), json!(r));
        eps_of.insert(name, mean_eps);
    }
    let (sg, direct) = (eps_of["square_grid"], eps_of["direct"]);
    let mut j = json!({"name": "fig3", "figure": sg, "reference": direct, "rel_err": sg / direct - 1.0, "note": "figure/reference: mean bed voidage, square grid vs direct"});
    j.as_object_mut().unwrap().extend(out);
    j
}
