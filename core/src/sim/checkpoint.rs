//! The checkpoint file: a self-describing header, then the state in named sections.
//!
//! Layout: `FLUIDBED`, the format number (u32 LE), the header's length (u32 LE), the header as
//! JSON (the format, the writer's version, and per section its name, encoding, byte length and
//! the shapes of its main arrays), then the sections' bytes in the header's order. A reader
//! finds sections by name, so a format that adds a section still reads the others, and every
//! refusal names the format (and writer) of the file and of this build, and the section at fault.
//!
//! Formats: 1–3 had no header (one bincode blob after the number); 4 is this layout; 5 adds the
//! DEM pair pass's chunk cuts to the `dem` section. The `analysis` section (the run's analysis
//! samples) is optional: a file without it resumes with an empty analysis window; so is
//! `gas_mass_budget` (cfd/mass_budget.rs): without it the budget starts at the resumed state; and
//! `gas_voidage_ramp` (cfd/voidage_ramp.rs): without it the gas holds its voidage; and
//! `pressure_follow` (sim/pressure_follow.rs): without it the particles' pressure force is held
//! until the next coupling; and `pressure_mean` (sim/pressure_mean.rs): without it the next
//! coupling's mean starts from its steps on.

use super::State;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub(super) const MAGIC: &[u8; 8] = b"FLUIDBED";
/// Bumped whenever a section changes shape; `describe` shows what a file holds.
pub(super) const FORMAT: u32 = 5;
/// Who wrote a checkpoint (in its header, for the messages).
const WRITER: &str = concat!("fluidbed-core ", env!("CARGO_PKG_VERSION"));

/// The header: what the file holds, in order.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Header {
    pub format: u32,
    pub writer: String,
    pub sections: Vec<Section>,
}

/// One named part of the state.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Section {
    pub name: String,
    /// `json` or `bincode-1` (serde's field order, little-endian, fixed-width integers).
    pub encoding: String,
    pub bytes: u64,
    /// Lengths of the section's main arrays (e.g. `positions: [n, 3]`), for readers and messages.
    pub shapes: BTreeMap<String, Vec<usize>>,
}

/// The state as a checkpoint.
pub(super) fn encode(st: &State) -> Vec<u8> {
    let n = st.dem.len();
    let (entries, near) = st.dem.list_sizes();
    let dem_shapes = [("positions", vec![n, 3]), ("verlet_list", vec![entries]), ("near_list", vec![near])];
    let parts = [
        part("case", "json", serde_json::to_vec(&st.case).expect("case serialises"), &[]),
        part("plan", "bincode-1", bincode_of(&st.plan), &[]),
        part("counters", "bincode-1", bincode_of(&(st.steps, st.snapshots_taken)), &[]),
        part("dem", "bincode-1", bincode_of(&st.dem), &dem_shapes),
        part("gas", "bincode-1", bincode_of(&st.gas), &[]),
        part("analysis", "bincode-1", bincode_of(&st.analysis), &[]),
        part("gas_mass_budget", "bincode-1", bincode_of(&st.gas.as_ref().map(|g| g.mass_budget())), &[]),
        part("gas_voidage_ramp", "bincode-1", bincode_of(&st.gas.as_ref().and_then(|g| g.voidage_ramp())), &[]),
        part("pressure_follow", "bincode-1", bincode_of(&st.follow), &[]),
        part("pressure_mean", "bincode-1", bincode_of(&st.mean), &[]),
    ];
    let header =
        Header { format: FORMAT, writer: WRITER.into(), sections: parts.iter().map(|p| p.0.clone()).collect() };
    let head = serde_json::to_vec(&header).expect("header serialises");
    let mut out = MAGIC.to_vec();
    out.extend_from_slice(&FORMAT.to_le_bytes());
    out.extend_from_slice(&(head.len() as u32).to_le_bytes());
    out.extend_from_slice(&head);
    for (_, body) in parts {
        out.extend_from_slice(&body);
    }
    out
}

fn part(name: &str, encoding: &str, body: Vec<u8>, shapes: &[(&str, Vec<usize>)]) -> (Section, Vec<u8>) {
    let shapes = shapes.iter().map(|(k, v)| (k.to_string(), v.clone())).collect();
    (Section { name: name.into(), encoding: encoding.into(), bytes: body.len() as u64, shapes }, body)
}

fn bincode_of<T: Serialize>(v: &T) -> Vec<u8> {
    bincode::serialize(v).expect("state serialises")
}

/// The header of a checkpoint and its sections' bytes by name, or why it cannot be read.
pub fn describe(bytes: &[u8]) -> Result<(Header, BTreeMap<String, &[u8]>), String> {
    let Some(rest) = bytes.strip_prefix(MAGIC).filter(|r| r.len() >= 4) else {
        return Err("not a fluidbed checkpoint, or one from a version before checkpoint formats (November 2026); rerun the case".into());
    };
    let format = u32::from_le_bytes(rest[..4].try_into().expect("four bytes"));
    if format != FORMAT {
        let era = if format < 4 { " (before self-describing headers)" } else { "" };
        return Err(format!(
            "written in checkpoint format {format}{era}, this build ({WRITER}) reads format {FORMAT}; rerun the case or resume it with the fluidbed version that wrote it"
        ));
    }
    let rest = &rest[4..];
    let len = rest.get(..4).map(|b| u32::from_le_bytes(b.try_into().expect("four bytes")) as usize);
    let head = len.and_then(|l| rest.get(4..4 + l)).ok_or("checkpoint header cut short")?;
    let header: Header = serde_json::from_slice(head).map_err(|e| format!("checkpoint header: {e}"))?;
    let mut at = 4 + head.len();
    let mut sections = BTreeMap::new();
    for s in &header.sections {
        let end = at + s.bytes as usize;
        let body = rest.get(at..end).ok_or_else(|| format!("checkpoint section {} cut short", s.name))?;
        sections.insert(s.name.clone(), body);
        at = end;
    }
    Ok((header, sections))
}

/// The state of a checkpoint written by this format.
pub(super) fn decode(bytes: &[u8]) -> Result<State, String> {
    let (header, sections) = describe(bytes)?;
    let section = |name: &str| -> Result<&[u8], String> {
        sections.get(name).copied().ok_or_else(|| format!("checkpoint by {} has no section {name}", header.writer))
    };
    let refuse = |name: &str, e: String| {
        let shapes =
            header.sections.iter().find(|s| s.name == name).map(|s| format!(" {:?}", s.shapes)).unwrap_or_default();
        format!(
            "checkpoint section {name}{shapes} written by {} (format {}) does not match this build ({WRITER}, format {FORMAT}): {e}",
            header.writer, header.format
        )
    };
    let case: crate::case::Case =
        serde_json::from_slice(section("case")?).map_err(|e| refuse("case", e.to_string()))?;
    let plan = bincode::deserialize(section("plan")?).map_err(|e| refuse("plan", e.to_string()))?;
    let (steps, snapshots_taken) =
        bincode::deserialize(section("counters")?).map_err(|e| refuse("counters", e.to_string()))?;
    let dem = bincode::deserialize(section("dem")?).map_err(|e| refuse("dem", e.to_string()))?;
    let mut gas: Option<crate::cfd::GasSolver> =
        bincode::deserialize(section("gas")?).map_err(|e| refuse("gas", e.to_string()))?;
    // The gas's time scheme is the case's (the gas section holds its state only).
    if let (Some(g), Some(gc)) = (gas.as_mut(), case.gas.as_ref()) {
        g.set_time_scheme(gc.time_scheme);
        g.set_inlet_jet(gc.inlet_jet.as_ref());
    }
    // A checkpoint from before the gas mass budget starts it afresh at the resumed state.
    if let Some(body) = sections.get("gas_mass_budget") {
        let budget: Option<crate::cfd::MassBudget> =
            bincode::deserialize(body).map_err(|e| refuse("gas_mass_budget", e.to_string()))?;
        if let (Some(g), Some(b)) = (gas.as_mut(), budget) {
            g.set_mass_budget(b);
        }
    }
    // A checkpoint from before the voidage ramp (or of a run without one) holds the voidage.
    if let Some(body) = sections.get("gas_voidage_ramp") {
        let mut ramp: Option<crate::cfd::VoidageRamp> =
            bincode::deserialize(body).map_err(|e| refuse("gas_voidage_ramp", e.to_string()))?;
        if let Some(r) = ramp.as_mut() {
            r.set_extrapolated(case.coupling.gas_voidage == crate::case::GasVoidage::Extrapolated);
        }
        if let Some(g) = gas.as_mut() {
            g.set_voidage_ramp(ramp);
        }
    }
    // A checkpoint from before the run analysis starts its window afresh.
    let analysis = match sections.get("analysis") {
        Some(body) => bincode::deserialize(body).map_err(|e| refuse("analysis", e.to_string()))?,
        None => super::RunAnalysis::new(&case, &super::fluid_grid(&case)),
    };
    // A checkpoint from before the pressure force followed the gas holds it until the next coupling.
    let follow = match sections.get("pressure_follow") {
        Some(body) => bincode::deserialize(body).map_err(|e| refuse("pressure_follow", e.to_string()))?,
        None => Default::default(),
    };
    let mean = match sections.get("pressure_mean") {
        Some(body) => bincode::deserialize(body).map_err(|e| refuse("pressure_mean", e.to_string()))?,
        None => Default::default(),
    };
    Ok(State { case, plan, steps, snapshots_taken, dem, gas, analysis, follow, mean })
}

/// The case and the run analysis of a checkpoint, read without the particle and gas state.
pub(super) fn analysis_of(bytes: &[u8]) -> Result<(crate::case::Case, super::RunAnalysis), String> {
    let (header, sections) = describe(bytes)?;
    let case_bytes = sections.get("case").ok_or_else(|| format!("checkpoint by {} has no case", header.writer))?;
    let case: crate::case::Case = serde_json::from_slice(case_bytes).map_err(|e| format!("checkpoint case: {e}"))?;
    let analysis = match sections.get("analysis") {
        Some(body) => bincode::deserialize(body).map_err(|e| format!("checkpoint section analysis: {e}"))?,
        None => super::RunAnalysis::new(&case, &super::fluid_grid(&case)),
    };
    Ok((case, analysis))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::Case;
    use crate::sim::Simulation;

    /// The four-particle DEM-only case the format-3 file below was written from.
    fn small_case() -> Case {
        let mut case: Case = serde_json::from_str(
            r#"{"name":"format 3 fixture","column":{"diameter_m":0.01,"height_m":0.02},"particles":{},"bed":{"explicit":{"positions_m":[[0,0,0.0006],[0.0013,0,0.0006],[0,0.0013,0.0006],[0.0005,0.0005,0.0019]]}},"end_time_s":0.001}"#,
        )
        .unwrap();
        case.outputs.snapshot_interval_s = 0.0005;
        case
    }

    #[test]
    fn header_names_the_sections_and_their_shapes_and_restores() {
        let mut sim = Simulation::new(small_case(), None).unwrap();
        sim.advance(100).unwrap();
        sim.advance(100).unwrap();
        let bytes = sim.checkpoint();
        let (header, sections) = describe(&bytes).unwrap();
        assert_eq!((header.format, header.writer.as_str()), (FORMAT, WRITER));
        let names: Vec<&str> = header.sections.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "case",
                "plan",
                "counters",
                "dem",
                "gas",
                "analysis",
                "gas_mass_budget",
                "gas_voidage_ramp",
                "pressure_follow",
                "pressure_mean"
            ]
        );
        let dem = header.sections.iter().find(|s| s.name == "dem").unwrap();
        assert_eq!(dem.shapes["positions"], [4, 3]);
        assert_eq!(sections["dem"].len() as u64, dem.bytes);
        let back = Simulation::restore(&bytes).unwrap();
        assert_eq!(back.steps(), sim.steps());
        assert_eq!(back.dem().positions(), sim.dem().positions());
        let budget = |s: &Simulation| s.gas().map(|g| g.mass_budget());
        assert_eq!(budget(&back), budget(&sim));
        // A section that no longer matches is refused with its name, shapes and both versions.
        let mut bad = bytes.clone();
        let cut = bad.len()
            - sections["pressure_mean"].len()
            - sections["pressure_follow"].len()
            - sections["gas_voidage_ramp"].len()
            - sections["gas_mass_budget"].len()
            - sections["analysis"].len()
            - sections["gas"].len()
            - 8;
        bad.truncate(cut);
        let err = Simulation::restore(&bad).err().unwrap().to_string();
        assert!(err.contains("section dem cut short"), "{err}");
    }

    /// A checkpoint written by the previous format (3, by the build before this layout, from
    /// `small_case`) is refused with a message naming both formats.
    #[test]
    fn a_previous_format_checkpoint_is_refused_naming_both_formats() {
        let old = include_bytes!("testdata/checkpoint_format3.bin");
        assert_eq!(&old[..8], MAGIC);
        assert_eq!(u32::from_le_bytes(old[8..12].try_into().unwrap()), 3, "the fixture is format 3");
        let err = Simulation::restore(old).err().expect("format 3 is refused").to_string();
        assert!(err.contains("checkpoint format 3") && err.contains(&format!("reads format {FORMAT}")), "{err}");
        // And a future format the same way.
        let mut new = Simulation::new(small_case(), None).unwrap().checkpoint();
        new[8..12].copy_from_slice(&(FORMAT + 1).to_le_bytes());
        let err = Simulation::restore(&new).err().unwrap().to_string();
        assert!(
            err.contains(&format!("checkpoint format {}", FORMAT + 1))
                && err.contains(&format!("reads format {FORMAT}")),
            "{err}"
        );
    }
}
