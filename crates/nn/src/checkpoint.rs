//! Checkpoints (placeholder, filled next).
