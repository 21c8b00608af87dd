//! Downloads: the snapshot list, one snapshot as json / npy / vtk (legacy) / vtu and vtp (VTK
//! XML, what .pvd series list) / png, the pressure-drop series.
//!
//! npy arrays: a cell field (`field=voidage|pressure`) has shape [nz, cells_per_layer] in the
//! grid's order (within a layer: annulus by annulus, n0·i² + j); `field=particles` has shape
//! [N, 6]: x, y, z, vx, vy, vz per particle (m, m/s); `field=gas_velocity` has shape
//! [nz, cells_per_layer, 3]: the interstitial gas velocity (U_r, U_θ, U_z) per cell (m/s).

use super::jobs::find;
use super::problem::{internal, problem};
use crate::App;
use axum::extract::{Path, Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use fluidbed_core::output::{fields, npy, plot, vtk, vtk_xml};
use fluidbed_core::sim::snapshot::Snapshot;
use serde::Deserialize;
use serde_json::json;
use std::sync::Arc;

pub async fn list(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    if let Err(r) = find(&app, &id) {
        return r;
    }
    match app.store.snapshots(&id) {
        Ok(list) => Json(json!({ "snapshots": list })).into_response(),
        Err(e) => internal(e),
    }
}

#[derive(Deserialize)]
pub struct SnapshotQuery {
    format: Option<String>,
    field: Option<String>,
    what: Option<String>,
}

fn bytes(content_type: &'static str, filename: String, body: Vec<u8>) -> Response {
    let disposition = format!("attachment; filename=\"{filename}\"");
    ([(header::CONTENT_TYPE, content_type.to_string()), (header::CONTENT_DISPOSITION, disposition)], body)
        .into_response()
}

fn missing(what: &str) -> Response {
    problem(
        StatusCode::NOT_FOUND,
        "Field not stored",
        &format!("this snapshot has no {what} (see the case's outputs.fields)"),
    )
}

pub async fn one(
    State(app): State<Arc<App>>,
    Path((id, n)): Path<(String, String)>,
    Query(q): Query<SnapshotQuery>,
) -> Response {
    if let Err(r) = find(&app, &id) {
        return r;
    }
    // Only a plain number names a snapshot; anything else (`..`, `/`) is simply not found.
    let Some(n) = n.parse::<u64>().ok().filter(|_| n.bytes().all(|b| b.is_ascii_digit())) else {
        return problem(StatusCode::NOT_FOUND, "Not found", "no such snapshot");
    };
    let a = app.clone();
    let snap = match tokio::task::spawn_blocking(move || a.store.snapshot(&id, n)).await {
        Ok(Ok(Some(s))) => s,
        Ok(Ok(None)) => return problem(StatusCode::NOT_FOUND, "Not found", "no such snapshot"),
        Ok(Err(e)) => return internal(e),
        Err(e) => return internal(e.into()),
    };
    let format = q.format.unwrap_or_else(|| "json".into());
    let what = q.what.or(q.field).unwrap_or_else(|| "voidage".into());
    match tokio::task::spawn_blocking(move || encode(&snap, &format, &what)).await {
        Ok(r) => r,
        Err(e) => internal(e.into()),
    }
}

fn cell_field(s: &Snapshot, what: &str) -> Option<Vec<f64>> {
    match what {
        "voidage" | "cells" => fields::voidage(s),
        "pressure" | "pressure_pa" => s.pressure_pa.clone(),
        _ => None,
    }
}

fn encode(s: &Snapshot, format: &str, what: &str) -> Response {
    let n = s.index;
    let grid = s.grid.grid();
    let field_name = if what == "cells" { "voidage" } else { what };
    match format {
        "json" => {
            let mut v = serde_json::to_value(s).unwrap_or_default();
            v["voidage"] = json!(fields::voidage(s));
            Json(v).into_response()
        }
        "npy" if what == "particles" => match &s.particles {
            Some(p) => {
                let data: Vec<f64> = p
                    .positions_m
                    .iter()
                    .zip(&p.velocities_m_s)
                    .flat_map(|(x, v)| [x[0], x[1], x[2], v[0], v[1], v[2]])
                    .collect();
                bytes(
                    "application/octet-stream",
                    format!("particles_{n:06}.npy"),
                    npy::encode_f64(&[p.positions_m.len(), 6], &data),
                )
            }
            None => missing("particles"),
        },
        "npy" if what == "gas_velocity" => match &s.gas_velocity_m_s {
            Some(u) => bytes(
                "application/octet-stream",
                format!("gas_velocity_{n:06}.npy"),
                npy::encode_f64(
                    &[grid.nz, grid.cells_per_layer(), 3],
                    &u.iter().flatten().copied().collect::<Vec<_>>(),
                ),
            ),
            None => missing("gas_velocity"),
        },
        "npy" => match cell_field(s, what) {
            Some(f) => bytes(
                "application/octet-stream",
                format!("{field_name}_{n:06}.npy"),
                npy::encode_f64(&[grid.nz, grid.cells_per_layer()], &f),
            ),
            None => missing(what),
        },
        "vtk" if what == "particles" => match &s.particles {
            Some(p) => bytes(
                "text/plain",
                format!("particles_{n:06}.vtk"),
                vtk::particles(p, &format!("fluidbed particles {n} t={} s", s.time_s)).into_bytes(),
            ),
            None => missing("particles"),
        },
        "vtk" => bytes("text/plain", format!("cells_{n:06}.vtk"), vtk::snapshot_cells(s).into_bytes()),
        "vtp" | "vtu" if what == "particles" => match &s.particles {
            Some(p) => bytes("application/xml", format!("particles_{n:06}.vtp"), vtk_xml::particles(p)),
            None => missing("particles"),
        },
        "vtu" => bytes("application/xml", format!("cells_{n:06}.vtu"), vtk_xml::snapshot_cells(s)),
        "png" => match cell_field(s, what) {
            Some(f) => {
                let (lo, hi) = if field_name == "voidage" { (0.3, 1.0) } else { min_max(&f) };
                bytes("image/png", format!("{field_name}_{n:06}.png"), plot::axial_slice(&grid, &f, lo, hi).encode())
            }
            None => missing(what),
        },
        _ => problem(StatusCode::BAD_REQUEST, "Unknown format", "format is one of json, npy, vtk, vtu, vtp, png"),
    }
}

fn min_max(v: &[f64]) -> (f64, f64) {
    let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
    if hi > lo {
        (lo, hi)
    } else {
        (lo - 1.0, hi + 1.0)
    }
}

#[derive(Deserialize)]
pub struct SeriesQuery {
    format: Option<String>,
}

/// One row per snapshot: time_s, pressure_drop_pa (empty for runs without gas) and the mean
/// particle-centre height (the bed-height proxy used for the plot of runs without gas).
pub async fn pressure_drop(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    Query(q): Query<SeriesQuery>,
) -> Response {
    if let Err(r) = find(&app, &id) {
        return r;
    }
    let rows = match app.store.snapshots(&id) {
        Ok(r) => r,
        Err(e) => return internal(e),
    };
    let opt = |x: Option<f64>| x.map(|v| v.to_string()).unwrap_or_default();
    match q.format.as_deref().unwrap_or("json") {
        "csv" => {
            let mut out = String::from("time_s,pressure_drop_pa,mean_particle_height_m\n");
            for r in &rows {
                out.push_str(&format!("{},{},{}\n", r.time_s, opt(r.pressure_drop_pa), opt(r.mean_particle_height_m)));
            }
            bytes("text/csv", "pressure_drop.csv".into(), out.into_bytes())
        }
        "json" => Json(json!({
            "time_s": rows.iter().map(|r| r.time_s).collect::<Vec<_>>(),
            "pressure_drop_pa": rows.iter().map(|r| r.pressure_drop_pa).collect::<Vec<_>>(),
            "mean_particle_height_m": rows.iter().map(|r| r.mean_particle_height_m).collect::<Vec<_>>(),
        }))
        .into_response(),
        "png" => {
            let t: Vec<f64> = rows.iter().map(|r| r.time_s).collect();
            let has_dp = rows.iter().any(|r| r.pressure_drop_pa.is_some());
            let y: Vec<f64> = rows
                .iter()
                .map(|r| if has_dp { r.pressure_drop_pa } else { r.mean_particle_height_m }.unwrap_or(f64::NAN))
                .collect();
            let name = if has_dp { "pressure_drop.png" } else { "mean_particle_height.png" };
            bytes("image/png", name.into(), plot::trace(&t, &y).encode())
        }
        _ => problem(StatusCode::BAD_REQUEST, "Unknown format", "format is one of csv, json, png"),
    }
}
