//! Snapshot encoders: .npy arrays, legacy VTK files for ParaView, PNG images (a voidage slice and
//! a time trace). Snapshots are stored compactly by the server and encoded here on request.

pub mod fields;
pub mod npy;
pub mod plot;
pub mod png;
pub mod vtk;
pub mod vtk_xml;

#[cfg(test)]
mod tests;
