//! Voidage methods, drag laws and the particle-gas force exchange (paper section 2.3).
