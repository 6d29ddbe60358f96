//! `info` and `convert` (owned by the io work).

use anyhow::Context;
use clap::Args;
use inbetween_core::roles::RoleOverrides;
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_io::convert::ConvertJob;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub struct InfoArgs {
    /// A .bvh file, or an .amc file (its .asf is looked up beside it or given with --asf).
    pub file: PathBuf,
    /// The ASF skeleton of an .amc file, when it is not beside it (`01_01.amc` → `01.asf`).
    #[arg(long)]
    pub asf: Option<PathBuf>,
    /// Length unit of the file: cm, m, mm, in, cmu (CMU mocap units, 5.6444 cm) or cm per unit
    /// (e.g. 2.54). Default: inferred from the skeleton's rest pose (printed with the reason).
    #[arg(long)]
    pub unit: Option<LengthUnit>,
    /// A roles file naming the joints whose role neither names nor shape settle: JSON, role → joint
    /// name (`{"left_upper_arm": "lShldrBend", "hips": "hip"}`).
    #[arg(long)]
    pub roles: Option<PathBuf>,
}

#[derive(Args)]
pub struct ConvertArgs {
    /// Input motion: .bvh, or .amc (with its .asf beside it or given with --asf).
    pub input: PathBuf,
    /// Output BVH file (written atomically).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The ASF skeleton of an .amc input, when it is not beside it.
    #[arg(long)]
    pub asf: Option<PathBuf>,
    /// Resample to this frame rate (after cropping).
    #[arg(long)]
    pub fps: Option<f64>,
    /// First input frame to keep (0-based).
    #[arg(long)]
    pub start: Option<usize>,
    /// Input frame to stop before (exclusive; default: the end of the clip).
    #[arg(long)]
    pub end: Option<usize>,
}

pub fn info(a: InfoArgs) -> anyhow::Result<()> {
    let m = inbetween_io::convert::load_motion_with(&a.file, a.asf.as_deref())?;
    let unit = UnitChoice::resolve(a.unit, &m.skeleton);
    let text = inbetween_io::info::describe_motion(&a.file, &m, &unit, &read_roles(a.roles.as_deref())?);
    print_tolerating_closed_pipe(&crate::errors::with_flags(&text))
}

/// The roles file given with `--roles` (none: no overrides); errors name the file, line and column.
pub(crate) fn read_roles(path: Option<&Path>) -> anyhow::Result<RoleOverrides> {
    let Some(path) = path else { return Ok(RoleOverrides::default()) };
    let text = std::fs::read_to_string(path).with_context(|| format!("reading the roles file {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| {
        format!("{}: expected a JSON object of role → joint name, e.g. {{\"left_hand\": \"lHand\"}}", path.display())
    })
}

/// Prints `text`; a reader that stops early (`| head`) is not an error.
fn print_tolerating_closed_pipe(text: &str) -> anyhow::Result<()> {
    use std::io::Write as _;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

pub fn convert(a: ConvertArgs) -> anyhow::Result<()> {
    let job = ConvertJob { input: a.input, asf: a.asf, output: a.output, start: a.start, end: a.end, fps: a.fps };
    println!("{}", job.run()?);
    Ok(())
}
