//! Physics tests of the gas solver against analytic values.

mod acoustics;
mod conservation;
mod forward_backward;
mod freeboard;
mod hydrostatic;
mod lateral_redistribution;
mod layer_pressure;
mod mass_budget;
mod outlet_pressure;
mod porous_zone;
mod support;
mod team;
mod validation;
mod voidage_in_time;
