//! Benchmarks (placeholder, filled next).
