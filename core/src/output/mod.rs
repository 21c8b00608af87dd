//! Snapshot encoders: .npy arrays, VTK files for ParaView, PNG figures (a field on the axial
//! plane and a time trace, drawn with plotters). Snapshots are stored compactly by the server and encoded here on request.

pub mod fields;
pub mod npy;
pub mod plot;
pub mod png;
pub mod vtk;
pub mod vtk_xml;

#[cfg(test)]
mod tests;
