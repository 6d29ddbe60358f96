//! Training loop (placeholder, filled next).
