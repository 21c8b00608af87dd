//! The job's analysis (case `analysis`, accumulated while it runs): the statistics as JSON and
//! their figures as PNG, read from the job's last checkpoint (its `analysis` section only, so a
//! large bed is not decoded for a request).

use super::jobs::find;
use super::problem::{internal, problem};
use crate::App;
use axum::extract::{Path, Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use fluidbed_api::{AnalysisQuery, ANALYSIS_FIGURES as FIGURES};
use fluidbed_core::grid::CylGrid;
use fluidbed_core::output::plot;
use fluidbed_core::sim::{AnalysisReport, Simulation};
use std::sync::Arc;

/// The report of the job's last checkpoint, or the problem to answer with.
async fn report(app: &Arc<App>, id: &str, q: &AnalysisQuery) -> Result<(CylGrid, AnalysisReport, String), Response> {
    let from = q.from;
    if from.is_some_and(|t| !(t.is_finite() && t >= 0.0)) {
        return Err(problem(StatusCode::BAD_REQUEST, "Bad query", "`from` must be a finite time ≥ 0 s"));
    }
    let job = find(app, id)?;
    let a = app.clone();
    let job_id = id.to_string();
    let bytes = match tokio::task::spawn_blocking(move || a.store.checkpoint(&job_id)).await {
        Ok(Ok(Some(b))) => b,
        Ok(Ok(None)) => {
            return Err(problem(
                StatusCode::NOT_FOUND,
                "No analysis yet",
                "the job has not written a checkpoint yet (its analysis is read from the last one)",
            ))
        }
        Ok(Err(e)) => return Err(internal(e)),
        Err(e) => return Err(internal(e.into())),
    };
    match tokio::task::spawn_blocking(move || Simulation::analysis_of_checkpoint(&bytes, from)).await {
        Ok(Ok((_, grid, r))) => Ok((grid, r, job.name)),
        Ok(Err(e)) => Err(internal(anyhow::anyhow!("{e}"))),
        Err(e) => Err(internal(e.into())),
    }
}

/// Every statistic of the run so far with its window and sample count: ΔP mean, spread, Welch
/// spectrum and dominant frequency; the bed height; bubbles per second and the bubble fraction by
/// height; the rise velocity by cross-correlation; particle-based and voidage maps on the axial
/// plane and radial profiles (docs/VALIDATION.md "Analysis during a run").
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/analysis",
    operation_id = "get_analysis",
    tag = "results",
    params(("id" = String, Path, description = "The job id"), AnalysisQuery),
    responses(
        (status = 200, description = "The analysis as of the job's last checkpoint", body = Object),
        (status = 400, description = "A bad query string", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
        (status = 404, description = "No such job, or no checkpoint yet", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
    )
)]
pub async fn get(State(app): State<Arc<App>>, Path(id): Path<String>, Query(q): Query<AnalysisQuery>) -> Response {
    match report(&app, &id, &q).await {
        Ok((_, r, _)) => Json(r).into_response(),
        Err(r) => r,
    }
}

/// One figure of the analysis: `pressure_spectrum.png` (Welch PSD of ΔP),
/// `rise_correlation.png` (the voidage cross-correlation between the two rise heights),
/// `eruption_link.png` (ΔP averaged around the bubble eruptions at the bed surface, Fig. 9),
/// `particle_velocity_map.png` (particle-based ⟨v_z⟩ on the axial plane, as the paper's Fig. 7),
/// `voidage_map.png` (time-averaged voidage on the axial plane, Fig. 6).
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/analysis/{figure}",
    operation_id = "get_analysis_figure",
    tag = "results",
    params(
        ("id" = String, Path, description = "The job id"),
        ("figure" = String, Path, description = "pressure_spectrum.png, rise_correlation.png, eruption_link.png, particle_velocity_map.png or voidage_map.png"),
        AnalysisQuery,
    ),
    responses(
        (status = 200, description = "The figure", body = fluidbed_api::Binary, content_type = "image/png"),
        (status = 400, description = "A bad query string", body = fluidbed_api::Problem,
            content_type = "application/problem+json"),
        (status = 404, description = "No such job or figure, no checkpoint yet, or too few samples for it",
            body = fluidbed_api::Problem, content_type = "application/problem+json"),
    )
)]
pub async fn figure(
    State(app): State<Arc<App>>,
    Path((id, figure)): Path<(String, String)>,
    Query(q): Query<AnalysisQuery>,
) -> Response {
    if !FIGURES.contains(&figure.as_str()) {
        return problem(
            StatusCode::NOT_FOUND,
            "Not found",
            &format!("no such figure; the figures are {}", FIGURES.join(", ")),
        );
    }
    let (grid, r, name) = match report(&app, &id, &q).await {
        Ok(x) => x,
        Err(r) => return r,
    };
    match tokio::task::spawn_blocking(move || draw(&grid, &r, &name, &figure)).await {
        Ok(r) => r,
        Err(e) => internal(e.into()),
    }
}

fn draw(grid: &CylGrid, r: &AnalysisReport, job_name: &str, figure: &str) -> Response {
    let window = format!("{:.3}–{:.3} s, {} samples", r.from_s, r.to_s, r.samples);
    let series = format!("{:.3}–{:.3} s, {} samples", r.series_from_s, r.to_s, r.series_samples);
    let too_few = |what: &str| problem(StatusCode::NOT_FOUND, "Not enough samples", &format!("{what} ({window})"));
    let image = match figure {
        "pressure_spectrum.png" => {
            let Some(s) = r.pressure_drop.as_ref().and_then(|p| p.spectrum.as_ref()) else {
                return too_few("no ΔP spectrum yet: a gas run needs at least 8 samples");
            };
            let title = format!("{job_name}: ΔP spectrum, {series}");
            let labels =
                plot::TraceLabels { title: &title, x: "frequency f [Hz]", y: "power spectral density [Pa²/Hz]" };
            plot::trace(&s.freq_hz, &s.psd, &labels)
        }
        "rise_correlation.png" => {
            let Some((rise, v)) = r.rise_velocity.as_ref().and_then(|x| Some((x, x.voidage.as_ref()?))) else {
                return too_few("no correlation peak between the rise heights yet");
            };
            let lag: Vec<f64> = (0..v.correlation.len()).map(|k| k as f64 * v.dt_s).collect();
            let title = format!(
                "{job_name}: voidage correlation {:.0}–{:.0} mm, u = {:.3} m/s, {series}",
                1e3 * rise.lower_m,
                1e3 * rise.upper_m,
                v.velocity_m_s
            );
            let labels = plot::TraceLabels { title: &title, x: "delay τ [s]", y: "cross-correlation R(τ) [-]" };
            plot::trace(&lag, &v.correlation, &labels)
        }
        "eruption_link.png" => {
            let Some(e) = r.eruptions.as_ref() else {
                return too_few("no bubble eruption at the bed surface yet");
            };
            let title = format!(
                "{job_name}: ΔP around {} eruptions at {:.0} mm ({:.2} /s), {series}",
                e.link.averaged,
                1e3 * e.fronts.height_m,
                e.fronts.count.per_second
            );
            let labels =
                plot::TraceLabels {
                    title: &title, x: "time from eruption τ [s]", y: "ΔP(t_e + τ) − mean ΔP [Pa]"
                };
            plot::trace(&e.link.lag_s, &e.link.triggered_dp_pa, &labels)
        }
        "particle_velocity_map.png" => {
            let field = r.particle_velocity_map.cell_field(grid);
            let top = field.iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(v.abs()));
            let title = format!("{job_name}: particle ⟨v_z⟩, {window}");
            let labels =
                plot::FieldLabels { title: &title, quantity: "particle-based ⟨v_z⟩ [m/s]", lo: -top, hi: top };
            plot::axial_slice(grid, &field, &labels)
        }
        _ => {
            let field = r.voidage_map.cell_field(grid);
            let title = format!("{job_name}: time-averaged voidage, {window}");
            let labels = plot::FieldLabels { title: &title, quantity: "⟨ε⟩ [-]", lo: 0.3, hi: 1.0 };
            plot::axial_slice(grid, &field, &labels)
        }
    };
    match image {
        Ok(img) => {
            let disposition = format!("attachment; filename=\"{figure}\"");
            (
                [(header::CONTENT_TYPE, "image/png".to_string()), (header::CONTENT_DISPOSITION, disposition)],
                img.encode(),
            )
                .into_response()
        }
        Err(e) => internal(e.into()),
    }
}
