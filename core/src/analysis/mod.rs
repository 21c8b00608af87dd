//! The paper's analyses (sections 3.3–3.4, Figs 6–9) as pure functions and accumulators: slices
//! in, numbers or structs out, no I/O. Every sampled signal is taken at a uniform step `dt`.
//!
//! - [`layers`]: layer means of a cell field and the bed pressure drop from them;
//! - [`stats`]: mean and standard deviation of a signal (ΔP);
//! - [`spectrum`]: Welch power spectrum and its dominant frequency;
//! - [`correlation`]: cross-correlation of two signals and the rise velocity it gives (Müller et
//!   al. 2007a);
//! - [`layer_series`]: cross-section voidage (or pressure) per layer over time, the input of the
//!   bubble counts and correlations;
//! - [`bubble_count`]: bubbles passing a height per second (threshold crossings with hysteresis);
//! - [`bubble_fraction`]: bubble volume fraction by height;
//! - [`eruptions`]: bubble eruptions at the bed surface against ΔP (paper Fig. 9);
//! - [`particle_average`]: particle-based time averages per cell (Boyce et al. 2013);
//! - [`field_average`]: time averages of the cell fields (voidage, gas velocity);
//! - [`profiles`]: radial profiles at chosen heights and azimuthal-mean maps on the axial plane;
//! - [`roughness`]: the cell-to-cell jumps of a field (paper Fig. 3).
//!
//! The accumulators (`LayerSeries`, `BubbleFraction`, `ParticleAverage`, `FieldAverage`) are
//! `Serialize + Deserialize` so a running job can keep them in its checkpoint; each has
//! `add_sample(..)` and `finish()`, which reads the state without consuming it.

pub mod bubble_count;
pub mod bubble_fraction;
pub mod correlation;
pub mod eruptions;
pub mod field_average;
pub mod layer_series;
pub mod layers;
pub mod particle_average;
pub mod peak_frequency;
pub mod profiles;
pub mod roughness;
pub mod spectrum;
pub mod stats;

pub use bubble_count::{count_bubbles, BubbleCount};
pub use bubble_fraction::{BubbleFraction, ByHeight};
pub use correlation::{cross_correlation, rise_velocity, RiseVelocity};
pub use eruptions::{eruption_link, EruptionLink};
pub use field_average::{FieldAverage, FieldMeans};
pub use layer_series::LayerSeries;
pub use layers::{bed_pressure_drop, layer_means, surface_height};
pub use particle_average::{ParticleAverage, ParticleMeans};
pub use peak_frequency::peak_frequency;
pub use profiles::{axial_map, radial_profile, AxialMap, RadialProfile};
pub use roughness::roughness;
pub use spectrum::{dominant_frequency, welch, Spectrum};
pub use stats::{signal_stats, SignalStats};

#[cfg(test)]
mod test_signals;
