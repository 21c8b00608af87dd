//! Pressure drop, time averages, particle-based averages.
