//! The common skeleton every clip is retargeted to (§4.2: "a standard T-pose" space shared by
//! locomotion and actions): core's 31-joint CMU-style skeleton scaled to metres, Y up, floor at
//! y = 0, facing +Z in its rest pose.

use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::fk::{forward, GlobalPose};
use inbetween_core::procedural::{standard_hip_height, standard_skeleton, CM_PER_CMU_UNIT};
use inbetween_core::roles::{find_roles, Role, RoleOverrides, Roles, Side};
use inbetween_core::units::scale_motion;
use inbetween_core::{Motion, Pose, Skeleton};

/// Metres per CMU length unit.
pub const M_PER_CMU: f64 = CM_PER_CMU_UNIT / 100.0;

/// Frame rate of every library clip and of generated motion.
pub const FPS: f64 = 30.0;

/// The standard skeleton in metres.
pub fn skeleton() -> Skeleton {
    let empty = Motion::new(standard_skeleton(), 1.0 / FPS, Vec::new()).expect("empty clip");
    scale_motion(&empty, M_PER_CMU).skeleton
}

/// Height of the `Hips` joint above the floor in the rest pose, metres.
pub fn hip_height() -> f64 {
    standard_hip_height() * M_PER_CMU
}

/// Joint indices of the standard skeleton that the motion code uses.
#[derive(Clone, Debug)]
pub struct Rig {
    pub skeleton: Skeleton,
    pub hips: usize,
    pub lower_back: usize,
    pub spine1: usize,
    pub neck: usize,
    pub head: usize,
    /// `[UpLeg, Leg, Foot, ToeBase]`, left then right.
    pub legs: [[usize; 4]; 2],
    /// `[Shoulder, Arm, ForeArm, Hand]`, left then right.
    pub arms: [[usize; 4]; 2],
    /// Rest height of the ankle (`Foot` joint) above the floor, metres.
    pub ankle_height: f64,
    /// The skeleton's joint roles ([`inbetween_core::roles`]), where the indices above come from.
    pub roles: Roles,
}

impl Rig {
    pub fn standard() -> Rig {
        Rig::of(skeleton())
    }

    /// Indices on the standard skeleton or another humanoid (panics on a skeleton without roles:
    /// use [`Rig::try_of`] for skeletons that did not come from this module).
    pub fn of(skeleton: Skeleton) -> Rig {
        Rig::try_of(skeleton).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The rig of a clip's skeleton for `what` (a helper's task, for the message), or an error
    /// naming the joint missing.
    pub fn for_clip(c: &Clip, what: &str) -> Result<Rig, crate::error::ScriptError> {
        Rig::try_of(c.skeleton().clone())
            .map_err(|e| crate::error::ScriptError::Invalid(format!("{what} needs the common rig's joints: {e}")))
    }

    /// Indices on a humanoid skeleton (its roles by name or shape, [`inbetween_core::roles`]), or
    /// which role is missing.
    pub fn try_of(skeleton: Skeleton) -> Result<Rig, String> {
        let roles = find_roles(&skeleton, &RoleOverrides::default()).map_err(|e| format!("not the common rig: {e}"))?;
        let f = |r: Role| {
            roles.get(r).ok_or_else(|| {
                format!("not the common rig: no {} joint (the skeleton has {} joints)", r.key(), skeleton.len())
            })
        };
        let limb = |r: [Role; 4]| -> Result<[usize; 4], String> { Ok([f(r[0])?, f(r[1])?, f(r[2])?, f(r[3])?]) };
        let leg = |s: Side| limb([Role::Thigh(s), Role::Shin(s), Role::Foot(s), Role::Toe(s)]);
        let arm = |s: Side| limb([Role::Clavicle(s), Role::UpperArm(s), Role::Forearm(s), Role::Hand(s)]);
        let legs = [leg(Side::Left)?, leg(Side::Right)?];
        let arms = [arm(Side::Left)?, arm(Side::Right)?];
        let (hips, lower_back, spine1, neck, head) =
            (f(Role::Hips)?, f(Role::Spine)?, f(Role::Chest)?, f(Role::Neck)?, f(Role::Head)?);
        let mut rest = Pose::rest(&skeleton);
        rest.translations[hips] = DVec3::new(0.0, hip_height(), 0.0);
        let g = forward(&skeleton, &rest);
        let ankle_height = g.positions[legs[0][2]].y;
        Ok(Rig { hips, lower_back, spine1, neck, head, legs, arms, ankle_height, skeleton, roles })
    }

    /// The end of the hand's longest finger chain (`LeftHandIndex1`), or the hand itself.
    pub fn fingertip(&self, side: Side) -> usize {
        let hand = self.arms[usize::from(side == Side::Right)][3];
        self.roles.fingertip(&self.skeleton, side).unwrap_or(hand)
    }

    /// True for the joints of the upper body: `LowerBack` and everything below it (§4.2, "joints
    /// above the hip").
    pub fn upper_body_mask(&self) -> Vec<bool> {
        let mut m = vec![false; self.skeleton.len()];
        m[self.lower_back] = true;
        for j in 0..self.skeleton.len() {
            if let Some(p) = self.skeleton.parent(j) {
                if m[p] {
                    m[j] = true;
                }
            }
        }
        m
    }

    /// Rest pose standing at the origin, feet on the floor.
    pub fn standing(&self) -> Pose {
        let mut p = Pose::rest(&self.skeleton);
        p.translations[self.hips] = DVec3::new(0.0, hip_height(), 0.0);
        p
    }

    pub fn fk(&self, pose: &Pose) -> GlobalPose {
        forward(&self.skeleton, pose)
    }
}

/// Heading (yaw about +Y, 0 = facing +Z) of a root rotation: its forward axis projected on the floor.
pub fn heading_of(q: DQuat) -> f64 {
    let f = q * DVec3::Z;
    f.x.atan2(f.z)
}

/// Yaw rotation about +Y.
pub fn yaw(angle: f64) -> DQuat {
    DQuat::from_rotation_y(angle)
}

/// The minimal rotation taking direction `from` to direction `to` (both non-zero).
pub fn arc(from: DVec3, to: DVec3) -> DQuat {
    let (a, b) = (from.normalize_or_zero(), to.normalize_or_zero());
    if a == DVec3::ZERO || b == DVec3::ZERO {
        return DQuat::IDENTITY;
    }
    DQuat::from_rotation_arc(a, b)
}

/// Wraps an angle to (-π, π].
pub fn wrap(a: f64) -> f64 {
    inbetween_core::angle::wrap_angle(a)
}

/// Local rotation of joint `j` that gives it the global rotation `global`, under `parent_global`.
pub fn local_from_global(parent_global: DQuat, global: DQuat) -> DQuat {
    (parent_global.inverse() * global).normalize()
}

/// Clip from poses on the rig's skeleton at [`FPS`] (at least one; unit rotations).
pub fn clip(rig: &Rig, poses: &[Pose]) -> Clip {
    Clip::from_poses(rig.skeleton.clone(), 1.0 / FPS, poses).expect("poses fit the standard skeleton")
}
