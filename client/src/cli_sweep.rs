//! `fluidbed sweep BASE.json --set POINTER=VALUES ...`: one job per point of the grid of every
//! `--set`, submitted as one sweep, followed to its end, and summarised as a table (printed, and
//! written as `summary.csv` and `sweep.json`). Without `--server`, on an embedded server that runs
//! one point per core.

use crate::api::Api;
use crate::cli_run::{fresh_out, start_embedded, stop_embedded, Embedding};
use crate::exit;
use crate::outcome::{api_fail, fail};
use fluidbed_api::{GridAxis, JobStatus, Sweep, SweepRequest};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Most values one `--set` range may give (a typo such as `0:1:1e-9` must not build millions).
const MAX_VALUES: usize = 10_000;

/// One `--set POINTER=VALUES`: `a:b:step` (from a to b inclusive), `v1,v2,…`, or one value; each
/// value JSON if it parses as JSON, else a string.
pub fn parse_set(arg: &str) -> Result<GridAxis, String> {
    let (pointer, spec) = arg.split_once('=').ok_or_else(|| {
        format!("`--set {arg}`: write POINTER=VALUES, e.g. /gas/superficial_velocity_m_s=0.3:0.9:0.1")
    })?;
    if !pointer.starts_with('/') {
        return Err(format!("`--set {arg}`: `{pointer}` is not a JSON pointer (it starts with /)"));
    }
    let parts: Vec<&str> = spec.split(':').collect();
    let values = if parts.len() == 3 {
        let num = |s: &str| s.trim().parse::<f64>().map_err(|_| format!("`--set {arg}`: `{s}` is not a number"));
        let (a, b, step) = (num(parts[0])?, num(parts[1])?, num(parts[2])?);
        if !(step > 0.0 && step.is_finite() && a.is_finite() && b.is_finite() && b >= a) {
            return Err(format!("`--set {arg}`: a range is FROM:TO:STEP with TO ≥ FROM and STEP > 0"));
        }
        // Inclusive of TO within a millionth of a step (0.3:0.9:0.1 ends at 0.9).
        let n = ((b - a) / step + 1e-6).floor() as usize + 1;
        if n > MAX_VALUES {
            return Err(format!("`--set {arg}` gives {n} values; at most {MAX_VALUES}"));
        }
        // Rounded to 12 significant digits: 0.3 + 2 × 0.1 is 0.5, not 0.5000000000000001.
        (0..n).map(|k| Value::from(round12(a + k as f64 * step))).collect()
    } else {
        spec.split(',')
            .map(|v| serde_json::from_str(v.trim()).unwrap_or_else(|_| Value::String(v.trim().into())))
            .collect()
    };
    Ok(GridAxis { pointer: pointer.to_string(), values })
}

fn round12(x: f64) -> f64 {
    if x == 0.0 {
        return 0.0;
    }
    let scale = 10f64.powi(11 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

pub struct SweepArgs {
    pub base: PathBuf,
    pub set: Vec<String>,
    pub name: Option<String>,
    pub out: Option<PathBuf>,
    pub threads: Option<usize>,
}

pub async fn sweep(server: Option<Api>, token: Option<String>, args: SweepArgs, json_out: bool) -> i32 {
    let grid = match args.set.iter().map(|s| parse_set(s)).collect::<Result<Vec<_>, _>>() {
        Ok(g) if !g.is_empty() => g,
        Ok(_) => return fail(exit::USAGE, "give at least one --set POINTER=VALUES"),
        Err(m) => return fail(exit::USAGE, &m),
    };
    let text = match std::fs::read_to_string(&args.base) {
        Ok(t) => t,
        Err(e) => return fail(exit::USAGE, &format!("cannot read {}: {e}", args.base.display())),
    };
    let base: Value = match serde_json::from_str(&text) {
        Ok(v) => v,
        Err(e) => return fail(exit::INVALID_CASE, &format!("{} is not JSON: {e}", args.base.display())),
    };
    let points: usize = grid.iter().map(|a| a.values.len()).product();
    let stem = args.base.file_stem().and_then(|s| s.to_str()).unwrap_or("case").to_string();
    let out = args.out.unwrap_or_else(|| PathBuf::from("fluidbed-out").join(format!("{stem}-sweep")));
    if let Err(m) = fresh_out(&out) {
        return fail(exit::USAGE, &m);
    }
    let (api, embedded) = match server {
        Some(api) => (api, None),
        None => match start_embedded(&out, Embedding::many_jobs(args.threads, points), token.as_deref()) {
            Ok(pair) => pair,
            Err(code) => return code,
        },
    };
    let req = SweepRequest { name: args.name, base, grid: Some(grid), points: None };
    let code = submit_and_follow(&api, &req, &out, json_out).await;
    stop_embedded(embedded).await;
    code
}

async fn submit_and_follow(api: &Api, req: &SweepRequest, out: &Path, json_out: bool) -> i32 {
    let sweep = match api.submit_sweep(req).await {
        Ok(s) => s,
        Err(e) => return api_fail(e, json_out),
    };
    if !json_out {
        eprintln!("fluidbed: sweep {} of {} points submitted to {}", sweep.id, sweep.points.len(), api.base);
    }
    let mut last_line = String::new();
    let sweep = loop {
        let s = match api.sweep(&sweep.id).await {
            Ok(s) => s,
            Err(e) => return api_fail(e, json_out),
        };
        let ended = s.points.iter().filter(|p| p.status.is_final()).count();
        let line = format!("{ended}/{} points ended, {:.0}% done", s.points.len(), 100.0 * s.progress);
        if !json_out && line != last_line {
            eprintln!("fluidbed: {line}");
            last_line = line;
        }
        if s.status.is_final() {
            break s;
        }
        tokio::time::sleep(Duration::from_secs(1)).await;
    };
    let written = std::fs::write(out.join("summary.csv"), summary_csv(&sweep))
        .and_then(|_| std::fs::write(out.join("sweep.json"), serde_json::to_string_pretty(&sweep).unwrap_or_default()));
    if let Err(e) = written {
        return fail(exit::SERVER, &format!("cannot write the summary into {}: {e}", out.display()));
    }
    if json_out {
        println!("{}", serde_json::to_string(&sweep).unwrap_or_default());
    } else {
        print!("{}", summary_table(&sweep));
        eprintln!("fluidbed: sweep {} {}; summary.csv and sweep.json in {}", sweep.id, sweep.status, out.display());
    }
    if sweep.status == JobStatus::Succeeded {
        exit::OK
    } else {
        exit::JOB_FAILED
    }
}

/// The swept pointers, in the order of the first point.
fn columns(s: &Sweep) -> Vec<String> {
    s.points.first().map(|p| p.set.keys().cloned().collect()).unwrap_or_default()
}

fn rows(s: &Sweep) -> (Vec<String>, Vec<Vec<String>>) {
    let set = columns(s);
    let mut head = vec!["point".to_string()];
    head.extend(set.iter().cloned());
    head.extend(
        ["job", "status", "U_m_s", "dp_mean_pa", "dp_std_pa", "mean_height_m", "window_s", "samples"].map(String::from),
    );
    let num = |x: Option<f64>, digits: usize| x.map(|v| format!("{v:.digits$}")).unwrap_or_default();
    let body = s
        .points
        .iter()
        .map(|p| {
            let mut r = vec![p.index.to_string()];
            r.extend(set.iter().map(|k| p.set.get(k).map(|v| v.to_string()).unwrap_or_default()));
            r.push(p.job.clone());
            r.push(p.status.to_string());
            let sm = p.summary.as_ref();
            r.push(num(sm.and_then(|s| s.superficial_velocity_m_s), 3));
            r.push(num(sm.and_then(|s| s.pressure_drop_mean_pa), 2));
            r.push(num(sm.and_then(|s| s.pressure_drop_std_pa), 2));
            r.push(num(sm.and_then(|s| s.mean_particle_height_m), 5));
            r.push(sm.map(|s| format!("{:.3}-{:.3}", s.from_s, s.to_s)).unwrap_or_default());
            r.push(sm.map(|s| s.samples.to_string()).unwrap_or_default());
            r
        })
        .collect();
    (head, body)
}

/// CSV, one row per point (RFC 4180 quoting where a value needs it).
pub fn summary_csv(s: &Sweep) -> String {
    let quote = |f: &String| {
        if f.contains([',', '"', '\n']) {
            format!("\"{}\"", f.replace('"', "\"\""))
        } else {
            f.clone()
        }
    };
    let (head, body) = rows(s);
    std::iter::once(head).chain(body).map(|r| r.iter().map(quote).collect::<Vec<_>>().join(",") + "\n").collect()
}

/// An aligned text table of the same rows, without the columns no point has a value in.
pub fn summary_table(s: &Sweep) -> String {
    let (head, body) = rows(s);
    let keep: Vec<bool> = (0..head.len()).map(|c| body.iter().any(|r| !r[c].is_empty())).collect();
    let pick = |r: Vec<String>| r.into_iter().zip(&keep).filter(|(_, k)| **k).map(|(f, _)| f).collect::<Vec<_>>();
    let (head, body): (Vec<String>, Vec<Vec<String>>) = (pick(head), body.into_iter().map(pick).collect());
    let mut width: Vec<usize> = head.iter().map(|h| h.chars().count()).collect();
    for r in &body {
        for (w, f) in width.iter_mut().zip(r) {
            *w = (*w).max(f.chars().count());
        }
    }
    std::iter::once(head)
        .chain(body)
        .map(|r| {
            let cells: Vec<String> = r.iter().zip(&width).map(|(f, w)| format!("{f:>w$}")).collect();
            cells.join("  ") + "\n"
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_range_includes_its_end_and_lists_parse_as_json() {
        let a = parse_set("/gas/superficial_velocity_m_s=0.3:0.9:0.1").unwrap();
        assert_eq!(a.pointer, "/gas/superficial_velocity_m_s");
        assert_eq!(a.values, [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9].map(Value::from).to_vec());
        let b = parse_set("/voidage/method=direct,square_grid").unwrap();
        assert_eq!(b.values, vec![json!("direct"), json!("square_grid")]);
        assert_eq!(parse_set("/bed/generated/seed=1,2").unwrap().values, vec![json!(1), json!(2)]);
        assert!(parse_set("gas=1").unwrap_err().contains("JSON pointer"));
        assert!(parse_set("/a=1:0:0.1").unwrap_err().contains("TO ≥ FROM"));
        assert!(parse_set("/a=0:1:1e-9").unwrap_err().contains("at most"));
    }
}
