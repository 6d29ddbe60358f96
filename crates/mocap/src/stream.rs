//! stream: in progress.
