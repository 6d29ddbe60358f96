//! `inbetween demo`: the main job. Runs on a fresh clone with no data: a procedural walk, written as
//! BVH and previewed, then each engine's own demo.

use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct DemoArgs {
    /// Folder for the outputs.
    #[arg(short, long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Seed for the procedural motion.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    std::fs::create_dir_all(&a.out)?;
    let mut lines = Vec::new();
    lines.extend(crate::cmd_mocap::demo(&a.out)?);
    lines.extend(crate::cmd_camera::demo(&a.out)?);
    for l in lines {
        println!("{l}");
    }
    Ok(())
}
