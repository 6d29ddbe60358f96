//! Forward kinematics: global joint positions and rotations from local poses.

use crate::motion::{Motion, Pose};
use crate::skeleton::Skeleton;
use glam::{DQuat, DVec3};
use rayon::prelude::*;

/// Global transforms of every joint for one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct GlobalPose {
    pub positions: Vec<DVec3>,
    pub rotations: Vec<DQuat>,
}

impl GlobalPose {
    /// Position of joint `j`'s end site, if it has one.
    pub fn end_site(&self, skeleton: &Skeleton, j: usize) -> Option<DVec3> {
        skeleton.joint(j).end_site.map(|e| self.positions[j] + self.rotations[j] * e)
    }
}

/// Global transforms of one pose: `R_j = R_parent · r_j`, `p_j = p_parent + R_parent · t_j`.
pub fn forward(skeleton: &Skeleton, pose: &Pose) -> GlobalPose {
    let mut out =
        GlobalPose { positions: Vec::with_capacity(skeleton.len()), rotations: Vec::with_capacity(skeleton.len()) };
    forward_into(skeleton, pose, &mut out);
    out
}

/// [`forward`] into a global pose the caller owns (no allocation once it has the skeleton's size):
/// the playback loop's second step after [`crate::clip::Clip::sample_into`].
pub fn forward_into(skeleton: &Skeleton, pose: &Pose, out: &mut GlobalPose) {
    out.positions.clear();
    out.rotations.clear();
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let local_r = pose.rotations[j];
        let local_t = pose.translations[j];
        match joint.parent {
            None => {
                out.positions.push(local_t);
                out.rotations.push(local_r);
            }
            Some(p) => {
                let pr: DQuat = out.rotations[p];
                let position = out.positions[p] + pr * local_t;
                out.positions.push(position);
                out.rotations.push((pr * local_r).normalize());
            }
        }
    }
}

/// Global transforms of every frame of a clip, in parallel over frames.
pub fn forward_clip(motion: &Motion) -> Vec<GlobalPose> {
    (0..motion.num_frames()).into_par_iter().map(|f| forward(&motion.skeleton, &motion.pose(f))).collect()
}

/// Global positions only, frame-major `[frame][joint]`.
pub fn positions_clip(motion: &Motion) -> Vec<Vec<DVec3>> {
    forward_clip(motion).into_iter().map(|g| g.positions).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::EulerOrder;
    use crate::skeleton::{Channel, Joint};

    fn arm() -> Skeleton {
        let mut root_ch = Channel::POSITION_XYZ.to_vec();
        root_ch.extend(Channel::rotations(EulerOrder::Zyx));
        Skeleton::new(vec![
            Joint { name: "root".into(), parent: None, offset: DVec3::ZERO, channels: root_ch, end_site: None },
            Joint {
                name: "elbow".into(),
                parent: Some(0),
                offset: DVec3::new(1.0, 0.0, 0.0),
                channels: Channel::rotations(EulerOrder::Zyx).to_vec(),
                end_site: Some(DVec3::new(1.0, 0.0, 0.0)),
            },
        ])
        .unwrap()
    }

    #[test]
    fn rotating_the_root_swings_the_child() {
        let s = arm();
        // Root at (0, 5, 0), rotated 90° about Z; elbow rotated 90° about Z.
        let m = Motion::new(s.clone(), 1.0 / 30.0, vec![0.0, 5.0, 0.0, 90.0, 0.0, 0.0, 90.0, 0.0, 0.0]).unwrap();
        let g = forward(&s, &m.pose(0));
        assert!((g.positions[1] - DVec3::new(0.0, 6.0, 0.0)).length() < 1e-12);
        let tip = g.end_site(&s, 1).unwrap();
        assert!((tip - DVec3::new(-1.0, 6.0, 0.0)).length() < 1e-12);
        // Into a reused global pose: the same transforms.
        let mut reused = forward(&s, &m.pose(0));
        reused.positions[1] = DVec3::ZERO;
        forward_into(&s, &m.pose(0), &mut reused);
        assert_eq!(reused, g);
    }
}
