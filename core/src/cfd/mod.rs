//! The compressible, volume-averaged gas solver on the cylindrical grid (paper section 2.2, Appendix A).
