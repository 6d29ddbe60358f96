//! codec: in progress.
