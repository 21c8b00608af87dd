//! A job's plan (what runs, what is skipped and why) and its wall time per stage, as the lines
//! `fluidbed status` and `fluidbed run` print.

use fluidbed_api::Job;
use serde_json::Value;

/// Stage names as the job status gives them, in the order of a step.
const STAGES: [&str; 6] = ["neighbours", "contacts_integration", "voidage", "exchange", "gas", "output"];

/// `plan: …` with each part that runs, then one `skipped: …` line per part that does not.
pub fn plan_lines(job: &Job) -> Vec<String> {
    let Some(p) = &job.plan else { return Vec::new() };
    let on = |k: &str| p[k].as_bool().unwrap_or(false);
    let mut runs = Vec::new();
    if on("particles_move") {
        runs.push(if on("tangential") { "DEM with friction" } else { "DEM (frictionless)" }.to_string());
    }
    if on("gas") {
        let dt = p["gas_dt_s"].as_f64().map(|g| format!(" at {:.3} µs", g * 1e6)).unwrap_or_default();
        runs.push(format!(
            "gas{dt} ({:.2} gas steps per DEM step)",
            p["gas_steps_per_dem_step"].as_f64().unwrap_or(0.0)
        ));
    }
    if on("coupling") {
        runs.push(format!("coupling every {} DEM steps", p["coupling_interval"].as_u64().unwrap_or(1)));
    }
    let mut out = vec![format!("plan: {}", if runs.is_empty() { "nothing to step".into() } else { runs.join(", ") })];
    out.extend(
        p["skipped"].as_array().into_iter().flatten().filter_map(Value::as_str).map(|s| format!("skipped: {s}")),
    );
    out
}

/// `stages: neighbours 1.2 s (10%), …` (wall time since the job last started), if reported.
pub fn stage_line(job: &Job) -> Option<String> {
    let s = job.stage_seconds.as_ref()?;
    let total: f64 = STAGES.iter().filter_map(|k| s[*k].as_f64()).sum();
    if total <= 0.0 {
        return None;
    }
    let parts: Vec<String> = STAGES
        .iter()
        .filter_map(|k| s[*k].as_f64().map(|v| (k, v)))
        .filter(|(_, v)| *v > 0.0)
        .map(|(k, v)| format!("{k} {v:.1} s ({:.0}%)", 100.0 * v / total))
        .collect();
    Some(format!("stages: {}", parts.join(", ")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn job(plan: Value, stages: Value) -> Job {
        let mut j: Job = serde_json::from_value(json!({
            "id": "0", "name": "n", "status": "running", "created_at": "", "started_at": null, "finished_at": null,
            "progress": 0.5, "time_s": 0.1, "end_time_s": 0.2, "steps": 10, "wall_time_s": 1.0, "eta_s": null,
            "message": null, "warnings": [], "plan": null,
            "links": {"self": "", "events": "", "snapshots": "", "pressure_drop": ""}
        }))
        .unwrap();
        j.plan = Some(plan);
        j.stage_seconds = Some(stages);
        j
    }

    #[test]
    fn the_plan_and_stages_read_as_text() {
        let j = job(
            json!({"particles_move": true, "tangential": true, "gas": true, "coupling": true, "gas_dt_s": 2.5e-6,
                   "gas_steps_per_dem_step": 0.5, "coupling_interval": 10, "skipped": ["gas steps: sub-cycled"]}),
            json!({"neighbours": 1.0, "contacts_integration": 2.0, "voidage": 0.0, "exchange": 0.5, "gas": 0.5, "output": 0.0}),
        );
        assert_eq!(
            plan_lines(&j),
            [
                "plan: DEM with friction, gas at 2.500 µs (0.50 gas steps per DEM step), coupling every 10 DEM steps",
                "skipped: gas steps: sub-cycled"
            ]
        );
        assert_eq!(
            stage_line(&j).unwrap(),
            "stages: neighbours 1.0 s (25%), contacts_integration 2.0 s (50%), exchange 0.5 s (12%), gas 0.5 s (12%)"
        );
    }
}
