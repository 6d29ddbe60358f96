//! CMU mocap as template actions (§3.2 dataset preparation): the corpus index (`index.tsv`)
//! tagged from its descriptions, and cgspeed BVH clips retargeted onto the common skeleton
//! (§4.2 "rotate … skeletons to the standard T-pose").

use super::rig::{arc, local_from_global, Rig, FPS};
use super::verbs::tags_of_description;
use crate::ScriptError;
use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
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

/// Standard joint name of a cgspeed joint: the MotionBuilder-style files use the standard names
/// (fingers aside), the 3ds Max-friendly release (subjects 131–140) its own.
fn standard_name(name: &str, max_style: bool) -> String {
    let max_map: &[(&str, &str)] = &[
        ("LeftHip", "LeftUpLeg"),
        ("LeftKnee", "LeftLeg"),
        ("LeftAnkle", "LeftFoot"),
        ("LeftToe", "LeftToeBase"),
        ("RightHip", "RightUpLeg"),
        ("RightKnee", "RightLeg"),
        ("RightAnkle", "RightFoot"),
        ("RightToe", "RightToeBase"),
        ("lowerback", "LowerBack"),
        ("Chest", "Spine"),
        ("Chest2", "Spine1"),
        ("lowerneck", "Neck"),
        ("Neck", "Neck1"),
        ("LeftCollar", "LeftShoulder"),
        ("LeftShoulder", "LeftArm"),
        ("LeftElbow", "LeftForeArm"),
        ("LeftWrist", "LeftHand"),
        ("lhand", "LeftFingerBase"),
        ("RightCollar", "RightShoulder"),
        ("RightShoulder", "RightArm"),
        ("RightElbow", "RightForeArm"),
        ("RightWrist", "RightHand"),
        ("rhand", "RightFingerBase"),
    ];
    if max_style {
        if let Some((_, s)) = max_map.iter().find(|(m, _)| *m == name) {
            return s.to_string();
        }
    }
    match name {
        "LFingers" => "LeftHandIndex1".into(),
        "RFingers" => "RightHandIndex1".into(),
        n => n.to_string(),
    }
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

fn leg_length(s: &Skeleton, up: &str, leg: &str, foot: &str) -> Option<f64> {
    let (_, l, f) = (s.find(up)?, s.find(leg)?, s.find(foot)?);
    Some(s.joint(l).offset.length() + s.joint(f).offset.length())
}

/// Retargets a cgspeed-layout clip onto the common skeleton: per joint, the global rotation is the
/// source's times the rest-pose correction that maps the target bone onto the source bone; the
/// root path is scaled by the leg-length ratio (which also converts units to metres), resampled to
/// 30 fps, grounded (feet on y = 0) and normalised to start at the origin facing +Z.
pub fn retarget(src: &Motion, rig: &Rig) -> Result<Clip, String> {
    let s = &src.skeleton;
    let max_style = s.find("LeftCollar").is_some() || s.find("LeftHip").is_some();
    let names: Vec<String> = s.joints().iter().map(|j| standard_name(&j.name, max_style)).collect();
    let t = &rig.skeleton;
    let map: Vec<Option<usize>> = t.joints().iter().map(|j| names.iter().position(|n| *n == j.name)).collect();
    for need in ["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "RightFoot", "LowerBack", "LeftArm", "RightArm"] {
        if map[t.find(need).expect("standard joint")].is_none() {
            return Err(format!("no joint maps to {need}: not a CMU/cgspeed layout"));
        }
    }
    let src_leg = {
        let find = |std: &str| names.iter().position(|n| n == std).map(|i| s.joint(i).name.clone()).unwrap_or_default();
        leg_length(s, &find("LeftUpLeg"), &find("LeftLeg"), &find("LeftFoot")).ok_or("no left leg")?
    };
    let tgt_leg = leg_length(t, "LeftUpLeg", "LeftLeg", "LeftFoot").expect("standard leg");
    let scale = tgt_leg / src_leg.max(1e-9);
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

/// Reads a CMU BVH and retargets it: cgspeed layouts with [`retarget`], Character Creator
/// (iClone) layouts with [`super::cc::retarget_cc`] (its first frame, a T-pose, dropped).
pub fn load_bvh(path: &Path, rig: &Rig) -> Result<Clip, ScriptError> {
    let m =
        inbetween_io::read_bvh(path).map_err(|e| ScriptError::Asset { path: path.into(), message: e.to_string() })?;
    let result = if m.skeleton.find("CC_Base_Hip").is_some() {
        super::cc::retarget_cc(&m, rig, false, true)
    } else {
        retarget(&m, rig)
    };
    result.map_err(|message| ScriptError::Asset { path: path.into(), message })
}
