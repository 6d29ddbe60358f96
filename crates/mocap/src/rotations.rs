//! Rotation output (beyond the paper): the paper reconstructs positions; to write a clip back as BVH
//! we also reconstruct every joint's local rotation with a quaternion Hermite curve (value + angular
//! velocity at both keys) and every translation with a cubic Hermite (the root's path, Eq. 12–13).
//! In-betweens again depend only on the two keys around them, so the same selectors apply.

use crate::metrics::{Scratch, SegmentCost, SegmentModel};
use crate::{MocapError, Result};
use glam::{DQuat, DVec3};
use inbetween_core::interp::{angular_velocity, hermite, hermite_quat, hermite_vec3};
use inbetween_core::rotation::{angle_between, make_continuous};
use inbetween_core::units::LengthUnit;
use inbetween_core::{KeyframeSet, Motion, Pose, Skeleton};

/// The local state of every joint at one frame: what a keyframe stores (values and tangents).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct KeyPose {
    pub rotations: Vec<DQuat>,
    /// Body-frame angular velocities, rad/s.
    pub angular_velocities: Vec<DVec3>,
    pub translations: Vec<DVec3>,
    /// Translation velocities, units/s.
    pub velocities: Vec<DVec3>,
}

/// A dense clip as key poses at every frame, plus the source's global positions for errors.
#[derive(Clone, Debug)]
pub struct RotationMotion {
    pub skeleton: Skeleton,
    pub frame_time: f64,
    pub frames: Vec<KeyPose>,
    /// Source global positions, frame-major.
    pub positions: Vec<DVec3>,
    pub cm_per_unit: f64,
}

/// How the rotations between two key poses are evaluated. Translations are a cubic Hermite per
/// component in both (Eq. 12–13).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RotationCurve {
    /// Kim, Kim & Shin's cumulative quaternion Hermite ([`hermite_quat`]): exact on the rotation
    /// manifold, the engine's own output (BVH, `.ibk`).
    #[default]
    Hermite,
    /// A cubic Hermite per quaternion component (x, y, z, w) with the component derivatives
    /// `q̇ = ½ q ⊗ (0, ω)` at both keys, then normalised: what a DCC evaluates from four Bezier
    /// F-curves whose handles lie a third of the segment along each tangent (Blender's pose bones in
    /// quaternion mode, quaternion curves in Maya and Unreal). Keys chosen with it keep their bound
    /// on what such a DCC plays back; [`crate::dcc::bezier_keys`] gives the handles.
    QuaternionBezier,
}

impl RotationCurve {
    pub fn name(self) -> &'static str {
        match self {
            RotationCurve::Hermite => "hermite",
            RotationCurve::QuaternionBezier => "quaternion_bezier",
        }
    }

    /// Parses a curve's name (`hermite`, `quaternion_bezier`).
    pub fn parse(s: &str) -> Result<RotationCurve> {
        match s {
            "hermite" => Ok(RotationCurve::Hermite),
            "quaternion_bezier" => Ok(RotationCurve::QuaternionBezier),
            _ => Err(MocapError::Invalid(format!("curve '{s}': expected 'hermite' or 'quaternion_bezier'"))),
        }
    }
}

/// The derivative of a unit quaternion's components turning at body-frame angular velocity `w`
/// (rad/s): `q̇ = ½ q ⊗ (w, 0)`.
pub fn quat_component_rate(q: DQuat, w: DVec3) -> DQuat {
    q * DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * 0.5
}

/// [`RotationCurve::QuaternionBezier`] between `q0` (derivative `d0`, per second) and `q1` (`d1`)
/// over `h` seconds at fraction `u`: a cubic Hermite per component, normalised. The components are
/// taken as stored (no sign flip): a DCC interpolates the curves it holds.
pub fn hermite_quat_components(q0: DQuat, d0: DQuat, q1: DQuat, d1: DQuat, h: f64, u: f64) -> DQuat {
    let c = |a: f64, da: f64, b: f64, db: f64| hermite(a, da, b, db, h, u);
    DQuat::from_xyzw(
        c(q0.x, d0.x, q1.x, d1.x),
        c(q0.y, d0.y, q1.y, d1.y),
        c(q0.z, d0.z, q1.z, d1.z),
        c(q0.w, d0.w, q1.w, d1.w),
    )
    .normalize()
}

/// Central difference step around frame f: the frames it spans.
fn neighbours(f: usize, n: usize) -> (usize, usize) {
    (f.saturating_sub(1), (f + 1).min(n - 1))
}

impl RotationMotion {
    /// The clip with its length unit inferred from the skeleton ([`LengthUnit::infer`]).
    pub fn from_motion(motion: &Motion) -> Result<RotationMotion> {
        Self::from_motion_in(motion, LengthUnit::infer(&motion.skeleton).cm_per_unit())
    }

    /// The clip, with errors measured at `cm_per_unit` centimetres per length unit.
    pub fn from_motion_in(motion: &Motion, cm_per_unit: f64) -> Result<RotationMotion> {
        let n = motion.num_frames();
        if n < 2 {
            return Err(MocapError::Invalid(format!(
                "a clip of {n} frames has nothing to reconstruct; need at least 2"
            )));
        }
        let nj = motion.skeleton.len();
        let dt = motion.frame_time;
        let poses = motion.poses();
        let mut rot_tracks: Vec<Vec<DQuat>> = (0..nj).map(|j| poses.iter().map(|p| p.rotations[j]).collect()).collect();
        for t in &mut rot_tracks {
            make_continuous(t);
        }
        let frames = (0..n)
            .map(|f| {
                let (lo, hi) = neighbours(f, n);
                let span = (hi - lo) as f64 * dt;
                KeyPose {
                    rotations: (0..nj).map(|j| rot_tracks[j][f]).collect(),
                    angular_velocities: (0..nj)
                        .map(|j| {
                            // Central difference expressed in the body frame at f.
                            let w_lo = angular_velocity(rot_tracks[j][lo], rot_tracks[j][hi], span);
                            let q = rot_tracks[j][f];
                            q.inverse() * (rot_tracks[j][lo] * w_lo)
                        })
                        .collect(),
                    translations: poses[f].translations.clone(),
                    velocities: (0..nj)
                        .map(|j| (poses[hi].translations[j] - poses[lo].translations[j]) / span)
                        .collect(),
                }
            })
            .collect();
        let mut positions = Vec::with_capacity(n * nj);
        for g in inbetween_core::forward_clip(motion) {
            positions.extend(g.positions);
        }
        Ok(RotationMotion { skeleton: motion.skeleton.clone(), frame_time: dt, frames, positions, cm_per_unit })
    }

    pub fn num_frames(&self) -> usize {
        self.frames.len()
    }

    /// The key poses of a keyframe set.
    pub fn key_poses(&self, keys: &KeyframeSet) -> Vec<KeyPose> {
        keys.frames().iter().map(|&f| self.frames[f].clone()).collect()
    }

    /// Reconstructs the whole clip from `keys` as a motion on the same skeleton.
    pub fn reconstruct(&self, keys: &KeyframeSet) -> Result<Motion> {
        reconstruct_from_keys(&self.skeleton, self.frame_time, keys.frames(), &self.key_poses(keys))
    }

    /// The clip as a segment model whose in-betweens follow `curve`, a segment feasible only where
    /// no joint's local rotation is further than `max_angle_rad` from the source (when given).
    pub fn along(&self, curve: RotationCurve, max_angle_rad: Option<f64>) -> CurveModel<'_> {
        CurveModel { motion: self, curve, max_angle_rad }
    }

    /// One in-between's cost and its largest local rotation error (radians).
    fn frame_cost_along(
        &self,
        curve: RotationCurve,
        a: usize,
        b: usize,
        f: usize,
        s: &mut Scratch,
    ) -> (SegmentCost, f64) {
        let nj = self.skeleton.len();
        let h = (b - a) as f64 * self.frame_time;
        let u = (f - a) as f64 / (b - a) as f64;
        let mut cost = SegmentCost::default();
        let mut angle_max = 0.0f64;
        interpolate_pose_into(&self.frames[a], &self.frames[b], h, u, curve, &mut s.locals, &mut s.translations);
        forward_into(&self.skeleton, &s.locals, &s.translations, &mut s.positions, &mut s.rotations);
        for j in 0..nj {
            if self.skeleton.joint(j).rotation_order().is_some() {
                let angle = angle_between(s.locals[j], self.frames[f].rotations[j]);
                cost.angle_sum += angle;
                angle_max = angle_max.max(angle);
            }
            let d = s.positions[j].distance(self.positions[f * nj + j]) * self.cm_per_unit;
            cost.cm_sum += d;
            cost.cm_max = cost.cm_max.max(d);
        }
        (cost, angle_max)
    }
}

/// A [`RotationMotion`] whose in-betweens follow one [`RotationCurve`]: the segment model of the
/// error-bounded search when the bound is on the rebuilt clip (or on a DCC's playback of it).
pub struct CurveModel<'a> {
    pub motion: &'a RotationMotion,
    pub curve: RotationCurve,
    /// Largest local rotation error of any joint a feasible segment may have, radians.
    pub max_angle_rad: Option<f64>,
}

impl SegmentModel for CurveModel<'_> {
    fn num_frames(&self) -> usize {
        self.motion.num_frames()
    }

    fn num_joints(&self) -> usize {
        self.motion.num_joints()
    }

    fn angle_terms_per_frame(&self) -> usize {
        self.motion.angle_terms_per_frame()
    }

    fn scratch(&self) -> Scratch {
        self.motion.scratch()
    }

    fn frame_cost(&self, a: usize, b: usize, f: usize, s: &mut Scratch) -> SegmentCost {
        self.motion.frame_cost_along(self.curve, a, b, f, s).0
    }

    /// Rejects a frame over `max_cm` or over the angle bound.
    fn frame_cost_within(&self, a: usize, b: usize, f: usize, max_cm: f64, s: &mut Scratch) -> Option<SegmentCost> {
        let (c, angle) = self.motion.frame_cost_along(self.curve, a, b, f, s);
        (c.cm_max <= max_cm && angle <= self.max_angle_rad.unwrap_or(f64::INFINITY)).then_some(c)
    }
}

/// Local pose at fraction `u` of a segment `h` seconds long between key poses `k0` and `k1`, the
/// rotations along `curve`.
pub fn interpolate_pose_into(
    k0: &KeyPose,
    k1: &KeyPose,
    h: f64,
    u: f64,
    curve: RotationCurve,
    rot: &mut [DQuat],
    trans: &mut [DVec3],
) {
    for j in 0..rot.len() {
        let (q0, w0, q1, w1) = (k0.rotations[j], k0.angular_velocities[j], k1.rotations[j], k1.angular_velocities[j]);
        rot[j] = match curve {
            RotationCurve::Hermite => hermite_quat(q0, w0, q1, w1, h, u),
            RotationCurve::QuaternionBezier => {
                hermite_quat_components(q0, quat_component_rate(q0, w0), q1, quat_component_rate(q1, w1), h, u)
            }
        };
        trans[j] = hermite_vec3(k0.translations[j], k0.velocities[j], k1.translations[j], k1.velocities[j], h, u);
    }
}

/// Forward kinematics into preallocated buffers (no allocation, unlike `inbetween_core::forward`).
pub fn forward_into(skeleton: &Skeleton, local_r: &[DQuat], local_t: &[DVec3], pos: &mut [DVec3], rot: &mut [DQuat]) {
    for (j, joint) in skeleton.joints().iter().enumerate() {
        match joint.parent {
            None => {
                pos[j] = local_t[j];
                rot[j] = local_r[j];
            }
            Some(p) => {
                pos[j] = pos[p] + rot[p] * local_t[j];
                rot[j] = rot[p] * local_r[j];
            }
        }
    }
}

/// Rebuilds a clip of `frames[last] + 1` frames from keys at `frames` (sorted, first = 0).
pub fn reconstruct_from_keys(
    skeleton: &Skeleton,
    frame_time: f64,
    frames: &[usize],
    keys: &[KeyPose],
) -> Result<Motion> {
    let poses = reconstruct_poses(skeleton, frame_time, frames, keys, RotationCurve::Hermite)?;
    Ok(Motion::from_poses(skeleton.clone(), frame_time, &poses)?)
}

/// The local poses of a clip rebuilt from keys at `frames`, the rotations along `curve` (those of
/// [`reconstruct_from_keys`] with [`RotationCurve::Hermite`]).
pub fn reconstruct_poses(
    skeleton: &Skeleton,
    frame_time: f64,
    frames: &[usize],
    keys: &[KeyPose],
    curve: RotationCurve,
) -> Result<Vec<Pose>> {
    if frames.len() < 2 || frames.len() != keys.len() || frames[0] != 0 || frames.windows(2).any(|w| w[0] >= w[1]) {
        return Err(MocapError::Invalid(format!(
            "keyframes {frames:?} must start at 0, increase and number at least 2"
        )));
    }
    let nj = skeleton.len();
    let n = frames[frames.len() - 1] + 1;
    // Frames are independent: in parallel (the same numbers), each from the segment it lies in.
    use rayon::prelude::*;
    let poses: Vec<Pose> = (0..n)
        .into_par_iter()
        .map(|f| {
            let s = frames.partition_point(|&k| k <= f).saturating_sub(1).min(frames.len() - 2);
            let (a, b) = (frames[s], frames[s + 1]);
            let mut pose = Pose { rotations: vec![DQuat::IDENTITY; nj], translations: vec![DVec3::ZERO; nj] };
            if f == a {
                pose.rotations.copy_from_slice(&keys[s].rotations);
                pose.translations.copy_from_slice(&keys[s].translations);
            } else if f == b {
                pose.rotations.copy_from_slice(&keys[s + 1].rotations);
                pose.translations.copy_from_slice(&keys[s + 1].translations);
            } else {
                let h = (b - a) as f64 * frame_time;
                let u = (f - a) as f64 / (b - a) as f64;
                interpolate_pose_into(&keys[s], &keys[s + 1], h, u, curve, &mut pose.rotations, &mut pose.translations);
            }
            pose
        })
        .collect();
    Ok(poses)
}

impl SegmentModel for RotationMotion {
    fn num_frames(&self) -> usize {
        self.frames.len()
    }

    fn num_joints(&self) -> usize {
        self.skeleton.len()
    }

    /// One geodesic error term per joint with rotation channels.
    fn angle_terms_per_frame(&self) -> usize {
        self.skeleton.joints().iter().filter(|j| j.rotation_order().is_some()).count()
    }

    fn scratch(&self) -> Scratch {
        let nj = self.skeleton.len();
        Scratch {
            positions: vec![DVec3::ZERO; nj],
            rotations: vec![DQuat::IDENTITY; nj],
            locals: vec![DQuat::IDENTITY; nj],
            translations: vec![DVec3::ZERO; nj],
            angles: Vec::new(),
        }
    }

    /// In-betweens along [`RotationCurve::Hermite`], the engine's own output.
    fn frame_cost(&self, a: usize, b: usize, f: usize, s: &mut Scratch) -> SegmentCost {
        self.frame_cost_along(RotationCurve::Hermite, a, b, f, s).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::positions_clip;
    use inbetween_core::procedural::{gait, GaitParams};

    #[test]
    fn rotation_reconstruction_hits_keys_and_matches_segment_costs() {
        let mut p = GaitParams::walk();
        p.frames = 45;
        let m = gait(&p);
        let rm = RotationMotion::from_motion(&m).unwrap();
        let keys = KeyframeSet::new(vec![11, 25, 38], 45).unwrap();
        let rec = rm.reconstruct(&keys).unwrap();
        assert_eq!(rec.num_frames(), 45);
        let (a, b) = (positions_clip(&m), positions_clip(&rec));
        for &k in keys.frames() {
            for j in 0..m.skeleton.len() {
                assert!((a[k][j] - b[k][j]).length() < 1e-9, "key {k} joint {j}");
            }
        }
        // The error of the written clip equals the sum of the segment costs.
        let err = rm.error(&keys);
        let direct = inbetween_core::position_error(&a, &b);
        assert!(
            (direct.mean * rm.cm_per_unit - err.mean_cm).abs() < 1e-6,
            "{} vs {}",
            direct.mean * rm.cm_per_unit,
            err.mean_cm
        );
        assert!(err.mean_cm > 0.0);
        // Bone lengths are exact: FK of local rotations with fixed offsets.
        let s = &m.skeleton;
        for frame in &b {
            for j in 1..s.len() {
                let par = s.parent(j).unwrap();
                assert!(((frame[j] - frame[par]).length() - s.joint(j).offset.length()).abs() < 1e-9);
            }
        }
    }

    /// A walk that turns 2.5 rad/s for 3 s: the root's yaw channel wraps from +180° to −180° in
    /// the BVH (twice). Quaternion keys stay in one hemisphere along the track, so the keys and the
    /// Hermite in-betweens see a smooth turn: the error is that of the same walk without the turn.
    #[test]
    fn euler_wraps_at_180_degrees_do_not_disturb_the_reconstruction() {
        let clip = |turn_rate: f64| {
            let mut p = GaitParams::walk();
            p.frames = 90;
            p.turn_rate = turn_rate;
            gait(&p)
        };
        let turning = clip(2.5);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("turn.bvh");
        inbetween_io::write_bvh(&path, &turning).unwrap();
        let turning = inbetween_io::read_bvh(&path).unwrap();
        let nc = turning.num_channels();
        let wraps = (1..90)
            .flat_map(|f| (3..6).map(move |c| (f, c)))
            .filter(|&(f, c)| (turning.data()[f * nc + c] - turning.data()[(f - 1) * nc + c]).abs() > 300.0)
            .count();
        assert!(wraps >= 2, "the root's Euler angles wrap at ±180° ({wraps} wraps)");
        let rm = RotationMotion::from_motion(&turning).unwrap();
        for j in 0..rm.skeleton.len() {
            for f in 1..90 {
                assert!(rm.frames[f - 1].rotations[j].dot(rm.frames[f].rotations[j]) >= 0.0, "joint {j} frame {f}");
            }
        }
        let keys = KeyframeSet::new((0..90).step_by(6).chain([89]).collect(), 90).unwrap();
        let straight = RotationMotion::from_motion(&clip(0.0)).unwrap().error(&keys);
        let e = rm.error(&keys);
        assert!(e.max_cm < 1.5 * straight.max_cm + 0.5, "turning {e:?} vs straight {straight:?}");
        assert!(e.mean_angle < 1.5 * straight.mean_angle + 1e-3, "turning {e:?} vs straight {straight:?}");
        // Quantised keys (rotation vectors, any hemisphere) decode to the same in-betweens.
        let c = crate::codec::compress(&turning, crate::codec::Budget::MaxErrorCm(1.0), 30).unwrap();
        assert!(c.decoded_max_cm <= 1.0 && c.keys.len() < 30, "{} keys, {} cm", c.keys.len(), c.decoded_max_cm);
    }

    #[test]
    fn quaternion_hermite_tracks_a_smooth_walk_closely() {
        let mut p = GaitParams::walk();
        p.frames = 31;
        let rm = RotationMotion::from_motion(&gait(&p)).unwrap();
        let dense = KeyframeSet::new((0..31).step_by(3).collect(), 31).unwrap();
        let e = rm.error(&dense);
        assert!(e.max_cm < 1.0, "keys every 0.1 s should stay within 1 cm, got {}", e.max_cm);
    }
}
