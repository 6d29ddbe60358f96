//! CMU trials converted for iClone / Character Creator (`iclone_cc/*.bvh`: CC_Base_* joints
//! modelled Z up under a root rotation that makes the world Y up, centimetres, a T-pose
//! prepended) retargeted onto the common skeleton (§4.2: both
//! skeletons brought to a shared rest frame). Each mapped joint's global rotation is the
//! source's times a rest-frame correction that maps the target bone (towards its mapped child;
//! for branching joints a frame of up and left-right directions) onto the source bone.

use super::rig::{local_from_global, Rig, FPS};
use glam::{DMat3, DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
use inbetween_core::roles::{correspondence, find_motion_roles, RoleOverrides};
use inbetween_core::{Motion, Pose, Skeleton};

/// Rest-pose global positions (identity rotations).
fn rest_positions(s: &Skeleton) -> Vec<DVec3> {
    let mut p: Vec<DVec3> = Vec::with_capacity(s.len());
    for j in s.joints() {
        p.push(j.parent.map(|q| p[q] + j.offset).unwrap_or(DVec3::ZERO));
    }
    p
}

/// Orthonormal frame with first axis along `a` and second in the plane of `a` and `b`.
fn frame(a: DVec3, b: DVec3) -> Option<DMat3> {
    let x = a.try_normalize()?;
    let y = (b - x * b.dot(x)).try_normalize()?;
    Some(DMat3::from_cols(x, y, x.cross(y)))
}

/// Retargets a Character Creator clip; `up_z` converts a source whose world is Z up (the
/// `iclone_cc` files are Y up after their root rotation: pass false). Drops the prepended
/// T-pose frame when `drop_first`.
pub fn retarget_cc(src: &Motion, rig: &Rig, up_z: bool, drop_first: bool) -> Result<Clip, String> {
    let s = &src.skeleton;
    let t = &rig.skeleton;
    // Roles, spine and neck chains; fingers and hip links are left to follow their parents.
    let roles = find_motion_roles(src, &RoleOverrides::default()).map_err(|e| e.to_string())?;
    let map = correspondence((t, &rig.roles), (s, &roles), false);
    for (role, a) in &rig.roles.roles {
        if map[a.joint].is_none() {
            return Err(format!("no joint plays the {role} of the common rig's {}", a.name));
        }
    }
    let (rt, rs) = (rest_positions(t), rest_positions(s));
    let src_of = |j: usize| map[j].expect("mapped");
    // Correction per target joint: maps target rest directions onto source rest directions.
    let mut corr = vec![DQuat::IDENTITY; t.len()];
    for j in 0..t.len() {
        if map[j].is_none() {
            continue;
        }
        let kids: Vec<usize> = t.children(j).filter(|&c| map[c].is_some()).collect();
        let dir = |c: usize| (rt[c] - rt[j], rs[src_of(c)] - rs[src_of(j)]);
        corr[j] = match kids.as_slice() {
            [c] => {
                let (dt, ds) = dir(*c);
                if dt.length() > 1e-9 && ds.length() > 1e-9 {
                    DQuat::from_rotation_arc(dt.normalize(), ds.normalize())
                } else {
                    t.parent(j).map(|p| corr[p]).unwrap_or(DQuat::IDENTITY)
                }
            }
            [] => t.parent(j).map(|p| corr[p]).unwrap_or(DQuat::IDENTITY),
            many => {
                // Up: the highest child (spine or neck); across: leftmost minus rightmost child.
                let up = *many.iter().max_by(|&&a, &&b| rt[a].y.total_cmp(&rt[b].y)).expect("children");
                let l = *many.iter().max_by(|&&a, &&b| rt[a].x.total_cmp(&rt[b].x)).expect("children");
                let r = *many.iter().min_by(|&&a, &&b| rt[a].x.total_cmp(&rt[b].x)).expect("children");
                let (ut, us) = dir(up);
                let (at, as_) = (rt[l] - rt[r], rs[src_of(l)] - rs[src_of(r)]);
                match (frame(ut, at), frame(us, as_)) {
                    (Some(ft), Some(fs)) => DQuat::from_mat3(&(fs * ft.transpose())).normalize(),
                    _ => DQuat::IDENTITY,
                }
            }
        };
    }
    let convert = if up_z { DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2) } else { DQuat::IDENTITY };
    let leg = |p: &[DVec3], a: usize, b: usize, c: usize| (p[b] - p[a]).length() + (p[c] - p[b]).length();
    let [ul, kn, an] = [rig.legs[0][0], rig.legs[0][1], rig.legs[0][2]];
    let scale = leg(&rt, ul, kn, an) / leg(&rs, src_of(ul), src_of(kn), src_of(an)).max(1e-9);
    let src = if (src.fps() - FPS).abs() > 1e-6 { src.resample(FPS).map_err(|e| e.to_string())? } else { src.clone() };
    let first = usize::from(drop_first && src.num_frames() > 1);
    let mut poses: Vec<Pose> = Vec::new();
    for f in first..src.num_frames() {
        let g = forward(s, &src.pose(f));
        let mut gt = vec![DQuat::IDENTITY; t.len()];
        let mut pose = Pose::rest(t);
        for j in 0..t.len() {
            let parent = t.parent(j).map(|p| gt[p]).unwrap_or(DQuat::IDENTITY);
            gt[j] = match map[j] {
                Some(sj) => (convert * g.rotations[sj] * corr[j]).normalize(),
                None => parent,
            };
            pose.rotations[j] = local_from_global(parent, gt[j]);
        }
        pose.translations[rig.hips] = convert * g.positions[src_of(rig.hips)] * scale;
        poses.push(pose);
    }
    super::grounding::grounded(rig, t, poses)
}
