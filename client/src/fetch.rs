//! Download a job's results into a folder: the ΔP series as CSV, every snapshot's voidage as
//! .npy and its cells (and particles, when stored) as VTK XML .vtu (.vtp) with a .pvd time series
//! for ParaView, and PNGs of the last voidage slice and of the ΔP (or bed-height) trace.

use crate::api::{Api, ApiError};
use serde_json::Value;
use std::path::{Path, PathBuf};

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
    if let Some(csv) = api.get_bytes(&format!("{base}/pressure-drop?format=csv")).await? {
        save("pressure_drop.csv".into(), csv)?;
    }
    let list = api.get_json(&format!("{base}/snapshots")).await?;
    let snaps: Vec<Value> = list["snapshots"].as_array().cloned().unwrap_or_default();
    let mut pvd_cells = Vec::new();
    let mut pvd_particles = Vec::new();
    let mut particles_stored = true;
    for s in &snaps {
        let n = s["n"].as_u64().unwrap_or(0);
        let t = s["time_s"].as_f64().unwrap_or(0.0);
        let snap = format!("{base}/snapshots/{n}");
        if formats.json {
            if let Some(b) = api.get_bytes(&format!("{snap}?format=json")).await? {
                save(format!("snapshot_{n:06}.json"), b)?;
            }
        }
        if formats.npy {
            for field in ["voidage", "pressure", "gas_velocity"] {
                if let Some(b) = api.get_bytes(&format!("{snap}?format=npy&field={field}")).await? {
                    save(format!("{field}_{n:06}.npy"), b)?;
                }
            }
        }
        if formats.vtk {
            if let Some(b) = api.get_bytes(&format!("{snap}?format=vtu")).await? {
                save(format!("cells_{n:06}.vtu"), b)?;
                pvd_cells.push((t, format!("cells_{n:06}.vtu")));
            }
            if particles_stored {
                match api.get_bytes(&format!("{snap}?format=vtp&what=particles")).await? {
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
    if let Some(last) = snaps.last().and_then(|s| s["n"].as_u64()) {
        if let Some(b) = api.get_bytes(&format!("{base}/snapshots/{last}?format=png&field=voidage")).await? {
            save("voidage_last.png".into(), b)?;
        }
        if let Some(b) = api.get_bytes(&format!("{base}/pressure-drop?format=png")).await? {
            let has_dp = snaps.iter().any(|s| s["pressure_drop_pa"].is_number());
            save(if has_dp { "pressure_drop.png" } else { "mean_particle_height.png" }.into(), b)?;
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
