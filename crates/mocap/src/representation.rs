//! The paper's motion representation (Eq. 1–8): every non-root joint as the bone vector from its
//! parent in spherical coordinates — a fixed length `r`, polar angle θ from the z axis and azimuth φ
//! in the x-y plane — plus the angular velocities (θ̇, φ̇) derived from the Cartesian velocity of the
//! bone vector; the root stays Cartesian with its velocity.
//!
//! Velocities come from the dense source by central differences (one-sided at the ends). φ is
//! unwrapped over time so that interpolating between any two frames takes the path the motion took,
//! and near the poles (sin θ small), where Eq. 8's φ̇ = v·e_φ / (r sin θ) is ill-conditioned, φ̇ falls
//! back to the central difference of the unwrapped φ.

use crate::{MocapError, Result};
use glam::DVec3;
use inbetween_core::angle::wrap_angle;
use inbetween_core::procedural::CM_PER_CMU_UNIT;
use inbetween_core::units::LengthUnit;
use inbetween_core::{Joint, Motion};

/// Below this sin θ, φ̇ comes from differencing φ rather than from Eq. 8.
const POLE_SIN_THETA: f64 = 0.1;
/// Bones shorter than this (in the clip's units) have no direction and carry no angles.
const MIN_BONE_LENGTH: f64 = 1e-9;

/// Which joints a keyframe problem works on. A joint whose name contains one of `drop_patterns`
/// (case-insensitive) is dropped with its whole subtree; the root always stays. Works on any skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct JointFilter {
    pub drop_patterns: Vec<String>,
}

impl JointFilter {
    /// The paper's 23 major joints: drops fingers, thumbs and toes. Covers both cgspeed CMU
    /// releases (`LeftFingerBase`, `LThumb`, `LeftToeBase`; and `lhand`/`rhand`, the finger base
    /// below `LeftWrist` in the 131_* files), CMU ASF (`lhand`, `ltoes`: 23 joints too) and
    /// Character Creator rigs, where it also drops the helper bones (`CC_Base_L_Index1`, twist and
    /// share bones, face, breasts: 22 joints, 23 under an `RL_BoneRoot`).
    pub fn paper() -> JointFilter {
        let p = [
            "finger",
            "thumb",
            "toe",
            "handindex",
            "lhand",
            "rhand",
            "index",
            "mid",
            "ring",
            "pinky",
            "thightwist",
            "calftwist",
            "armtwist",
            "ribstwist",
            "sharebone",
            "facialbone",
            "breast",
        ];
        JointFilter { drop_patterns: p.iter().map(|s| s.to_string()).collect() }
    }

    /// Keeps every joint.
    pub fn all() -> JointFilter {
        JointFilter { drop_patterns: Vec::new() }
    }

    /// Parses a comma-separated pattern list; `all` or an empty string keeps every joint, `paper` is
    /// [`JointFilter::paper`].
    pub fn parse(s: &str) -> JointFilter {
        match s.trim() {
            "" | "all" => JointFilter::all(),
            "paper" => JointFilter::paper(),
            list => JointFilter {
                drop_patterns: list
                    .split(',')
                    .map(|p| p.trim().to_ascii_lowercase())
                    .filter(|p| !p.is_empty())
                    .collect(),
            },
        }
    }

    pub fn keeps(&self, joint: &Joint) -> bool {
        let name = joint.name.to_ascii_lowercase();
        !self.drop_patterns.iter().any(|p| name.contains(p.as_str()))
    }

    /// The clip restricted to the kept joints.
    pub fn apply(&self, motion: &Motion) -> Motion {
        if self.drop_patterns.is_empty() {
            return motion.clone();
        }
        motion.filter_joints(|_, j| self.keeps(j))
    }
}

/// The clip without its first frame (the T-pose CMU cgspeed files start with); a clip of two
/// frames or fewer is returned whole.
pub fn skip_first_frame(motion: Motion) -> Result<Motion> {
    let n = motion.num_frames();
    if n > 2 {
        Ok(motion.crop(1, n)?)
    } else {
        Ok(motion)
    }
}

/// A clip in the paper's representation. Per-joint arrays are joint-major (`theta[j * n + f]`) so a
/// segment's frames of one joint are contiguous.
#[derive(Clone, Debug)]
pub struct SphericalMotion {
    pub num_frames: usize,
    pub num_joints: usize,
    /// Seconds per frame (Δt of Eq. 11).
    pub frame_time: f64,
    pub parents: Vec<Option<usize>>,
    /// Bone length r of each joint (0 for the root), Eq. 1.
    pub bone_length: Vec<f64>,
    /// True for joints that carry angles: non-root joints with a bone of non-zero length.
    pub has_angles: Vec<bool>,
    pub theta: Vec<f64>,
    /// Unwrapped azimuth.
    pub phi: Vec<f64>,
    pub dtheta: Vec<f64>,
    pub dphi: Vec<f64>,
    /// Root position and velocity per frame (Eq. 12–13 interpolate these).
    pub root_pos: Vec<DVec3>,
    pub root_vel: Vec<DVec3>,
    /// Original global joint positions, frame-major `[f * num_joints + j]`, for position errors.
    pub positions: Vec<DVec3>,
    /// Centimetres per length unit of the clip (CMU: 5.6444), for errors in cm. [`Self::from_positions`]
    /// assumes CMU units; [`Self::from_motion`] infers the unit.
    pub cm_per_unit: f64,
}

/// Spherical coordinates (r, θ, φ) of a vector, Eq. 1: θ from +z, φ = atan2(y, x).
pub fn to_spherical(v: DVec3) -> (f64, f64, f64) {
    let r = v.length();
    if r < MIN_BONE_LENGTH {
        return (r, 0.0, 0.0);
    }
    let theta = (v.z / r).clamp(-1.0, 1.0).acos();
    (r, theta, v.y.atan2(v.x))
}

/// The unit vector with polar angle θ and azimuth φ.
#[inline]
pub fn direction(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Angular velocities (θ̇, φ̇) of a vector at angles (θ, φ) with length r moving at Cartesian
/// velocity `v`, Eq. 2–8: the velocity projected on e_θ and e_φ (the radial part vanishes when r is
/// fixed). Returns `None` for φ̇ near the poles, where the projection divides by ~0.
pub fn angular_velocity(theta: f64, phi: f64, r: f64, v: DVec3) -> (f64, Option<f64>) {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    let e_theta = DVec3::new(ct * cp, ct * sp, -st);
    let e_phi = DVec3::new(-sp, cp, 0.0);
    let dtheta = v.dot(e_theta) / r;
    let dphi = if st >= POLE_SIN_THETA { Some(v.dot(e_phi) / (r * st)) } else { None };
    (dtheta, dphi)
}

/// Central difference of a per-frame series (one-sided at the ends), per second.
fn central_difference<T>(values: &[T], f: usize, dt: f64) -> T
where
    T: Copy + Default + std::ops::Sub<Output = T> + std::ops::Div<f64, Output = T>,
{
    let n = values.len();
    if n < 2 {
        return T::default();
    }
    let (lo, hi) = (f.saturating_sub(1), (f + 1).min(n - 1));
    (values[hi] - values[lo]) / ((hi - lo) as f64 * dt)
}

impl SphericalMotion {
    /// Converts a clip (use [`JointFilter::apply`] first to pick the joints). Needs at least 2 frames.
    /// The length unit is inferred from the skeleton ([`LengthUnit::infer`]); set `cm_per_unit`
    /// afterwards when it is known.
    pub fn from_motion(motion: &Motion) -> Result<SphericalMotion> {
        let n = motion.num_frames();
        if n < 2 {
            return Err(MocapError::Invalid(format!(
                "a clip of {n} frames has nothing to reconstruct; need at least 2"
            )));
        }
        let global = inbetween_core::positions_clip(motion);
        let mut s = Self::from_positions(
            &motion.skeleton.joints().iter().map(|j| j.parent).collect::<Vec<_>>(),
            &global,
            motion.frame_time,
        );
        s.cm_per_unit = LengthUnit::infer(&motion.skeleton).cm_per_unit();
        Ok(s)
    }

    /// Builds the representation from global positions `[frame][joint]` and the joint parents.
    pub fn from_positions(parents: &[Option<usize>], global: &[Vec<DVec3>], frame_time: f64) -> SphericalMotion {
        let n = global.len();
        let nj = parents.len();
        let mut positions = Vec::with_capacity(n * nj);
        for frame in global {
            positions.extend_from_slice(frame);
        }
        let root_pos: Vec<DVec3> = global.iter().map(|p| p[0]).collect();
        let root_vel: Vec<DVec3> = (0..n).map(|f| central_difference(&root_pos, f, frame_time)).collect();
        let mut s = SphericalMotion {
            num_frames: n,
            num_joints: nj,
            frame_time,
            parents: parents.to_vec(),
            bone_length: vec![0.0; nj],
            has_angles: vec![false; nj],
            theta: vec![0.0; n * nj],
            phi: vec![0.0; n * nj],
            dtheta: vec![0.0; n * nj],
            dphi: vec![0.0; n * nj],
            root_pos,
            root_vel,
            positions,
            cm_per_unit: CM_PER_CMU_UNIT,
        };
        for j in 1..nj {
            let Some(p) = parents[j] else { continue };
            let bones: Vec<DVec3> = global.iter().map(|fr| fr[j] - fr[p]).collect();
            // The mean length: exact for rotation-only joints, a fair constant otherwise.
            let r = bones.iter().map(|b| b.length()).sum::<f64>() / n as f64;
            s.bone_length[j] = r;
            if r < MIN_BONE_LENGTH {
                continue;
            }
            s.has_angles[j] = true;
            s.fill_joint(j, &bones, r);
        }
        s
    }

    fn fill_joint(&mut self, j: usize, bones: &[DVec3], r: f64) {
        let n = self.num_frames;
        let dt = self.frame_time;
        let base = j * n;
        let mut prev_raw = 0.0;
        for (f, b) in bones.iter().enumerate() {
            let (_, theta, raw_phi) = to_spherical(*b);
            self.theta[base + f] = theta;
            // Unwrap: each step moves φ by the short way round.
            self.phi[base + f] = if f == 0 { raw_phi } else { self.phi[base + f - 1] + wrap_angle(raw_phi - prev_raw) };
            prev_raw = raw_phi;
        }
        let phis = self.phi[base..base + n].to_vec();
        for f in 0..n {
            let v = central_difference(bones, f, dt);
            let (dth, dph) = angular_velocity(self.theta[base + f], self.phi[base + f], r, v);
            self.dtheta[base + f] = dth;
            self.dphi[base + f] = dph.unwrap_or_else(|| central_difference(&phis, f, dt));
        }
    }

    /// Number of joints that carry angles (the M of the angle error).
    pub fn angle_joint_count(&self) -> usize {
        self.has_angles.iter().filter(|&&h| h).count()
    }

    /// Original global position of joint `j` at frame `f`.
    pub fn position(&self, f: usize, j: usize) -> DVec3 {
        self.positions[f * self.num_joints + j]
    }

    /// Positions of one frame rebuilt from its own stored angles (a check of Eq. 1's inverse).
    pub fn frame_positions_from_angles(&self, f: usize, out: &mut [DVec3]) {
        let n = self.num_frames;
        out[0] = self.root_pos[f];
        for j in 1..self.num_joints {
            let p = self.parents[j].expect("non-root joints have parents");
            out[j] = out[p] + direction(self.theta[j * n + f], self.phi[j * n + f]) * self.bone_length[j];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};
    use std::f64::consts::PI;

    #[test]
    fn spherical_round_trip_and_velocity_projection() {
        let v = DVec3::new(0.3, -1.2, 0.7);
        let (r, t, p) = to_spherical(v);
        assert!((direction(t, p) * r - v).length() < 1e-12);
        // A vector rotating about z at 2 rad/s: φ̇ = 2, θ̇ = 0.
        let (dth, dph) = angular_velocity(t, p, r, DVec3::Z.cross(v) * 2.0);
        assert!(dth.abs() < 1e-12 && (dph.unwrap() - 2.0).abs() < 1e-12);
        assert!(angular_velocity(1e-3, 0.0, 1.0, DVec3::X).1.is_none(), "pole is flagged");
    }

    #[test]
    fn paper_filter_keeps_23_joints_of_the_cmu_layout() {
        let m = gait(&GaitParams::walk());
        assert_eq!(JointFilter::paper().apply(&m).skeleton.len(), 23);
        assert_eq!(JointFilter::all().apply(&m).skeleton.len(), 31);
        assert_eq!(JointFilter::parse("toe").apply(&m).skeleton.len(), 29);
    }

    #[test]
    fn angles_rebuild_the_original_positions_and_phi_is_continuous() {
        let mut p = GaitParams::walk();
        p.turn_rate = 2.5; // turns more than a full circle: φ must unwrap.
        p.frames = 90;
        let m = JointFilter::paper().apply(&gait(&p));
        let s = SphericalMotion::from_motion(&m).unwrap();
        let mut out = vec![DVec3::ZERO; s.num_joints];
        for f in 0..s.num_frames {
            s.frame_positions_from_angles(f, &mut out);
            for (j, o) in out.iter().enumerate() {
                assert!((*o - s.position(f, j)).length() < 1e-9, "frame {f} joint {j}");
            }
        }
        for j in 1..s.num_joints {
            for f in 1..s.num_frames {
                let step = (s.phi[j * s.num_frames + f] - s.phi[j * s.num_frames + f - 1]).abs();
                assert!(step < PI, "φ jumps by {step} at joint {j} frame {f}");
            }
        }
    }

    #[test]
    fn angular_velocities_match_differences_of_the_angles() {
        let m = JointFilter::paper().apply(&gait(&GaitParams::walk()));
        let s = SphericalMotion::from_motion(&m).unwrap();
        let n = s.num_frames;
        let j = m.skeleton.find("LeftLeg").unwrap();
        for f in 10..20 {
            let i = j * n + f;
            let fd = (s.theta[i + 1] - s.theta[i - 1]) / (2.0 * s.frame_time);
            // Velocity of the chord vs derivative of the angle agree to second order in Δt.
            assert!((fd - s.dtheta[i]).abs() < 0.05 * (1.0 + fd.abs()), "{fd} vs {}", s.dtheta[i]);
        }
    }
}
