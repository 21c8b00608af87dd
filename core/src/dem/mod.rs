//! Soft-sphere DEM: Hertz + Tsuji contacts, tube wall, AB3 (paper section 2.1).
