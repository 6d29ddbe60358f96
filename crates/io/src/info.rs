//! `inbetween info`: what a motion file holds, in words: joints, channels, frames, rate, duration,
//! the length unit (given or inferred, with the reason), the size of the rest pose, the joint roles
//! found on the rig ([`inbetween_core::roles`]) and the joint tree.

use std::fmt::Write as _;
use std::path::Path;

use inbetween_core::roles::{find_motion_roles, Role, RoleOverrides};
use inbetween_core::units::{rest_pose_extent, UnitChoice};
use inbetween_core::{Motion, Skeleton};

/// The description of `m` (read from `file`) with its length unit `unit` and the roles found with
/// `overrides`, one fact a line, then the joint tree.
pub fn describe_motion(file: &Path, m: &Motion, unit: &UnitChoice, overrides: &RoleOverrides) -> String {
    let mut out = String::new();
    let _ = write_description(&mut out, file, m, unit, overrides);
    out
}

fn write_description(
    out: &mut String,
    file: &Path,
    m: &Motion,
    unit: &UnitChoice,
    overrides: &RoleOverrides,
) -> std::fmt::Result {
    writeln!(out, "file:      {}", file.display())?;
    writeln!(out, "joints:    {}", m.skeleton.len())?;
    writeln!(out, "channels:  {}", m.num_channels())?;
    writeln!(out, "frames:    {}", m.num_frames())?;
    writeln!(out, "fps:       {:.3} (frame time {} s)", m.fps(), m.frame_time)?;
    writeln!(out, "duration:  {:.3} s", m.duration())?;
    writeln!(out, "unit:      {} ({})", unit.unit.describe(), unit.reason)?;
    let size = rest_pose_extent(&m.skeleton);
    writeln!(out, "rest pose: {size:.2} units = {:.1} cm tall (or wide)", size * unit.cm_per_unit())?;
    match find_motion_roles(m, overrides) {
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
        Err(e) => writeln!(out, "roles:     none: {e}")?,
    }
    writeln!(out, "skeleton:")?;
    write_tree(out, &m.skeleton)
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

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn describes_counts_unit_roles_and_every_joint() {
        let m = gait(&GaitParams { frames: 10, ..GaitParams::walk() });
        let unit = UnitChoice::resolve(None, &m.skeleton);
        let text = describe_motion(Path::new("walk.bvh"), &m, &unit, &RoleOverrides::default());
        assert!(text.starts_with("file:      walk.bvh\n"), "{text}");
        assert!(text.contains(&format!("joints:    {}\n", m.skeleton.len())), "{text}");
        assert!(text.contains("frames:    10\n") && text.contains("roles:     "), "{text}");
        for j in 0..m.skeleton.len() {
            assert!(text.contains(&m.skeleton.joint(j).name), "{}", m.skeleton.joint(j).name);
        }
    }
}
