//! The last step the retargeters share ([`super::cmu::retarget`] for cgspeed BVH,
//! [`super::cc::retarget_cc`] for Character Creator BVH): retargeted poses made into a clip on
//! the common rig, on the floor, starting at the origin facing +Z.

use super::rig::{heading_of, yaw, Rig, FPS};
use glam::DVec3;
use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
use inbetween_core::{Pose, Skeleton};

/// Retargeted poses made into a clip that starts at the origin facing +Z, with its lowest foot
/// points (5th percentile, so a stumble does not lift the floor) at y = 0.
pub(crate) fn grounded(rig: &Rig, t: &Skeleton, mut poses: Vec<Pose>) -> Result<Clip, String> {
    if poses.is_empty() {
        return Err("no frames".into());
    }
    let mut lows: Vec<f64> = poses
        .iter()
        .map(|p| {
            let g = forward(t, p);
            rig.legs
                .iter()
                .flat_map(|l| [g.positions[l[3]].y, g.positions[l[2]].y - rig.ankle_height])
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    lows.sort_by(f64::total_cmp);
    let ground = lows[lows.len() / 20];
    let r0 = poses[0].rotations[rig.hips];
    let turn = yaw(-heading_of(r0));
    let start = poses[0].translations[rig.hips];
    for p in &mut poses {
        let d = p.translations[rig.hips] - DVec3::new(start.x, ground, start.z);
        p.translations[rig.hips] = turn * d;
        p.rotations[rig.hips] = (turn * p.rotations[rig.hips]).normalize();
    }
    Clip::from_poses(t.clone(), 1.0 / FPS, &poses).map_err(|e| e.to_string())
}
