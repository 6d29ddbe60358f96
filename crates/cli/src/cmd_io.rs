//! `info` and `convert` (owned by the io work).

use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct InfoArgs {
    /// A .bvh file, or an .amc file (its .asf is looked up beside it or given with --asf).
    pub file: PathBuf,
}

#[derive(Args)]
pub struct ConvertArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn info(_a: InfoArgs) -> anyhow::Result<()> {
    anyhow::bail!("`inbetween info` is not implemented yet")
}

pub fn convert(_a: ConvertArgs) -> anyhow::Result<()> {
    anyhow::bail!("`inbetween convert` is not implemented yet")
}
