//! Snapshot encoders: JSON, .npy, VTK, PNG.
