//! Procedural motion: a CMU-style 31-joint skeleton and parametric gaits, so demos and tests run
//! without any captured data.
//!
//! Units follow CMU mocap (1 unit = 5.6444 cm), Y is up and the character faces +Z in its rest pose,
//! with arms hanging down. Joint names match the cgspeed BVH conversion, so the same joint filters
//! (drop fingers, thumbs and toes → 23 joints) apply to real and synthetic clips.

use crate::motion::{Motion, Pose};
use crate::rotation::EulerOrder;
use crate::skeleton::{Channel, Joint, Skeleton};
use glam::{DQuat, DVec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};

/// Centimetres per CMU length unit.
pub const CM_PER_CMU_UNIT: f64 = 5.6444;

/// The 31-joint cgspeed layout with plausible adult proportions.
pub fn standard_skeleton() -> Skeleton {
    let rot = Channel::rotations(EulerOrder::Zyx).to_vec();
    let mut root_ch = Channel::POSITION_XYZ.to_vec();
    root_ch.extend(Channel::rotations(EulerOrder::Zyx));
    let mut joints: Vec<Joint> = Vec::new();
    let add = |name: &str, parent: Option<&str>, offset: [f64; 3], end: Option<[f64; 3]>, joints: &mut Vec<Joint>| {
        let parent = parent.map(|p| joints.iter().position(|j| j.name == p).expect("parent defined first"));
        joints.push(Joint {
            name: name.to_string(),
            parent,
            offset: DVec3::from(offset),
            channels: if parent.is_none() { root_ch.clone() } else { rot.clone() },
            end_site: end.map(DVec3::from),
        });
    };
    add("Hips", None, [0.0, 0.0, 0.0], None, &mut joints);
    for (side, s, short) in [("Left", 1.0, "L"), ("Right", -1.0, "R")] {
        add(&format!("{short}HipJoint"), Some("Hips"), [0.0, 0.0, 0.0], None, &mut joints);
        add(&format!("{side}UpLeg"), Some(&format!("{short}HipJoint")), [1.7 * s, -1.0, 0.0], None, &mut joints);
        add(&format!("{side}Leg"), Some(&format!("{side}UpLeg")), [0.0, -7.4, 0.0], None, &mut joints);
        add(&format!("{side}Foot"), Some(&format!("{side}Leg")), [0.0, -7.3, 0.0], None, &mut joints);
        add(
            &format!("{side}ToeBase"),
            Some(&format!("{side}Foot")),
            [0.0, -0.9, 2.0],
            Some([0.0, 0.0, 1.0]),
            &mut joints,
        );
    }
    add("LowerBack", Some("Hips"), [0.0, 0.3, 0.0], None, &mut joints);
    add("Spine", Some("LowerBack"), [0.0, 2.0, 0.0], None, &mut joints);
    add("Spine1", Some("Spine"), [0.0, 2.0, 0.0], None, &mut joints);
    add("Neck", Some("Spine1"), [0.0, 2.0, 0.0], None, &mut joints);
    add("Neck1", Some("Neck"), [0.0, 1.0, 0.0], None, &mut joints);
    add("Head", Some("Neck1"), [0.0, 1.0, 0.0], Some([0.0, 1.8, 0.0]), &mut joints);
    for (side, s, short) in [("Left", 1.0, "L"), ("Right", -1.0, "R")] {
        add(&format!("{side}Shoulder"), Some("Spine1"), [0.5 * s, 1.6, 0.0], None, &mut joints);
        add(&format!("{side}Arm"), Some(&format!("{side}Shoulder")), [2.5 * s, 0.0, 0.0], None, &mut joints);
        add(&format!("{side}ForeArm"), Some(&format!("{side}Arm")), [0.0, -5.2, 0.0], None, &mut joints);
        add(&format!("{side}Hand"), Some(&format!("{side}ForeArm")), [0.0, -4.6, 0.0], None, &mut joints);
        add(&format!("{side}FingerBase"), Some(&format!("{side}Hand")), [0.0, -0.7, 0.0], None, &mut joints);
        add(
            &format!("{side}HandIndex1"),
            Some(&format!("{side}FingerBase")),
            [0.0, -0.6, 0.0],
            Some([0.0, -0.4, 0.0]),
            &mut joints,
        );
        add(
            &format!("{short}Thumb"),
            Some(&format!("{side}Hand")),
            [0.3 * s, -0.4, 0.3],
            Some([0.0, -0.5, 0.3]),
            &mut joints,
        );
    }
    Skeleton::new(joints).expect("the standard skeleton is valid")
}

/// Height of the hips above the ground in the rest pose (CMU units).
pub fn standard_hip_height() -> f64 {
    1.0 + 7.4 + 7.3 + 0.9
}

/// Parameters of a cyclic gait. Angles in radians, lengths in CMU units, times in seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitParams {
    pub frames: usize,
    pub fps: f64,
    /// Forward speed.
    pub speed: f64,
    /// Full gait cycles (two steps) per second.
    pub cycle_hz: f64,
    pub hip_swing: f64,
    pub knee_bend: f64,
    pub arm_swing: f64,
    pub elbow_bend: f64,
    /// Vertical bob amplitude of the pelvis.
    pub bob: f64,
    /// Heading change rate (rad/s); non-zero walks a circle.
    pub turn_rate: f64,
    /// Forward lean of the torso.
    pub lean: f64,
    pub phase: f64,
}

impl GaitParams {
    /// A relaxed walk: about 1.3 m/s.
    pub fn walk() -> GaitParams {
        GaitParams {
            frames: 120,
            fps: 30.0,
            speed: 23.0,
            cycle_hz: 0.9,
            hip_swing: 0.45,
            knee_bend: 0.9,
            arm_swing: 0.35,
            elbow_bend: 0.25,
            bob: 0.35,
            turn_rate: 0.0,
            lean: 0.05,
            phase: 0.0,
        }
    }

    /// A jog: faster, longer strides, stronger knee and elbow bend, forward lean.
    pub fn run() -> GaitParams {
        GaitParams {
            speed: 55.0,
            cycle_hz: 1.4,
            hip_swing: 0.7,
            knee_bend: 1.6,
            arm_swing: 0.6,
            elbow_bend: 1.4,
            bob: 0.7,
            lean: 0.2,
            ..GaitParams::walk()
        }
    }

    /// Varies every amplitude by up to ±`amount` (relative), the phase and the turn rate, from `seed`.
    pub fn jittered(&self, seed: u64, amount: f64) -> GaitParams {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut j = |v: f64| v * (1.0 + rng.random_range(-amount..=amount));
        let mut p = GaitParams {
            speed: j(self.speed),
            cycle_hz: j(self.cycle_hz),
            hip_swing: j(self.hip_swing),
            knee_bend: j(self.knee_bend),
            arm_swing: j(self.arm_swing),
            elbow_bend: j(self.elbow_bend),
            bob: j(self.bob),
            lean: j(self.lean),
            ..self.clone()
        };
        let mut rng = crate::seed::rng(seed ^ 0x9e37_79b9_7f4a_7c15);
        p.phase = rng.random_range(0.0..TAU);
        p.turn_rate = self.turn_rate + rng.random_range(-0.4..=0.4) * amount;
        p
    }
}

/// A smooth 0…1 pulse that peaks once per cycle at phase `center`.
fn pulse(phase: f64, center: f64, sharpness: f64) -> f64 {
    let c = (phase - center).cos();
    ((c + 1.0) * 0.5).powf(sharpness)
}

/// Generates a gait clip on [`standard_skeleton`].
pub fn gait(params: &GaitParams) -> Motion {
    let skeleton = standard_skeleton();
    let idx = |n: &str| skeleton.find(n).expect("standard joint");
    let (hips, lowback, spine1, neck) = (idx("Hips"), idx("LowerBack"), idx("Spine1"), idx("Neck"));
    let legs = [
        (idx("LeftUpLeg"), idx("LeftLeg"), idx("LeftFoot"), 0.0),
        (idx("RightUpLeg"), idx("RightLeg"), idx("RightFoot"), PI),
    ];
    let arms = [(idx("LeftArm"), idx("LeftForeArm"), PI), (idx("RightArm"), idx("RightForeArm"), 0.0)];
    let mut heading = 0.0f64;
    let mut root = DVec3::new(0.0, standard_hip_height(), 0.0);
    let dt = 1.0 / params.fps;
    let poses: Vec<Pose> = (0..params.frames)
        .map(|f| {
            let t = f as f64 * dt;
            let phase = TAU * params.cycle_hz * t + params.phase;
            let mut pose = Pose::rest(&skeleton);
            let yaw = DQuat::from_rotation_y(heading);
            root.y = standard_hip_height() - params.bob * 0.5 + params.bob * 0.5 * (2.0 * phase).cos();
            pose.translations[hips] = root + yaw * DVec3::new(0.15 * phase.sin(), 0.0, 0.0);
            pose.rotations[hips] =
                yaw * DQuat::from_rotation_y(0.12 * phase.sin()) * DQuat::from_rotation_z(0.04 * phase.cos());
            for &(up, knee, foot, offset) in &legs {
                let p = phase + offset;
                // Negative X rotation swings a leg forward (+Z).
                pose.rotations[up] = DQuat::from_rotation_x(-params.hip_swing * p.sin());
                let bend = params.knee_bend * (0.15 + 0.85 * pulse(p, 0.5 * PI + 0.9, 2.0));
                pose.rotations[knee] = DQuat::from_rotation_x(bend);
                pose.rotations[foot] = DQuat::from_rotation_x(-0.25 * (p + 0.6).sin() - 0.1 * bend);
            }
            for &(arm, fore, offset) in &arms {
                let p = phase + offset;
                pose.rotations[arm] = DQuat::from_rotation_x(-params.arm_swing * p.sin());
                pose.rotations[fore] = DQuat::from_rotation_x(-params.elbow_bend * (0.8 + 0.2 * (p + 0.5).sin()));
            }
            pose.rotations[lowback] = DQuat::from_rotation_x(params.lean);
            pose.rotations[spine1] = DQuat::from_rotation_y(-0.15 * phase.sin());
            pose.rotations[neck] =
                DQuat::from_rotation_x(-0.5 * params.lean) * DQuat::from_rotation_y(0.08 * phase.sin());
            heading += params.turn_rate * dt;
            root += DQuat::from_rotation_y(heading) * DVec3::new(0.0, 0.0, params.speed * dt);
            pose
        })
        .collect();
    Motion::from_poses(skeleton, dt, &poses).expect("gait poses fit the standard skeleton")
}

/// A seeded, varied set of walks and runs (some turning) for tests, demos and training on data we
/// generate ourselves.
pub fn gait_library(seed: u64, count: usize, frames: usize, fps: f64) -> Vec<Motion> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let base = if rng.random_bool(0.6) { GaitParams::walk() } else { GaitParams::run() };
            let mut p = base.jittered(rng.random(), 0.3);
            p.frames = frames;
            p.fps = fps;
            if rng.random_bool(0.3) {
                p.turn_rate += rng.random_range(-1.0..1.0);
            }
            gait(&p)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fk::forward;

    #[test]
    fn standard_skeleton_has_31_joints_and_23_without_extremities() {
        let s = standard_skeleton();
        assert_eq!(s.len(), 31);
        assert_eq!(s.num_channels(), 96);
        let drop = ["FingerBase", "HandIndex", "Thumb", "ToeBase"];
        let (f, _) = s.filter(|_, j| !drop.iter().any(|d| j.name.contains(d)));
        assert_eq!(f.len(), 23);
    }

    #[test]
    fn rest_pose_stands_on_the_ground() {
        let s = standard_skeleton();
        let mut pose = Pose::rest(&s);
        pose.translations[0] = DVec3::new(0.0, standard_hip_height(), 0.0);
        let g = forward(&s, &pose);
        let foot = g.positions[s.find("LeftFoot").unwrap()];
        assert!(foot.y > 0.0 && foot.y < 1.5, "{foot:?}");
        let head = g.end_site(&s, s.find("Head").unwrap()).unwrap();
        assert!(head.y * CM_PER_CMU_UNIT > 150.0 && head.y * CM_PER_CMU_UNIT < 200.0);
    }

    #[test]
    fn walk_moves_forward_and_is_deterministic() {
        let m = gait(&GaitParams::walk());
        assert_eq!(m.num_frames(), 120);
        let p0 = m.pose(0).translations[0];
        let p1 = m.pose(119).translations[0];
        let dist = (p1 - p0).length();
        let expected = GaitParams::walk().speed * 119.0 / 30.0;
        assert!((dist - expected).abs() < 0.05 * expected, "{dist} vs {expected}");
        assert_eq!(gait_library(7, 3, 40, 30.0), gait_library(7, 3, 40, 30.0));
        assert_ne!(gait_library(7, 3, 40, 30.0), gait_library(8, 3, 40, 30.0));
    }

    #[test]
    fn legs_alternate() {
        let m = gait(&GaitParams::walk());
        let s = &m.skeleton;
        let (l, r) = (s.find("LeftFoot").unwrap(), s.find("RightFoot").unwrap());
        let g = forward(s, &m.pose(8));
        let root = g.positions[0];
        // A quarter cycle in, one foot is ahead of the pelvis and the other behind.
        assert!((g.positions[l].z - root.z) * (g.positions[r].z - root.z) < 0.0);
    }
}
