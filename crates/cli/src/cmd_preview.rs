//! `preview` (owned by the render work).

use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct PreviewArgs {
    pub file: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(_a: PreviewArgs) -> anyhow::Result<()> {
    anyhow::bail!("`inbetween preview` is not implemented yet")
}
