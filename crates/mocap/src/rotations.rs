//! Rotation output (beyond the paper): the paper reconstructs positions; to write a clip back as BVH
//! we also reconstruct every joint's local rotation with a quaternion Hermite curve (value + angular
//! velocity at both keys) and every translation with a cubic Hermite (the root's path, Eq. 12–13).
//! In-betweens again depend only on the two keys around them, so the same selectors apply.

use crate::metrics::{Scratch, SegmentCost, SegmentModel};
use crate::{MocapError, Result};
use glam::{DMat3, DQuat, DVec3};
use inbetween_core::interp::{angular_velocity, hermite, hermite_quat, hermite_vec3};
use inbetween_core::rotation::{angle_between, make_continuous, EulerOrder};
use inbetween_core::units::LengthUnit;
use inbetween_core::{KeyframeSet, Motion, Pose, Skeleton};
use std::borrow::Cow;
use std::f64::consts::{PI, TAU};

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
    /// Every joint's Euler angles and rates at every frame, for [`RotationCurve::EulerBezier`]
    /// ([`RotationMotion::with_euler`]); `None` until asked for.
    pub euler: Option<EulerKeys>,
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
    /// A cubic Hermite per Euler angle, what a DCC evaluates from three Euler Bezier F-curves with
    /// handles a third of the segment along each tangent (Blender's pose bones in an Euler mode,
    /// BVH and Maya channels): a joint's local rotation is `pre ⊗ R(E)` with `E` the angles in its
    /// [`EulerPlayback`] order, the key values the source's angles made continuous along the track
    /// and the slopes its Euler rates `Ė = J(E)⁻¹ ω`. Joints without an Euler order play
    /// [`RotationCurve::QuaternionBezier`]. The per-joint data lives on the clip
    /// ([`RotationMotion::with_euler`]); [`crate::dcc::bezier_keys`] gives the handles.
    EulerBezier,
}

impl RotationCurve {
    pub fn name(self) -> &'static str {
        match self {
            RotationCurve::Hermite => "hermite",
            RotationCurve::QuaternionBezier => "quaternion_bezier",
            RotationCurve::EulerBezier => "euler_bezier",
        }
    }

    /// Parses a curve's name (`hermite`, `quaternion_bezier`, `euler_bezier`).
    pub fn parse(s: &str) -> Result<RotationCurve> {
        match s {
            "hermite" => Ok(RotationCurve::Hermite),
            "quaternion_bezier" => Ok(RotationCurve::QuaternionBezier),
            "euler_bezier" => Ok(RotationCurve::EulerBezier),
            _ => Err(MocapError::Invalid(format!(
                "curve '{s}': expected 'hermite', 'quaternion_bezier' or 'euler_bezier'"
            ))),
        }
    }
}

/// How a DCC plays each joint's rotation from Euler curves ([`RotationCurve::EulerBezier`]): the
/// joint's local rotation (relative to its parent) is `pre ⊗ R(E)`, `R(E)` the Euler rotation of
/// the three curves' angles `E` in the joint's order.
#[derive(Clone, Debug, PartialEq)]
pub struct EulerPlayback {
    /// Per joint, the order of its angles ([`EulerOrder`]: channel order, composed left to right,
    /// `Zyx` = Rz·Ry·Rx, which Blender calls "XYZ"), or `None`: the joint plays quaternion Bezier
    /// curves.
    pub orders: Vec<Option<EulerOrder>>,
    /// Per joint, a constant rotation on the left (Blender: the bone's rest rotation relative to its
    /// parent, the F-curves holding the pose basis; BVH and Maya: identity).
    pub pre: Vec<DQuat>,
    /// The DCC's own angles, frame-major (`[frame × joints + joint]`), `(x, y, z)` by axis, radians:
    /// each frame's angles are then the equivalent (2π turns, or the other solution of the same
    /// rotation) nearest these, so the keys carry the curves' own values. Without them each frame's
    /// angles are the equivalent nearest the previous frame's.
    pub reference: Option<Vec<DVec3>>,
}

impl EulerPlayback {
    /// A BVH's (or Maya's) playback of `skeleton`: each joint's channel order, no pre-rotation.
    pub fn of_skeleton(skeleton: &Skeleton) -> EulerPlayback {
        EulerPlayback {
            orders: skeleton.joints().iter().map(|j| j.rotation_order()).collect(),
            pre: vec![DQuat::IDENTITY; skeleton.len()],
            reference: None,
        }
    }
}

/// One joint's Euler curve values at one pose: angles in its order's channel order (radians) and
/// their rates (rad/s).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct EulerKey {
    pub angles: DVec3,
    pub rates: DVec3,
}

/// Euler curve values of a run of poses (every frame of a clip, or its keys): the playback's
/// orders and pre-rotations, and `[pose][joint]` angles and rates (zero for joints without an
/// order).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct EulerKeys {
    pub orders: Vec<Option<EulerOrder>>,
    pub pre: Vec<DQuat>,
    pub keys: Vec<Vec<EulerKey>>,
}

/// One segment's Euler keys: what [`interpolate_pose_into`] needs beyond the key poses for
/// [`RotationCurve::EulerBezier`].
#[derive(Clone, Copy, Debug)]
pub struct EulerSegment<'a> {
    pub orders: &'a [Option<EulerOrder>],
    pub pre: &'a [DQuat],
    pub k0: &'a [EulerKey],
    pub k1: &'a [EulerKey],
}

impl EulerKeys {
    /// The keys of the poses at `frames` (indices into these poses).
    pub fn at(&self, frames: &[usize]) -> EulerKeys {
        EulerKeys {
            orders: self.orders.clone(),
            pre: self.pre.clone(),
            keys: frames.iter().map(|&f| self.keys[f].clone()).collect(),
        }
    }

    /// The segment between poses `a` and `b`.
    pub fn segment(&self, a: usize, b: usize) -> EulerSegment<'_> {
        EulerSegment { orders: &self.orders, pre: &self.pre, k0: &self.keys[a], k1: &self.keys[b] }
    }
}

/// Refuses an Euler playback with a curve other than [`RotationCurve::EulerBezier`].
pub fn check_playback(curve: RotationCurve, euler: Option<&EulerPlayback>) -> Result<()> {
    match (curve, euler) {
        (RotationCurve::EulerBezier, _) | (_, None) => Ok(()),
        _ => Err(MocapError::Invalid(format!(
            "Euler playback given with curve '{}': it needs curve 'euler_bezier'",
            curve.name()
        ))),
    }
}

/// Angles in channel order from `(x, y, z)` by axis.
fn by_channel(order: EulerOrder, xyz: DVec3) -> DVec3 {
    let a = order.axes();
    DVec3::new(xyz[a[0].index()], xyz[a[1].index()], xyz[a[2].index()])
}

/// `(x, y, z)` by axis from angles in `order`'s channel order.
pub fn euler_by_axis(order: EulerOrder, angles: DVec3) -> DVec3 {
    let mut out = DVec3::ZERO;
    for (k, axis) in order.axes().into_iter().enumerate() {
        out[axis.index()] = angles[k];
    }
    out
}

/// The angles of the rotation `e` (channel order) nearest `target`: `e` or the other solution of
/// a Tait–Bryan decomposition `(a + π, π − b, c + π)`, each angle moved by whole turns.
pub fn nearest_euler(e: DVec3, target: DVec3) -> DVec3 {
    let turn = |v: DVec3| v + ((target - v) / TAU).round() * TAU;
    let a = turn(e);
    let b = turn(DVec3::new(e.x + PI, PI - e.y, e.z + PI));
    if a.distance_squared(target) <= b.distance_squared(target) {
        a
    } else {
        b
    }
}

/// The rates `Ė` of Euler angles `e` (channel order of `order`) of a rotation turning at body-frame
/// angular velocity `w`: `ω = J(E) Ė` with `J`'s columns the axes seen from the body,
/// `(R_c⁻¹ R_b⁻¹ a, R_c⁻¹ b, c)`. `None` near gimbal lock (|det J| = |cos E₁| below 10⁻⁶).
pub fn euler_rates(order: EulerOrder, e: DVec3, w: DVec3) -> Option<DVec3> {
    let [a, b, c] = order.axes();
    let (rb, rc) = (b.rotation(e.y).inverse(), c.rotation(e.z).inverse());
    let j = DMat3::from_cols(rc * (rb * a.unit()), rc * b.unit(), c.unit());
    (j.determinant().abs() > 1e-6).then(|| j.inverse() * w)
}

/// A joint's rotation `pre ⊗ R(E)` at Euler angles `e` (channel order).
fn euler_rotation(order: EulerOrder, pre: DQuat, e: DVec3) -> DQuat {
    pre * order.to_quat(e.to_array())
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
        Ok(RotationMotion {
            skeleton: motion.skeleton.clone(),
            frame_time: dt,
            frames,
            positions,
            cm_per_unit,
            euler: None,
        })
    }

    pub fn num_frames(&self) -> usize {
        self.frames.len()
    }

    /// The clip with every joint's Euler angles and rates as `playback` plays them (for
    /// [`RotationCurve::EulerBezier`]): the angles of `pre⁻¹ ⊗ q` made continuous (or nearest the
    /// playback's reference), the rates `J(E)⁻¹ ω` from the body-frame angular velocity (the
    /// central difference of the angles at gimbal lock).
    pub fn with_euler(&self, playback: &EulerPlayback) -> Result<RotationMotion> {
        let (n, nj) = (self.num_frames(), self.skeleton.len());
        if playback.orders.len() != nj || playback.pre.len() != nj {
            return Err(MocapError::Invalid(format!(
                "Euler playback for {} orders and {} pre-rotations: expected one per joint, {nj}",
                playback.orders.len(),
                playback.pre.len()
            )));
        }
        if let Some(r) = &playback.reference {
            if r.len() != n * nj {
                return Err(MocapError::Invalid(format!(
                    "{} reference Euler angles: expected one per frame and joint, {n} × {nj}",
                    r.len()
                )));
            }
            if let Some(i) = r.iter().position(|v| !v.is_finite()) {
                return Err(MocapError::Invalid(format!(
                    "reference Euler angles of joint {} at frame {}: {} is not finite",
                    i % nj,
                    i / nj,
                    r[i]
                )));
            }
        }
        if let Some(j) = playback.pre.iter().position(|q| !q.is_finite() || (q.length() - 1.0).abs() > 1e-3) {
            return Err(MocapError::Invalid(format!(
                "pre-rotation of joint {j}: {} is not a unit quaternion",
                playback.pre[j]
            )));
        }
        let mut keys = vec![vec![EulerKey::default(); nj]; n];
        for j in 0..nj {
            let Some(order) = playback.orders[j] else { continue };
            let inv = playback.pre[j].normalize().inverse();
            for f in 0..n {
                let e = DVec3::from_array(order.from_quat(inv * self.frames[f].rotations[j]));
                let target = match (&playback.reference, f) {
                    (Some(r), _) => Some(by_channel(order, r[f * nj + j])),
                    (None, 0) => None,
                    (None, _) => Some(keys[f - 1][j].angles),
                };
                keys[f][j].angles = target.map_or(e, |t| nearest_euler(e, t));
            }
            for f in 0..n {
                let k = keys[f][j].angles;
                keys[f][j].rates = euler_rates(order, k, self.frames[f].angular_velocities[j]).unwrap_or_else(|| {
                    let (lo, hi) = neighbours(f, n);
                    (keys[hi][j].angles - keys[lo][j].angles) / ((hi - lo) as f64 * self.frame_time)
                });
            }
        }
        let euler = EulerKeys { orders: playback.orders.clone(), pre: playback.pre.clone(), keys };
        Ok(RotationMotion { euler: Some(euler), ..self.clone() })
    }

    /// The clip as `curve` plays it: with its Euler keys for [`RotationCurve::EulerBezier`] (from
    /// `euler`, by default the skeleton's BVH channels, [`EulerPlayback::of_skeleton`]), else as it
    /// is (an Euler playback then is an error).
    pub fn played(&self, curve: RotationCurve, euler: Option<&EulerPlayback>) -> Result<Cow<'_, RotationMotion>> {
        check_playback(curve, euler)?;
        match (curve, euler) {
            (RotationCurve::EulerBezier, Some(p)) => Ok(Cow::Owned(self.with_euler(p)?)),
            (RotationCurve::EulerBezier, None) => {
                Ok(Cow::Owned(self.with_euler(&EulerPlayback::of_skeleton(&self.skeleton))?))
            }
            _ => Ok(Cow::Borrowed(self)),
        }
    }

    /// The Euler keys of `keys` (when the clip has them).
    pub fn key_euler(&self, keys: &KeyframeSet) -> Option<EulerKeys> {
        self.euler.as_ref().map(|e| e.at(keys.frames()))
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
        let euler = self.euler.as_ref().map(|e| e.segment(a, b));
        interpolate_pose_into(&self.frames[a], &self.frames[b], h, u, curve, euler, &mut s.locals, &mut s.translations);
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
/// rotations along `curve`. [`RotationCurve::EulerBezier`] plays the joints with an order in
/// `euler` (the segment's Euler keys) from their angles, every other joint (and every joint
/// without `euler`) as [`RotationCurve::QuaternionBezier`].
#[allow(clippy::too_many_arguments)]
pub fn interpolate_pose_into(
    k0: &KeyPose,
    k1: &KeyPose,
    h: f64,
    u: f64,
    curve: RotationCurve,
    euler: Option<EulerSegment<'_>>,
    rot: &mut [DQuat],
    trans: &mut [DVec3],
) {
    for j in 0..rot.len() {
        let (q0, w0, q1, w1) = (k0.rotations[j], k0.angular_velocities[j], k1.rotations[j], k1.angular_velocities[j]);
        let quaternion_bezier =
            || hermite_quat_components(q0, quat_component_rate(q0, w0), q1, quat_component_rate(q1, w1), h, u);
        rot[j] = match curve {
            RotationCurve::Hermite => hermite_quat(q0, w0, q1, w1, h, u),
            RotationCurve::QuaternionBezier => quaternion_bezier(),
            RotationCurve::EulerBezier => match euler.and_then(|e| e.orders[j].map(|o| (e, o))) {
                Some((e, order)) => {
                    let (a, b) = (e.k0[j], e.k1[j]);
                    euler_rotation(order, e.pre[j], hermite_vec3(a.angles, a.rates, b.angles, b.rates, h, u))
                }
                None => quaternion_bezier(),
            },
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
    let poses = reconstruct_poses(skeleton, frame_time, frames, keys, RotationCurve::Hermite, None)?;
    Ok(Motion::from_poses(skeleton.clone(), frame_time, &poses)?)
}

/// The local poses of a clip rebuilt from keys at `frames`, the rotations along `curve` (those of
/// [`reconstruct_from_keys`] with [`RotationCurve::Hermite`]); `euler`: the keys' Euler keys, which
/// [`RotationCurve::EulerBezier`] needs.
pub fn reconstruct_poses(
    skeleton: &Skeleton,
    frame_time: f64,
    frames: &[usize],
    keys: &[KeyPose],
    curve: RotationCurve,
    euler: Option<&EulerKeys>,
) -> Result<Vec<Pose>> {
    if frames.len() < 2 || frames.len() != keys.len() || frames[0] != 0 || frames.windows(2).any(|w| w[0] >= w[1]) {
        return Err(MocapError::Invalid(format!(
            "keyframes {frames:?} must start at 0, increase and number at least 2"
        )));
    }
    match (curve, euler) {
        (RotationCurve::EulerBezier, None) => {
            return Err(MocapError::Invalid("curve 'euler_bezier' needs the keys' Euler angles".into()))
        }
        (_, Some(e)) if e.keys.len() != keys.len() || e.orders.len() != skeleton.len() => {
            return Err(MocapError::Invalid(format!(
                "{} Euler keys of {} joints for {} key poses of {} joints",
                e.keys.len(),
                e.orders.len(),
                keys.len(),
                skeleton.len()
            )))
        }
        _ => {}
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
                let e = euler.map(|e| e.segment(s, s + 1));
                interpolate_pose_into(
                    &keys[s],
                    &keys[s + 1],
                    h,
                    u,
                    curve,
                    e,
                    &mut pose.rotations,
                    &mut pose.translations,
                );
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
    fn the_other_euler_solution_and_whole_turns_are_the_same_rotation_and_rates_invert_the_velocity() {
        let e = DVec3::new(0.4, -0.7, 2.9);
        for order in EulerOrder::ALL {
            let q = order.to_quat(e.to_array());
            let far = nearest_euler(e, DVec3::new(7.0, 3.5, -9.0));
            assert!(far.distance(e) > 1.0, "{order:?}");
            assert!(angle_between(q, order.to_quat(far.to_array())) < 1e-12, "{order:?}: {far}");
            assert!(nearest_euler(e, e + 0.1).distance(e) < 1e-12, "{order:?}");
            // Ė = J⁻¹ ω: stepping the angles by Ė·dt turns the rotation by ω·dt in the body frame.
            let w = DVec3::new(0.3, -1.2, 0.8);
            let rate = euler_rates(order, e, w).unwrap();
            let dt = 1e-6;
            let q1 = order.to_quat((e + rate * dt).to_array());
            let body = inbetween_core::rotation::quat_to_rotvec(q.inverse() * q1) / dt;
            assert!(body.distance(w) < 1e-5, "{order:?}: {body} vs {w}");
            // Gimbal lock: no rates.
            assert!(euler_rates(order, DVec3::new(0.3, std::f64::consts::FRAC_PI_2, 0.2), w).is_none());
        }
    }

    #[test]
    fn euler_keys_follow_the_reference_angles_and_rebuild_the_keys_exactly() {
        let mut p = GaitParams::walk();
        p.frames = 40;
        let rm = RotationMotion::from_motion(&gait(&p)).unwrap();
        let nj = rm.skeleton.len();
        let plain = rm.with_euler(&EulerPlayback::of_skeleton(&rm.skeleton)).unwrap();
        let e = plain.euler.as_ref().unwrap();
        // A DCC holding the same angles two turns up (and the other solution on joint 1) keeps them.
        let mut reference = Vec::new();
        for f in 0..40 {
            for j in 0..nj {
                let o = e.orders[j].unwrap();
                let a = e.keys[f][j].angles;
                let a = if j == 1 { DVec3::new(a.x + PI, PI - a.y, a.z + PI) } else { a + 2.0 * TAU };
                reference.push(euler_by_axis(o, a));
            }
        }
        let shifted = rm
            .with_euler(&EulerPlayback {
                reference: Some(reference.clone()),
                ..EulerPlayback::of_skeleton(&rm.skeleton)
            })
            .unwrap();
        let s = shifted.euler.as_ref().unwrap();
        for f in 0..40 {
            for j in 0..nj {
                let o = s.orders[j].unwrap();
                assert!(euler_by_axis(o, s.keys[f][j].angles).distance(reference[f * nj + j]) < 1e-9, "{f} {j}");
            }
        }
        // Every form plays the same in-betweens.
        let keys = KeyframeSet::new(vec![0, 13, 27, 39], 40).unwrap();
        let rebuild = |m: &RotationMotion| {
            reconstruct_poses(
                &m.skeleton,
                m.frame_time,
                keys.frames(),
                &m.key_poses(&keys),
                RotationCurve::EulerBezier,
                m.key_euler(&keys).as_ref(),
            )
            .unwrap()
        };
        let (a, b) = (rebuild(&plain), rebuild(&shifted));
        for f in 0..40 {
            for j in 0..nj {
                assert!(angle_between(a[f].rotations[j], b[f].rotations[j]) < 1e-6, "frame {f} joint {j}");
            }
            if keys.frames().contains(&f) {
                for j in 0..nj {
                    assert!(angle_between(a[f].rotations[j], rm.frames[f].rotations[j]) < 1e-9);
                }
            }
        }
        assert!(reconstruct_poses(
            &rm.skeleton,
            0.1,
            &[0, 39],
            &rm.key_poses(&KeyframeSet::new(vec![0, 39], 40).unwrap()),
            RotationCurve::EulerBezier,
            None
        )
        .unwrap_err()
        .to_string()
        .contains("needs the keys' Euler angles"));
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
