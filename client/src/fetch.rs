//! Download a job's results into a folder: the ΔP series as CSV, every snapshot's voidage as
//! .npy and its cells (and particles, when stored) as VTK XML .vtu (.vtp) with a .pvd time series
//! for ParaView, and PNGs of the last voidage slice and of the ΔP (or bed-height) trace.

use crate::api::{Api, ApiError};
use fluidbed_api::{SeriesFormat, SeriesQuery, SnapshotField, SnapshotFormat, SnapshotQuery, ANALYSIS_FIGURES};
use std::path::{Path, PathBuf};

fn snapshot(format: SnapshotFormat, field: Option<SnapshotField>) -> SnapshotQuery {
    SnapshotQuery { format: Some(format), field, what: None }
}

fn series(format: SeriesFormat) -> SeriesQuery {
    SeriesQuery { format: Some(format) }
}

/// Which encodings to download per snapshot.
#[derive(Clone, Debug)]
pub struct Formats {
    pub npy: bool,
    pub vtk: bool,
    pub json: bool,
}

impl Formats {
    pub fn parse(s: &str) -> Result<Formats, String> {
        let mut f = Formats { npy: false, vtk: false, json: false };
        for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            match part {
                "npy" => f.npy = true,
                "vtk" => f.vtk = true,
                "json" => f.json = true,
                other => return Err(format!("unknown format `{other}` (npy, vtk, json)")),
            }
        }
        Ok(f)
    }
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), ApiError> {
    std::fs::write(path, bytes).map_err(|e| ApiError::Server(format!("cannot write {}: {e}", path.display())))
}

/// Fetch everything into `out`; returns the files written.
pub async fn fetch(api: &Api, id: &str, out: &Path, formats: &Formats) -> Result<Vec<PathBuf>, ApiError> {
    std::fs::create_dir_all(out).map_err(|e| ApiError::Server(format!("cannot create {}: {e}", out.display())))?;
    let mut files = Vec::new();
    let mut save = |name: String, bytes: Vec<u8>| -> Result<(), ApiError> {
        let p = out.join(name);
        write(&p, &bytes)?;
        files.push(p);
        Ok(())
    };
    let base = format!("/v1/jobs/{id}");
    let pressure_drop = format!("{base}/pressure-drop");
    if let Some(csv) = api.get_bytes(&pressure_drop, &series(SeriesFormat::Csv)).await? {
        save("pressure_drop.csv".into(), csv)?;
    }
    let snaps = api.snapshots(id).await?.snapshots;
    let mut pvd_cells = Vec::new();
    let mut pvd_particles = Vec::new();
    let mut particles_stored = true;
    for s in &snaps {
        let (n, t) = (s.n, s.time_s);
        let snap = format!("{base}/snapshots/{n}");
        if formats.json {
            if let Some(b) = api.get_bytes(&snap, &snapshot(SnapshotFormat::Json, None)).await? {
                save(format!("snapshot_{n:06}.json"), b)?;
            }
        }
        if formats.npy {
            for (field, name) in [
                (SnapshotField::Voidage, "voidage"),
                (SnapshotField::Pressure, "pressure"),
                (SnapshotField::GasVelocity, "gas_velocity"),
            ] {
                if let Some(b) = api.get_bytes(&snap, &snapshot(SnapshotFormat::Npy, Some(field))).await? {
                    save(format!("{name}_{n:06}.npy"), b)?;
                }
            }
        }
        if formats.vtk {
            if let Some(b) = api.get_bytes(&snap, &snapshot(SnapshotFormat::Vtu, None)).await? {
                save(format!("cells_{n:06}.vtu"), b)?;
                pvd_cells.push((t, format!("cells_{n:06}.vtu")));
            }
            if particles_stored {
                match api.get_bytes(&snap, &snapshot(SnapshotFormat::Vtp, Some(SnapshotField::Particles))).await? {
                    Some(b) => {
                        save(format!("particles_{n:06}.vtp"), b)?;
                        pvd_particles.push((t, format!("particles_{n:06}.vtp")));
                    }
                    None => particles_stored = false,
                }
            }
        }
    }
    for (name, list) in [("cells.pvd", &pvd_cells), ("particles.pvd", &pvd_particles)] {
        if !list.is_empty() {
            save(name.into(), pvd(list).into_bytes())?;
        }
    }
    if let Some(last) = snaps.last().map(|s| s.n) {
        let png = snapshot(SnapshotFormat::Png, Some(SnapshotField::Voidage));
        if let Some(b) = api.get_bytes(&format!("{base}/snapshots/{last}"), &png).await? {
            save("voidage_last.png".into(), b)?;
        }
        if let Some(b) = api.get_bytes(&pressure_drop, &series(SeriesFormat::Png)).await? {
            let has_dp = snaps.iter().any(|s| s.pressure_drop_pa.is_some());
            save(if has_dp { "pressure_drop.png" } else { "mean_particle_height.png" }.into(), b)?;
        }
    }
    files.extend(fetch_analysis(api, id, out, None).await?);
    Ok(files)
}

/// The job's analysis into `out`: `analysis.json` and the figures it has samples for (a figure
/// without enough samples, or a job without a checkpoint yet, is skipped).
/// The analysis and its figures into `out`; `from_s` starts the time-series statistics later.
pub async fn fetch_analysis(api: &Api, id: &str, out: &Path, from_s: Option<f64>) -> Result<Vec<PathBuf>, ApiError> {
    let q = fluidbed_api::AnalysisQuery { from: from_s };
    std::fs::create_dir_all(out).map_err(|e| ApiError::Server(format!("cannot create {}: {e}", out.display())))?;
    let base = format!("/v1/jobs/{id}/analysis");
    let mut files = Vec::new();
    let Some(json) = api.get_bytes(&base, &q).await? else {
        return Ok(files);
    };
    for (name, bytes) in std::iter::once(("analysis.json".to_string(), Some(json))).chain({
        let mut figs = Vec::new();
        for f in ANALYSIS_FIGURES {
            figs.push((f.to_string(), api.get_bytes(&format!("{base}/{f}"), &q).await?));
        }
        figs
    }) {
        if let Some(b) = bytes {
            let p = out.join(name);
            write(&p, &b)?;
            files.push(p);
        }
    }
    Ok(files)
}

/// A ParaView collection (.pvd) listing the snapshot files with their times.
fn pvd(files: &[(f64, String)]) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");
    for (t, f) in files {
        s.push_str(&format!("<DataSet timestep=\"{t}\" part=\"0\" file=\"{f}\"/>\n"));
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}
