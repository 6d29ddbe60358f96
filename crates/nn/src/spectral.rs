//! Spectral normalisation (placeholder, filled next).
