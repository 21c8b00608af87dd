//! fluidbed-core: the complete DEM-CFD solver for 3D cylindrical gas-fluidized beds,
//! after Boyce, Holland, Scott & Dennis (2014). No async, no HTTP: data flows one way,
//! case JSON -> `Case` -> `Simulation` -> `Snapshot`s.

pub mod analysis;
mod buffers;
pub mod case;
pub mod cfd;
pub mod coupling;
pub mod dem;
pub mod grid;
pub mod memory;
pub mod output;
pub mod sim;
mod simd;
mod team;
