//! A scene from two (or more) mocap takes (issue 24): each character's root is its hips joint and its
//! shoulders its upper-arm joints, as [`inbetween_core::roles`] finds them on any rig (by name or by
//! shape; a roles file settles the rest), in metres (the length unit inferred per
//! file, as elsewhere), Y up as in BVH. Takes at other frame rates are resampled to the first one's;
//! the scene lasts as long as the shortest take.

use glam::DVec3;
use inbetween_core::roles::{find_motion_roles, Role, RoleOverrides, Side};
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::{positions_clip, Motion};

use super::scene::{CharacterPoints, Scene};

/// What [`scene_from_motions`] did beyond the obvious, for the user to read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneNotes {
    pub lines: Vec<String>,
    /// The character moved aside and by how much (metres), when the takes stood at one spot: the
    /// scene's world is then not the takes' own (a camera pose given in the takes' world would
    /// frame the moved character where it no longer is).
    pub moved: Option<(usize, DVec3)>,
}

/// A scene of `takes` (name shown to the user, motion). Errors name the take and what was expected.
pub fn scene_from_motions(takes: &[(&str, &Motion)]) -> Result<(Scene, SceneNotes), String> {
    scene_from_motions_with(takes, &RoleOverrides::default())
}

/// The scene of two mocap files (BVH, or ASF+AMC as `.amc` with its `.asf` beside it) as its
/// characters, with the roles `overrides` names; also the scene's name (the files joined by ` + `).
pub fn scene_from_files(
    paths: &[std::path::PathBuf],
    overrides: &RoleOverrides,
) -> Result<(Scene, SceneNotes, String), crate::CameraError> {
    let motions = paths.iter().map(|p| inbetween_io::load_motion(p)).collect::<Result<Vec<_>, _>>()?;
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    let takes: Vec<(&str, &Motion)> = names.iter().map(String::as_str).zip(motions.iter()).collect();
    let (scene, notes) = scene_from_motions_with(&takes, overrides).map_err(crate::CameraError::Request)?;
    Ok((scene, notes, names.join(" + ")))
}

/// [`scene_from_motions`] with joints named in a roles file (`roles`), for rigs whose names and
/// shape leave a role open.
pub fn scene_from_motions_with(
    takes: &[(&str, &Motion)],
    overrides: &RoleOverrides,
) -> Result<(Scene, SceneNotes), String> {
    scene_from_motions_in_units(takes, &[], overrides)
}

/// [`scene_from_motions_with`] with the takes' length units where the caller knows them (`units[i]`
/// for take `i`, e.g. a clip made from arrays in cm; missing or `None`: inferred from the skeleton,
/// as for a file). A clip's rest pose need not be a standing one, so inferring is a guess there.
pub fn scene_from_motions_in_units(
    takes: &[(&str, &Motion)],
    units: &[Option<LengthUnit>],
    overrides: &RoleOverrides,
) -> Result<(Scene, SceneNotes), String> {
    if takes.len() < 2 {
        return Err(format!("a camera scene needs two characters, got {}", takes.len()));
    }
    let fps = takes[0].1.fps();
    let duration =
        takes.iter().map(|(_, m)| (m.num_frames().saturating_sub(1)) as f64 / m.fps()).fold(f64::INFINITY, f64::min);
    let frames = (duration * fps).floor() as usize + 1;
    if frames < 2 {
        return Err(format!("the shortest take lasts {duration:.3} s: a scene needs at least 2 frames"));
    }
    let mut notes = SceneNotes::default();
    let mut characters = Vec::new();
    for (i, (name, motion)) in takes.iter().enumerate() {
        let roles = find_motion_roles(motion, overrides).map_err(|e| format!("{name}: {e}"))?;
        let (hips, l, r) = (
            roles.joint(Role::Hips),
            roles.joint(Role::UpperArm(Side::Left)),
            roles.joint(Role::UpperArm(Side::Right)),
        );
        let how = roles.how(Role::UpperArm(Side::Left)).map(|h| h.to_string()).unwrap_or_default();
        let unit = UnitChoice::resolve(units.get(i).copied().flatten(), &motion.skeleton);
        let m = unit.cm_per_unit() / 100.0;
        let pos = positions_clip(motion);
        let at = |f: usize, j: usize| pos[f][j] * m;
        // Position of joint `j` at scene frame `f`: linear between the take's frames around that time.
        let sample = |f: usize, j: usize| -> DVec3 {
            let x = f as f64 / fps * motion.fps();
            let (i0, w) = (x.floor() as usize, x - x.floor());
            let i0 = i0.min(motion.num_frames() - 1);
            let i1 = (i0 + 1).min(motion.num_frames() - 1);
            at(i0, j).lerp(at(i1, j), w)
        };
        notes.lines.push(format!(
            "{name}: root {}, shoulders {} / {} (by {how}); {}",
            motion.skeleton.joint(hips).name,
            motion.skeleton.joint(l).name,
            motion.skeleton.joint(r).name,
            unit
        ));
        characters.push(CharacterPoints {
            name: name.to_string(),
            root: (0..frames).map(|f| sample(f, hips)).collect(),
            shoulder_l: (0..frames).map(|f| sample(f, l)).collect(),
            shoulder_r: (0..frames).map(|f| sample(f, r)).collect(),
        });
    }
    // Two takes recorded at the same spot would stand inside each other: the framing needs two
    // distinct targets, so the second steps aside (said in the notes).
    let mean_gap =
        (0..frames).map(|f| characters[0].frame(f).target().distance(characters[1].frame(f).target())).sum::<f64>()
            / frames as f64;
    if mean_gap < 0.5 {
        let shift = DVec3::new(1.5, 0.0, 0.0);
        let c = &mut characters[1];
        for v in c.root.iter_mut().chain(c.shoulder_l.iter_mut()).chain(c.shoulder_r.iter_mut()) {
            *v += shift;
        }
        notes.moved = Some((1, shift));
        notes.lines.push(format!(
            "the two takes stand {mean_gap:.2} m apart on average: {} moved 1.5 m along +X so that both can be framed",
            characters[1].name
        ));
    }
    if takes.iter().any(|(_, m)| (m.fps() - fps).abs() > 1e-6) {
        notes.lines.push(format!("takes resampled to {fps:.3} fps (the first take's rate)"));
    }
    let scene = Scene { fps, characters };
    scene.validate()?;
    Ok((scene, notes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn two_walks_make_a_valid_scene_with_shoulders_at_shoulder_height() {
        let a = gait(&GaitParams { frames: 60, ..GaitParams::walk() });
        let b = gait(&GaitParams { frames: 90, ..GaitParams::walk() });
        let (scene, notes) = scene_from_motions(&[("a.bvh", &a), ("b.bvh", &b)]).unwrap();
        assert_eq!(scene.characters.len(), 2);
        assert_eq!(scene.num_frames(), 60, "the shortest take");
        let f = scene.characters[0].frame(10);
        assert!(f.shoulder_l.y > f.root.y, "shoulders above the hips: {f:?}");
        assert!((f.shoulder_l - f.shoulder_r).length() > 0.1, "two distinct shoulders");
        // Same spot: the second character is moved aside, and the notes say so.
        assert!(notes.lines.iter().any(|l| l.contains("moved 1.5 m")), "{notes:?}");
        assert_eq!(notes.moved, Some((1, DVec3::new(1.5, 0.0, 0.0))));
        assert!(scene.characters[0].frame(0).target().distance(scene.characters[1].frame(0).target()) > 1.0);
    }

    #[test]
    fn a_unit_the_caller_knows_is_used_instead_of_inferring_one() {
        let a = gait(&GaitParams { frames: 30, ..GaitParams::walk() });
        let b = gait(&GaitParams { frames: 30, ..GaitParams::walk() });
        let takes = [("a.bvh", &a), ("b.bvh", &b)];
        let (inferred, _) = scene_from_motions(&takes).unwrap();
        let (given, notes) =
            scene_from_motions_in_units(&takes, &[Some(LengthUnit::Inch), None], &RoleOverrides::default()).unwrap();
        assert!(notes.lines[0].contains("given"), "{notes:?}");
        let (fa, ga) = (inferred.characters[0].frame(10), given.characters[0].frame(10));
        let k = LengthUnit::Inch.cm_per_unit() / LengthUnit::infer(&a.skeleton).cm_per_unit();
        assert!((ga.shoulder_l - fa.shoulder_l * k).length() < 1e-9, "{:?} vs {:?}", ga.shoulder_l, fa.shoulder_l);
        // B keeps its inferred unit (heights: the same-spot rule may move it along X only).
        assert_eq!(inferred.characters[1].frame(10).shoulder_l.y, given.characters[1].frame(10).shoulder_l.y);
    }

    #[test]
    fn a_take_that_is_no_humanoid_is_refused_naming_it_and_the_roles_file() {
        let chain = inbetween_core::roles::fixtures::chain();
        let frames = vec![0.0; 20 * chain.num_channels()];
        let a = Motion::new(chain, 1.0 / 30.0, frames).unwrap();
        let b = gait(&GaitParams { frames: 20, ..GaitParams::walk() });
        let err = scene_from_motions(&[("odd.bvh", &a), ("b.bvh", &b)]).unwrap_err();
        assert!(err.starts_with("odd.bvh: not a humanoid skeleton"), "{err}");
        assert!(err.contains("left_upper_arm") && err.contains("`roles`"), "{err}");
    }
}
