//! `inbetween mocap …` (owned by the mocap engine work).

use clap::Subcommand;

#[derive(Subcommand)]
pub enum MocapCommand {
    /// Benchmark keyframe selection methods.
    Bench,
}

pub fn run(_c: MocapCommand) -> anyhow::Result<()> {
    anyhow::bail!("`inbetween mocap` is not implemented yet")
}

/// The mocap part of `inbetween demo`: writes its outputs under `out` and returns lines to print.
pub fn demo(_out: &std::path::Path) -> anyhow::Result<Vec<String>> {
    Ok(Vec::new())
}
