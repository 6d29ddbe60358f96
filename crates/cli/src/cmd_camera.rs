//! `inbetween camera …` (owned by the camera engine work).

use clap::Subcommand;

#[derive(Subcommand)]
pub enum CameraCommand {
    /// Benchmark the camera networks.
    Bench,
}

pub fn run(_c: CameraCommand) -> anyhow::Result<()> {
    anyhow::bail!("`inbetween camera` is not implemented yet")
}

/// The camera part of `inbetween demo`: writes its outputs under `out` and returns lines to print.
pub fn demo(_out: &std::path::Path) -> anyhow::Result<Vec<String>> {
    Ok(Vec::new())
}
