//! `info` and `convert` (owned by the io work).

use anyhow::Context;
use clap::Args;
use inbetween_core::roles::{Role, RoleOverrides};
use inbetween_core::units::{rest_pose_extent, LengthUnit, UnitChoice};
use inbetween_core::{Motion, Skeleton};
use std::fmt::Write as _;
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

fn load(file: &Path, asf: Option<&Path>) -> anyhow::Result<Motion> {
    let motion = match asf {
        Some(asf) => inbetween_io::read_asf_amc(asf, file)?,
        None => inbetween_io::load_motion(file)?,
    };
    Ok(motion)
}

pub fn info(a: InfoArgs) -> anyhow::Result<()> {
    let m = load(&a.file, a.asf.as_deref())?;
    let mut out = String::new();
    writeln!(out, "file:      {}", a.file.display())?;
    writeln!(out, "joints:    {}", m.skeleton.len())?;
    writeln!(out, "channels:  {}", m.num_channels())?;
    writeln!(out, "frames:    {}", m.num_frames())?;
    writeln!(out, "fps:       {:.3} (frame time {} s)", m.fps(), m.frame_time)?;
    writeln!(out, "duration:  {:.3} s", m.duration())?;
    let unit = UnitChoice::resolve(a.unit, &m.skeleton);
    writeln!(out, "unit:      {} ({})", unit.unit.describe(), crate::errors::with_flags(&unit.reason))?;
    let size = rest_pose_extent(&m.skeleton);
    writeln!(out, "rest pose: {size:.2} units = {:.1} cm tall (or wide)", size * unit.cm_per_unit())?;
    let overrides = read_roles(a.roles.as_deref())?;
    match inbetween_core::roles::find_motion_roles(&m, &overrides) {
        Ok(r) => {
            let found = r.scheme.map(|s| format!("names read as {}", s.label())).unwrap_or("no known names".into());
            writeln!(
                out,
                "roles:     {} of {} ({found}; confidence {:.2})",
                r.roles.len(),
                Role::ALL.len(),
                r.confidence()
            )?;
            write!(out, "{r}")?;
        }
        Err(e) => writeln!(out, "roles:     none: {}", crate::errors::with_flags(&e.to_string()))?,
    }
    writeln!(out, "skeleton:")?;
    write_tree(&mut out, &m.skeleton)?;
    print_tolerating_closed_pipe(&out)
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

/// One line per joint, indented by depth: name, offset, channels.
fn write_tree(out: &mut String, s: &Skeleton) -> std::fmt::Result {
    let mut depth = vec![0usize; s.len()];
    let mut stack = vec![0usize];
    while let Some(j) = stack.pop() {
        let joint = s.joint(j);
        if let Some(p) = joint.parent {
            depth[j] = depth[p] + 1;
        }
        let channels: Vec<&str> = joint.channels.iter().map(|c| c.name()).collect();
        let end =
            joint.end_site.map(|e| format!("  end site ({:.3}, {:.3}, {:.3})", e.x, e.y, e.z)).unwrap_or_default();
        writeln!(
            out,
            "  {}{}  offset ({:.3}, {:.3}, {:.3})  [{}] {}{end}",
            "  ".repeat(depth[j]),
            joint.name,
            joint.offset.x,
            joint.offset.y,
            joint.offset.z,
            channels.len(),
            channels.join(" "),
        )?;
        let children: Vec<usize> = s.children(j).collect();
        stack.extend(children.into_iter().rev());
    }
    Ok(())
}

pub fn convert(a: ConvertArgs) -> anyhow::Result<()> {
    let mut m = load(&a.input, a.asf.as_deref())?;
    let n = m.num_frames();
    if a.start.is_some() || a.end.is_some() {
        let (start, end) = (a.start.unwrap_or(0), a.end.unwrap_or(n));
        m = m.crop(start, end).with_context(|| format!("cropping {}", a.input.display()))?;
    }
    if let Some(fps) = a.fps {
        m = m.resample(fps).with_context(|| format!("resampling to {fps} fps"))?;
    }
    inbetween_io::write_bvh(&a.output, &m)?;
    println!(
        "wrote {}: {} joints, {} channels, {} frames at {:.3} fps ({:.3} s) from {} input frames",
        a.output.display(),
        m.skeleton.len(),
        m.num_channels(),
        m.num_frames(),
        m.fps(),
        m.duration(),
        n
    );
    Ok(())
}
