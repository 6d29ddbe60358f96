//! CMU mocap as template actions (§3.2 dataset preparation): the corpus index (`index.tsv`)
//! tagged from its descriptions, and cgspeed BVH clips retargeted onto the common skeleton
//! (§4.2 "rotate … skeletons to the standard T-pose").

use super::rig::{arc, local_from_global, Rig, FPS};
use super::verbs::tags_of_description;
use crate::ScriptError;
use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
use inbetween_core::roles::{correspondence, find_motion_roles, Role, RoleOverrides, Roles, Scheme, Side};
use inbetween_core::{Motion, Pose, Skeleton};
use std::path::Path;

/// One trial of the CMU index, with its action tags.
#[derive(Clone, Debug, PartialEq)]
pub struct CmuTrial {
    pub clip_id: String,
    pub subject: u32,
    pub trial: u32,
    pub description: String,
    pub framerate_hz: f64,
    /// Files of this trial present in the corpus (relative to the cmu folder).
    pub files: Vec<String>,
    /// Canonical action tags from the description ([`super::verbs`]).
    pub tags: Vec<String>,
}

impl CmuTrial {
    /// The trial's cgspeed BVH file, when the corpus holds one.
    /// The trial's BVH file to load: the cgspeed conversion when present, else the iClone/CC one.
    pub fn bvh(&self) -> Option<&str> {
        self.cgspeed_bvh().or_else(|| {
            self.files.iter().map(|s| s.as_str()).find(|f| f.starts_with("iclone_cc/") && f.ends_with(".bvh"))
        })
    }

    pub fn cgspeed_bvh(&self) -> Option<&str> {
        self.files.iter().map(|s| s.as_str()).find(|f| f.starts_with("cgspeed/") && f.ends_with(".bvh"))
    }
}

/// Reads and tags `index.tsv` (columns subject, trial, clip_id, description, framerate_hz,
/// in_this_corpus; `in_this_corpus` holds `;`-separated relative paths).
pub fn read_index(path: &Path) -> Result<Vec<CmuTrial>, ScriptError> {
    let text = std::fs::read_to_string(path).map_err(|e| ScriptError::io(path, e))?;
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if n == 0 || line.trim().is_empty() {
            continue;
        }
        let cols: Vec<&str> = line.split('\t').collect();
        if cols.len() < 5 {
            return Err(ScriptError::Asset {
                path: path.into(),
                message: format!("line {}: expected 6 tab-separated columns", n + 1),
            });
        }
        let bad = |what: &str| ScriptError::Asset { path: path.into(), message: format!("line {}: bad {what}", n + 1) };
        let files = cols
            .get(5)
            .map(|c| {
                c.split(';').map(|f| f.trim()).filter(|f| !f.is_empty() && !f.contains(' ')).map(String::from).collect()
            })
            .unwrap_or_default();
        out.push(CmuTrial {
            subject: cols[0].trim().parse().map_err(|_| bad("subject"))?,
            trial: cols[1].trim().parse().map_err(|_| bad("trial"))?,
            clip_id: cols[2].trim().to_string(),
            description: cols[3].trim().to_string(),
            framerate_hz: cols[4].trim().parse().unwrap_or(120.0),
            tags: tags_of_description(cols[3]),
            files,
        });
    }
    Ok(out)
}

/// Rest direction of the bone a joint drives: its only child's offset (skipping zero-length
/// links) or its end site; None for branching joints.
fn bone_dir(s: &Skeleton, j: usize) -> Option<DVec3> {
    let mut cur = j;
    loop {
        let kids: Vec<usize> = s.children(cur).collect();
        match kids.as_slice() {
            [] => return s.joint(cur).end_site.filter(|e| e.length() > 1e-6),
            [k] => {
                let off = s.joint(*k).offset;
                if off.length() > 1e-6 {
                    return Some(off);
                }
                cur = *k;
            }
            _ => return None,
        }
    }
}

/// Thigh-to-knee plus knee-to-ankle length of the left leg (the shin's and foot's offsets).
fn leg_length(s: &Skeleton, roles: &Roles) -> f64 {
    let (shin, foot) = (roles.joint(Role::Shin(Side::Left)), roles.joint(Role::Foot(Side::Left)));
    s.joint(shin).offset.length() + s.joint(foot).offset.length()
}

/// Retargets a clip of any humanoid rig onto the common skeleton: joints matched by their roles
/// ([`correspondence`]: roles, spine and neck chains, hip links and the longest finger chain, else
/// names; the cgspeed layouts of both CMU releases map joint for joint); per joint, the global
/// rotation is the source's times the rest-pose correction that maps the target bone onto the
/// source bone; the root path is scaled by the leg-length ratio (which also converts units to
/// metres), resampled to 30 fps, grounded (feet on y = 0) and normalised to start at the origin
/// facing +Z.
pub fn retarget(src: &Motion, rig: &Rig) -> Result<Clip, String> {
    let s = &src.skeleton;
    let t = &rig.skeleton;
    let roles = find_motion_roles(src, &RoleOverrides::default()).map_err(|e| e.to_string())?;
    if roles.spine.is_empty() {
        return Err("no spine joint between the hips and the arms".into());
    }
    let map = correspondence((t, &rig.roles), (s, &roles), true);
    let scale = leg_length(t, &rig.roles) / leg_length(s, &roles).max(1e-9);
    let corr: Vec<DQuat> = (0..t.len())
        .map(|j| match (map[j], bone_dir(t, j)) {
            (Some(sj), Some(dt)) => bone_dir(s, sj).map(|ds| arc(dt, ds)).unwrap_or(DQuat::IDENTITY),
            _ => DQuat::IDENTITY,
        })
        .collect();
    let src = if (src.fps() - FPS).abs() > 1e-6 { src.resample(FPS).map_err(|e| e.to_string())? } else { src.clone() };
    let mut poses: Vec<Pose> = Vec::with_capacity(src.num_frames());
    for f in 0..src.num_frames() {
        let g = forward(s, &src.pose(f));
        let mut gt = vec![DQuat::IDENTITY; t.len()];
        let mut pose = Pose::rest(t);
        for j in 0..t.len() {
            let parent = t.parent(j).map(|p| gt[p]).unwrap_or(DQuat::IDENTITY);
            gt[j] = match map[j] {
                Some(sj) => (g.rotations[sj] * corr[j]).normalize(),
                None => parent,
            };
            pose.rotations[j] = local_from_global(parent, gt[j]);
        }
        pose.translations[rig.hips] = g.positions[map[rig.hips].expect("hips")] * scale;
        poses.push(pose);
    }
    super::grounding::grounded(rig, t, poses)
}

/// Reads a CMU BVH and retargets it: Character Creator (iClone) rigs with
/// [`super::cc::retarget_cc`] (its first frame, a T-pose, dropped), any other with [`retarget`].
pub fn load_bvh(path: &Path, rig: &Rig) -> Result<Clip, ScriptError> {
    let m =
        inbetween_io::read_bvh(path).map_err(|e| ScriptError::Asset { path: path.into(), message: e.to_string() })?;
    let scheme = find_motion_roles(&m, &RoleOverrides::default()).ok().and_then(|r| r.scheme);
    let result = if scheme == Some(Scheme::CharacterCreator) {
        super::cc::retarget_cc(&m, rig, false, true)
    } else {
        retarget(&m, rig)
    };
    result.map_err(|message| ScriptError::Asset { path: path.into(), message })
}
