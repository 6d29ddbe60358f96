//! Analytic inverse kinematics (§4.2 "IK is used to ensure that the combined action conforms to
//! laws of kinematics", §4.3 contact points): two-bone limbs with a pole vector, and hips
//! placement for sitting.

use super::rig::{arc, hip_height, local_from_global, Rig};
use glam::{DQuat, DVec3};
use inbetween_core::fk::forward;
use inbetween_core::{Pose, Skeleton};

/// Positions of a solved two-bone chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoBone {
    /// New middle joint (knee, elbow).
    pub mid: DVec3,
    /// New end joint (ankle, wrist): the target, or the closest reachable point.
    pub end: DVec3,
    /// True when the target was out of reach (too far or too close) and was clamped.
    pub clamped: bool,
}

/// Solves a two-bone chain `root`–`mid`–`end` for `target`: bone lengths are kept, the root stays,
/// the middle joint bends towards `pole` (a point). Unreachable targets are clamped to the
/// reachable shell along the root→target direction.
pub fn two_bone(root: DVec3, mid: DVec3, end: DVec3, target: DVec3, pole: DVec3) -> TwoBone {
    let l1 = (mid - root).length();
    let l2 = (end - mid).length();
    let to = target - root;
    let mut d = to.length();
    let u = if d > 1e-12 { to / d } else { (end - root).normalize_or(DVec3::NEG_Y) };
    let (lo, hi) = ((l1 - l2).abs(), l1 + l2);
    let clamped = d > hi || d < lo;
    d = d.clamp(lo, hi);
    // Bend direction: the pole's component perpendicular to the root→target line.
    let mut n = (pole - root) - u * (pole - root).dot(u);
    if n.length_squared() < 1e-18 {
        n = (mid - root) - u * (mid - root).dot(u);
    }
    if n.length_squared() < 1e-18 {
        n = u.any_orthonormal_vector();
    }
    let n = n.normalize();
    let cos_a = if d > 1e-12 { ((l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d)).clamp(-1.0, 1.0) } else { 1.0 };
    let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
    let mid_new = root + l1 * (cos_a * u + sin_a * n);
    TwoBone { mid: mid_new, end: root + d * u, clamped }
}

/// Which limb of the standard skeleton.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Limb {
    LeftLeg,
    RightLeg,
    LeftArm,
    RightArm,
}

impl Limb {
    /// `[upper, mid, end]` joints (UpLeg–Leg–Foot or Arm–ForeArm–Hand).
    pub fn chain(self, rig: &Rig) -> [usize; 3] {
        let (l, first) = match self {
            Limb::LeftLeg => (rig.legs[0], 0),
            Limb::RightLeg => (rig.legs[1], 0),
            Limb::LeftArm => (rig.arms[0], 1),
            Limb::RightArm => (rig.arms[1], 1),
        };
        [l[first], l[first + 1], l[first + 2]]
    }

    /// Default bend direction in the character's frame: knees forward, elbows back and out.
    fn default_bend(self) -> DVec3 {
        match self {
            Limb::LeftLeg | Limb::RightLeg => DVec3::Z,
            Limb::LeftArm => DVec3::new(0.3, 0.0, -1.0),
            Limb::RightArm => DVec3::new(-0.3, 0.0, -1.0),
        }
    }
}

/// Moves the end joint of `chain` (`[upper, mid, end]`, a parent chain) to `target` (global) by
/// rotating `upper` and `mid`; the end joint keeps its global orientation. `pole`: a global point
/// the middle joint bends towards (None: keep the current bend plane, or the limb's default).
/// Returns the remaining distance to the target (0 when reachable).
pub fn solve_chain(
    skeleton: &Skeleton,
    pose: &mut Pose,
    chain: [usize; 3],
    target: DVec3,
    pole: Option<DVec3>,
    default_bend: DVec3,
) -> f64 {
    let g = forward(skeleton, pose);
    let [a, b, c] = chain;
    let (pa, pb, pc) = (g.positions[a], g.positions[b], g.positions[c]);
    let pole = pole.unwrap_or_else(|| {
        let line = pc - pa;
        let off = (pb - pa) - line.normalize_or_zero() * (pb - pa).dot(line.normalize_or_zero());
        if off.length() > 1e-4 * line.length().max(1e-9) {
            pb + off
        } else {
            pb + g.rotations[0] * default_bend
        }
    });
    let sol = two_bone(pa, pb, pc, target, pole);
    let r1 = arc(pb - pa, sol.mid - pa);
    let ga = (r1 * g.rotations[a]).normalize();
    let pc1 = sol.mid + r1 * (pc - pb);
    let r2 = arc(pc1 - sol.mid, sol.end - sol.mid);
    let gb = (r2 * r1 * g.rotations[b]).normalize();
    let parent_a = skeleton.parent(a).map(|p| g.rotations[p]).unwrap_or(DQuat::IDENTITY);
    pose.rotations[a] = local_from_global(parent_a, ga);
    pose.rotations[b] = local_from_global(ga, gb);
    pose.rotations[c] = local_from_global(gb, g.rotations[c]);
    (sol.end - target).length()
}

/// [`solve_chain`] on a limb of the standard rig.
pub fn solve_limb(rig: &Rig, pose: &mut Pose, limb: Limb, target: DVec3, pole: Option<DVec3>) -> f64 {
    solve_chain(&rig.skeleton, pose, limb.chain(rig), target, pole, limb.default_bend())
}

/// How far the heel lies behind the ankle joint, metres (the heel point is straight under the
/// ankle at rest height, this far back).
pub const HEEL_BACK: f64 = 0.03;
/// How far under the floor a sole point may be before [`ground_feet`] moves it, metres.
const SOLE_SLACK: f64 = 1e-4;

/// The foot's yaw alone: `q` with its pitch and roll removed (forward projected on the floor).
pub(crate) fn flat_of(q: DQuat) -> DQuat {
    let f = q * DVec3::Z;
    let h = DVec3::new(f.x, 0.0, f.z);
    if h.length_squared() < 1e-12 {
        return DQuat::IDENTITY;
    }
    DQuat::from_rotation_y(h.x.atan2(h.z))
}

/// Feet on the floor (issue 27): no point of a sole (heel, toe base, toe tip) ends under the
/// floor. A foot that reaches under it is turned towards flat (its yaw kept, toes straightened)
/// just as far as clears it, so a foot pitched toe-down on a planted ankle lies flat and one
/// rolling over its toes keeps them on the floor; when even flat does not clear it, the ankle is
/// lifted with the leg's two-bone IK. A foot above the floor is left as it is. Works on one
/// pose, so every frame a timeline appends goes through it.
pub fn ground_feet(rig: &Rig, pose: &mut Pose) {
    let s = &rig.skeleton;
    for leg in rig.legs {
        let [_, knee, foot, toe] = leg;
        let g = forward(s, pose);
        let ankle = g.positions[foot];
        let own = g.rotations[foot];
        let flat = flat_of(own);
        let toe_local = pose.rotations[toe];
        let toe_offset = s.joint(toe).offset;
        let tip_offset = s.joint(toe).end_site.unwrap_or(DVec3::ZERO);
        // Lowest sole point for a foot rotation `r` (toe keeping its local rotation) at `at`.
        let heel = DVec3::new(0.0, -rig.ankle_height, -HEEL_BACK);
        let lowest = |r: DQuat, toe_rot: DQuat, at: DVec3| -> f64 {
            let toe_pos = at + r * toe_offset;
            let tip = toe_pos + (r * toe_rot) * tip_offset;
            (at + r * heel).y.min(toe_pos.y).min(tip.y)
        };
        if lowest(own, toe_local, ankle) >= -SOLE_SLACK {
            continue;
        }
        // The least turn towards flat that clears the floor (all the way when none does).
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        if lowest(flat, DQuat::IDENTITY, ankle) >= -SOLE_SLACK {
            for _ in 0..12 {
                let mid = 0.5 * (lo + hi);
                if lowest(own.slerp(flat, mid), toe_local.slerp(DQuat::IDENTITY, mid), ankle) >= -SOLE_SLACK {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
        }
        let (r, toe_rot) = (own.slerp(flat, hi), toe_local.slerp(DQuat::IDENTITY, hi));
        let lift = -lowest(r, toe_rot, ankle);
        if lift > SOLE_SLACK {
            let limb = if leg == rig.legs[0] { Limb::LeftLeg } else { Limb::RightLeg };
            solve_limb(rig, pose, limb, ankle + DVec3::Y * lift, None);
        }
        let knee_global = forward(s, pose).rotations[knee];
        pose.rotations[foot] = local_from_global(knee_global, r);
        pose.rotations[toe] = toe_rot.normalize();
    }
}

/// Height of the pelvis contact (midpoint of the hip joints) above the seat surface when sitting.
pub const PELVIS_ABOVE_SEAT: f64 = 0.09;

/// Sitting placement (§4.3 hip contact point): moves the root so the pelvis (midpoint of the two
/// `UpLeg` joints) sits [`PELVIS_ABOVE_SEAT`] above `seat` (a world point on the seat surface),
/// then, when `feet_on_floor`, re-solves both legs so the ankles stand on the floor where the pose
/// put them (horizontally), at rest ankle height. Returns the largest remaining foot error.
pub fn place_hips(rig: &Rig, pose: &mut Pose, seat: DVec3, feet_on_floor: bool) -> f64 {
    let g = forward(&rig.skeleton, pose);
    let ankles = [g.positions[rig.legs[0][2]], g.positions[rig.legs[1][2]]];
    let pelvis = (g.positions[rig.legs[0][0]] + g.positions[rig.legs[1][0]]) * 0.5;
    let want = seat + DVec3::Y * PELVIS_ABOVE_SEAT;
    pose.translations[rig.hips] += want - pelvis;
    if !feet_on_floor {
        return 0.0;
    }
    let shift = want - pelvis;
    let mut err: f64 = 0.0;
    for (k, limb) in [Limb::LeftLeg, Limb::RightLeg].into_iter().enumerate() {
        // Feet move with the hips horizontally, then go down to the floor.
        let a = ankles[k] + DVec3::new(shift.x, 0.0, shift.z);
        let target = DVec3::new(a.x, rig.ankle_height, a.z);
        err = err.max(solve_limb(rig, pose, limb, target, None));
    }
    err
}

/// A seated pose at the origin facing +Z for a seat of height `seat_height` (thighs forward,
/// shins down, feet on the floor), placed with [`place_hips`].
pub fn seated_pose(rig: &Rig, seat: DVec3, heading: f64) -> Pose {
    let mut p = rig.standing();
    p.translations[rig.hips] = DVec3::new(seat.x, hip_height(), seat.z);
    p.rotations[rig.hips] = DQuat::from_rotation_y(heading);
    for leg in rig.legs {
        p.rotations[leg[0]] = DQuat::from_rotation_x(-1.45);
        p.rotations[leg[1]] = DQuat::from_rotation_x(1.45);
    }
    place_hips(rig, &mut p, seat, true);
    p
}
