//! `inbetween demo`: the main job. Runs on a fresh clone with no data: a procedural walk, written as
//! BVH and previewed as a GIF, then each engine's own demo on built-in data.

use anyhow::Context;
use clap::Args;
use inbetween_io::Progress;
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
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    // The mocap and camera demos count their own steps; one here for the walk, the face, video and script demos.
    let steps = Progress::new(inbetween_mocap::demo::STEPS + inbetween_camera::demo::STEPS + 4, "demo");
    let mut lines = vec![inbetween_mocap::demo::opening_walk(&a.out, a.seed)?];
    steps.inc(1);
    lines.extend(inbetween_mocap::demo::run(&a.out, &steps)?);
    lines.extend(inbetween_camera::demo::run(&a.out, &steps)?);
    lines.push(inbetween_face::demo::run(&a.out, a.seed, &Progress::hidden())?.to_string());
    steps.inc(1);
    lines.push(inbetween_video::demo::run(&a.out, a.seed, &Progress::hidden())?.to_string());
    steps.inc(1);
    lines.extend(inbetween_script::demo::run(&a.out, a.seed)?);
    steps.inc(1);
    steps.finish();
    for l in lines {
        println!("{l}");
    }
    Ok(())
}
