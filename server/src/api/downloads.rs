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
use fluidbed_api::{
    Binary, PressureDropSeries, SeriesFormat, SeriesQuery, SnapshotDocument, SnapshotField, SnapshotFormat,
    SnapshotList, SnapshotQuery,
};
use fluidbed_core::output::{fields, npy, plot, vtk, vtk_xml};
use fluidbed_core::sim::snapshot::Snapshot;
use std::sync::Arc;

/// The job's snapshots, oldest first.
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/snapshots",
    operation_id = "list_snapshots",
    tag = "results",
    params(("id" = String, Path, description = "The job id")),
    responses(
        (status = 200, description = "The snapshot index", body = SnapshotList),
        (status = 404, description = "No such job", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn list(State(app): State<Arc<App>>, Path(id): Path<String>) -> Response {
    if let Err(r) = find(&app, &id) {
        return r;
    }
    match app.store.snapshots(&id) {
        Ok(snapshots) => Json(SnapshotList { snapshots }).into_response(),
        Err(e) => internal(e),
    }
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

/// One snapshot, encoded as asked.
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/snapshots/{n}",
    operation_id = "get_snapshot",
    tag = "results",
    params(
        ("id" = String, Path, description = "The job id"),
        ("n" = String, Path, description = "The snapshot number (a plain number; anything else is 404)"),
        SnapshotQuery,
    ),
    responses(
        (status = 200, description = "The snapshot", content(
            (SnapshotDocument = "application/json"),
            (Binary = "application/octet-stream"),
            (String = "text/plain"),
            (String = "application/xml"),
            (Binary = "image/png"),
        )),
        (status = 400, description = "A bad query string", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 404, description = "No such job or snapshot, or the field is not stored", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
    )
)]
pub async fn one(
    State(app): State<Arc<App>>,
    Path((id, n)): Path<(String, String)>,
    Query(q): Query<SnapshotQuery>,
) -> Response {
    let job = match find(&app, &id) {
        Ok(j) => j,
        Err(r) => return r,
    };
    // Only a plain number names a snapshot; anything else (`..`, `/`) is simply not found.
    let Some(n) = n.parse::<u64>().ok().filter(|_| n.bytes().all(|b| b.is_ascii_digit())) else {
        return problem(StatusCode::NOT_FOUND, "Not found", "no such snapshot");
    };
    let a = app.clone();
    let job_id = id.clone();
    let snap = match tokio::task::spawn_blocking(move || a.store.snapshot(&job_id, n)).await {
        Ok(Ok(Some(s))) => s,
        Ok(Ok(None)) => return problem(StatusCode::NOT_FOUND, "Not found", "no such snapshot"),
        Ok(Err(e)) => return internal(e),
        Err(e) => return internal(e.into()),
    };
    let (format, field) = (q.format.unwrap_or(SnapshotFormat::Json), q.field());
    // A picture of the pressure shows it as gauge pressure, against the case's outlet pressure.
    let outlet_pa = match (format, field) {
        (SnapshotFormat::Png, SnapshotField::Pressure) => match app.store.case_json(&id) {
            Ok(text) => text.and_then(|t| outlet_pressure_pa(&t)),
            Err(e) => return internal(e),
        },
        _ => None,
    };
    let figure = Figure { job_name: job.name, outlet_pa };
    match tokio::task::spawn_blocking(move || encode(&snap, format, field, &figure)).await {
        Ok(r) => r,
        Err(e) => internal(e.into()),
    }
}

fn cell_field(s: &Snapshot, field: SnapshotField) -> Option<Vec<f64>> {
    match field {
        SnapshotField::Voidage => fields::voidage(s),
        SnapshotField::Pressure => s.pressure_pa.clone(),
        SnapshotField::GasVelocity | SnapshotField::Particles => None,
    }
}

/// The field's name in file names and messages.
fn name(field: SnapshotField) -> &'static str {
    match field {
        SnapshotField::Voidage => "voidage",
        SnapshotField::Pressure => "pressure",
        SnapshotField::GasVelocity => "gas_velocity",
        SnapshotField::Particles => "particles",
    }
}

/// What a snapshot's picture needs beside the snapshot.
struct Figure {
    job_name: String,
    /// The case's `gas.outlet_pressure_pa`, the zero of the gauge pressure.
    outlet_pa: Option<f64>,
}

fn outlet_pressure_pa(case_json: &str) -> Option<f64> {
    serde_json::from_str::<serde_json::Value>(case_json).ok()?.pointer("/gas/outlet_pressure_pa")?.as_f64()
}

/// "what — job name", or just "what" for a job without a name.
fn titled(what: String, job_name: &str) -> String {
    if job_name.trim().is_empty() {
        what
    } else {
        format!("{what} — {job_name}")
    }
}

/// The field on the axial plane: voidage from 0.3 to 1; pressure as gauge pressure over its range.
fn field_png(s: &Snapshot, field: SnapshotField, values: Vec<f64>, figure: &Figure) -> Response {
    let t = format!("t = {:.4} s", s.time_s);
    let (values, quantity, title, (lo, hi)) = match field {
        SnapshotField::Pressure => {
            let p_out = figure.outlet_pa.unwrap_or(0.0);
            let gauge: Vec<f64> = values.iter().map(|p| p - p_out).collect();
            let range = min_max(&gauge);
            let quantity =
                if figure.outlet_pa.is_some() { "gauge pressure p − p_outlet [Pa]" } else { "pressure p [Pa]" };
            (gauge, quantity, format!("Gas pressure at {t}"), range)
        }
        _ => (values, "voidage ε [-]", format!("Voidage at {t}"), (0.3, 1.0)),
    };
    let title = titled(title, &figure.job_name);
    let labels = plot::FieldLabels { title: &title, quantity, lo, hi };
    match plot::axial_slice(&s.grid.grid(), &values, &labels) {
        Ok(img) => bytes("image/png", format!("{}_{:06}.png", name(field), s.index), img.encode()),
        Err(e) => internal(e.into()),
    }
}

fn encode(s: &Snapshot, format: SnapshotFormat, field: SnapshotField, figure: &Figure) -> Response {
    use SnapshotField as F;
    use SnapshotFormat as Fmt;
    let n = s.index;
    let grid = s.grid.grid();
    let field_name = name(field);
    match (format, field) {
        (Fmt::Json, _) => Json(SnapshotDocument::of(s)).into_response(),
        (Fmt::Npy, F::Particles) => match &s.particles {
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
        (Fmt::Npy, F::GasVelocity) => match &s.gas_velocity_m_s {
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
        (Fmt::Npy, _) => match cell_field(s, field) {
            Some(f) => bytes(
                "application/octet-stream",
                format!("{field_name}_{n:06}.npy"),
                npy::encode_f64(&[grid.nz, grid.cells_per_layer()], &f),
            ),
            None => missing(field_name),
        },
        (Fmt::Vtk, F::Particles) => match &s.particles {
            Some(p) => bytes(
                "text/plain",
                format!("particles_{n:06}.vtk"),
                vtk::particles(p, &format!("fluidbed particles {n} t={} s", s.time_s)).into_bytes(),
            ),
            None => missing("particles"),
        },
        (Fmt::Vtk, _) => bytes("text/plain", format!("cells_{n:06}.vtk"), vtk::snapshot_cells(s).into_bytes()),
        (Fmt::Vtp | Fmt::Vtu, F::Particles) => match &s.particles {
            Some(p) => bytes("application/xml", format!("particles_{n:06}.vtp"), vtk_xml::particles(p)),
            None => missing("particles"),
        },
        (Fmt::Vtu, _) => bytes("application/xml", format!("cells_{n:06}.vtu"), vtk_xml::snapshot_cells(s)),
        (Fmt::Vtp, _) => problem(
            StatusCode::BAD_REQUEST,
            "Unknown format",
            "vtp holds the particles (field=particles); the cells are vtu",
        ),
        (Fmt::Png, F::GasVelocity | F::Particles) => {
            problem(StatusCode::BAD_REQUEST, "Unknown format", "png draws field=voidage or field=pressure")
        }
        (Fmt::Png, _) => match cell_field(s, field) {
            Some(f) => field_png(s, field, f, figure),
            None => missing(field_name),
        },
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

/// One row per snapshot: time_s, pressure_drop_pa (empty for runs without gas) and the mean
/// particle-centre height (the bed-height proxy used for the plot of runs without gas).
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/pressure-drop",
    operation_id = "get_pressure_drop",
    tag = "results",
    params(("id" = String, Path, description = "The job id"), SeriesQuery),
    responses(
        (status = 200, description = "The series", content(
            (PressureDropSeries = "application/json"),
            (String = "text/csv"),
            (Binary = "image/png"),
        )),
        (status = 400, description = "A bad query string", body = fluidbed_api::Problem, content_type = "application/problem+json"),
        (status = 404, description = "No such job", body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn pressure_drop(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    Query(q): Query<SeriesQuery>,
) -> Response {
    let job = match find(&app, &id) {
        Ok(j) => j,
        Err(r) => return r,
    };
    let rows = match app.store.snapshots(&id) {
        Ok(r) => r,
        Err(e) => return internal(e),
    };
    let opt = |x: Option<f64>| x.map(|v| v.to_string()).unwrap_or_default();
    match q.format.unwrap_or(SeriesFormat::Json) {
        SeriesFormat::Csv => {
            let mut out = String::from("time_s,pressure_drop_pa,mean_particle_height_m\n");
            for r in &rows {
                out.push_str(&format!("{},{},{}\n", r.time_s, opt(r.pressure_drop_pa), opt(r.mean_particle_height_m)));
            }
            bytes("text/csv", "pressure_drop.csv".into(), out.into_bytes())
        }
        SeriesFormat::Json => Json(PressureDropSeries {
            time_s: rows.iter().map(|r| r.time_s).collect(),
            pressure_drop_pa: rows.iter().map(|r| r.pressure_drop_pa).collect(),
            mean_particle_height_m: rows.iter().map(|r| r.mean_particle_height_m).collect(),
        })
        .into_response(),
        SeriesFormat::Png => {
            let t: Vec<f64> = rows.iter().map(|r| r.time_s).collect();
            let has_dp = rows.iter().any(|r| r.pressure_drop_pa.is_some());
            let y: Vec<f64> = rows
                .iter()
                .map(|r| if has_dp { r.pressure_drop_pa } else { r.mean_particle_height_m }.unwrap_or(f64::NAN))
                .collect();
            let (file, title, y_label) = if has_dp {
                ("pressure_drop.png", "Bed pressure drop", "pressure drop ΔP (bottom to top layer) [Pa]")
            } else {
                ("mean_particle_height.png", "Mean particle height", "mean particle-centre height [m]")
            };
            let title = titled(title.to_string(), &job.name);
            let labels = plot::TraceLabels { title: &title, x: "time t [s]", y: y_label };
            match plot::trace(&t, &y, &labels) {
                Ok(img) => bytes("image/png", file.into(), img.encode()),
                Err(e) => internal(e.into()),
            }
        }
    }
}
