//! Voidage methods, drag laws and the particle-gas force exchange (paper section 2.3).

pub mod drag;
pub mod exchange;
pub mod fast_math;
mod sublayer_pressure;
pub mod voidage;

pub use drag::{beetstra_f, beta_a, drag_force, DragLaw, DragModel};
pub use exchange::{layers_with_particles, DragCells, Exchange, ExchangeParams, GasAtCells};
pub use voidage::{build_voidage, voidage_from_solid, VoidageMethod};
