//! Keys as a DCC holds them (beyond the paper): per key and channel a value and two Bezier handles
//! such that the DCC's own curve evaluation plays back [`RotationCurve::QuaternionBezier`](crate::rotations::RotationCurve::QuaternionBezier) exactly.
//!
//! A cubic Bezier F-curve whose handles lie a third of the way along each segment in time,
//! `(t_k ± h/3, p_k ± m_k·h/3)` with `m_k` the value's rate at the key, is linear in time and so is
//! the cubic Hermite through both keys with those rates (the form of Eq. 12–13). Four such curves
//! on a quaternion's components, normalised by the DCC, are the engine's component curve; three on
//! a translation are its translation Hermite. Handles use each side's own segment length, so keys
//! with gaps of different lengths on either side keep one slope (aligned, unequal handles: a DCC's
//! "free" or "aligned" handle type, never "auto", which would move them).
//!
//! Euler curves ([`RotationCurve::EulerBezier`](crate::rotations::RotationCurve::EulerBezier)) are
//! three such curves per joint on its angles, with the angles' rates as slopes: the DCC composes
//! `pre ⊗ R(E)` from the values it evaluates, which is the engine's Euler curve.

use crate::rotations::{euler_by_axis, quat_component_rate, EulerKeys, KeyPose};
use crate::{MocapError, Result};

/// One channel's key: the value and its left and right handles' values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BezierKey<const N: usize> {
    pub value: [f64; N],
    pub left: [f64; N],
    pub right: [f64; N],
}

/// Bezier keys for every joint at every key frame.
#[derive(Clone, Debug)]
pub struct BezierKeys {
    /// Key frames (the clip's frame numbers, 0-based).
    pub frames: Vec<usize>,
    /// Where each key's left and right handles lie in time, frames (fractional). The first key's
    /// left and the last key's right handle mirror their one segment; they shape nothing.
    pub left_frames: Vec<f64>,
    pub right_frames: Vec<f64>,
    /// `[key][joint]` quaternion components (x, y, z, w), signs continuous along each joint's track
    /// as the engine interpolates them.
    pub rotations: Vec<Vec<BezierKey<4>>>,
    /// `[key][joint]` translations in the clip's length unit.
    pub translations: Vec<Vec<BezierKey<3>>>,
    /// `[key][joint]` Euler angles `(x, y, z)` by axis (a DCC's X, Y and Z rotation curves), radians,
    /// continuous along each joint's track; NaN for joints without an Euler order; empty without
    /// Euler keys.
    pub euler: Vec<Vec<BezierKey<3>>>,
}

/// The Bezier keys that play back `keys` (the key poses at `frames`, as
/// [`crate::SelectReport::key_poses`] gives them) along [`RotationCurve::QuaternionBezier`](crate::rotations::RotationCurve::QuaternionBezier) on a
/// clip of `frame_time` seconds per frame; with `euler` (the keys' Euler keys,
/// [`crate::SelectReport::key_euler`]) also the Euler curves that play
/// [`RotationCurve::EulerBezier`](crate::rotations::RotationCurve::EulerBezier).
pub fn bezier_keys(
    frames: &[usize],
    keys: &[KeyPose],
    euler: Option<&EulerKeys>,
    frame_time: f64,
) -> Result<BezierKeys> {
    if frames.len() < 2 || frames.len() != keys.len() || frames.windows(2).any(|w| w[0] >= w[1]) {
        return Err(MocapError::Invalid(format!(
            "{} key frames for {} key poses: expected at least 2 increasing frames, one per pose",
            frames.len(),
            keys.len()
        )));
    }
    if !(frame_time.is_finite() && frame_time > 0.0) {
        return Err(MocapError::Invalid(format!("frame time {frame_time} s: expected a positive number of seconds")));
    }
    if let Some(e) = euler {
        if e.keys.len() != keys.len() {
            return Err(MocapError::Invalid(format!(
                "{} Euler keys for {} key poses: expected one per key",
                e.keys.len(),
                keys.len()
            )));
        }
    }
    let last = frames.len() - 1;
    // Each side's segment, frames: the first and last keys mirror their one segment.
    let gap = |a: usize, b: usize| (frames[b] - frames[a]) as f64;
    let before: Vec<f64> = (0..=last).map(|k| if k == 0 { gap(0, 1) } else { gap(k - 1, k) }).collect();
    let after: Vec<f64> = (0..=last).map(|k| if k == last { gap(last - 1, last) } else { gap(k, k + 1) }).collect();
    let handle = |value: &[f64], rate: &[f64], k: usize, out: (&mut [f64], &mut [f64])| {
        // Rates are per second; a third of the side's segment, in seconds.
        let (l, r) = (before[k] * frame_time / 3.0, after[k] * frame_time / 3.0);
        for i in 0..value.len() {
            out.0[i] = value[i] - rate[i] * l;
            out.1[i] = value[i] + rate[i] * r;
        }
    };
    let mut rotations = Vec::with_capacity(keys.len());
    let mut translations = Vec::with_capacity(keys.len());
    for (k, key) in keys.iter().enumerate() {
        let rot = key
            .rotations
            .iter()
            .zip(&key.angular_velocities)
            .map(|(&q, &w)| {
                let d = quat_component_rate(q, w);
                let (value, rate) = (q.to_array(), d.to_array());
                let mut b = BezierKey { value, left: [0.0; 4], right: [0.0; 4] };
                handle(&value, &rate, k, (&mut b.left, &mut b.right));
                b
            })
            .collect();
        let trans = key
            .translations
            .iter()
            .zip(&key.velocities)
            .map(|(&p, &v)| {
                let (value, rate) = (p.to_array(), v.to_array());
                let mut b = BezierKey { value, left: [0.0; 3], right: [0.0; 3] };
                handle(&value, &rate, k, (&mut b.left, &mut b.right));
                b
            })
            .collect();
        rotations.push(rot);
        translations.push(trans);
    }
    let euler = match euler {
        None => Vec::new(),
        Some(e) => e
            .keys
            .iter()
            .enumerate()
            .map(|(k, row)| {
                row.iter()
                    .zip(&e.orders)
                    .map(|(key, order)| match order {
                        Some(o) => {
                            let (value, rate) =
                                (euler_by_axis(*o, key.angles).to_array(), euler_by_axis(*o, key.rates).to_array());
                            let mut b = BezierKey { value, left: [0.0; 3], right: [0.0; 3] };
                            handle(&value, &rate, k, (&mut b.left, &mut b.right));
                            b
                        }
                        None => BezierKey { value: [f64::NAN; 3], left: [f64::NAN; 3], right: [f64::NAN; 3] },
                    })
                    .collect()
            })
            .collect(),
    };
    Ok(BezierKeys {
        frames: frames.to_vec(),
        left_frames: (0..=last).map(|k| frames[k] as f64 - before[k] / 3.0).collect(),
        right_frames: (0..=last).map(|k| frames[k] as f64 + after[k] / 3.0).collect(),
        rotations,
        translations,
        euler,
    })
}

/// A cubic Bezier's value at `frame` between control points `(x0, y0) … (x3, y3)`, found the way a
/// DCC does: solve x(s) = frame for the curve parameter, then evaluate y(s). (Tests and the bench
/// check the handles against it; a DCC has its own.)
pub fn eval_bezier(x: [f64; 4], y: [f64; 4], frame: f64) -> f64 {
    let bez = |c: [f64; 4], s: f64| {
        let t = 1.0 - s;
        t * t * t * c[0] + 3.0 * t * t * s * c[1] + 3.0 * t * s * s * c[2] + s * s * s * c[3]
    };
    // Bisection: x(s) increases on [0, 1] for handles inside their segment.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if bez(x, mid) < frame {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    bez(y, 0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepared::PreparedClip;
    use crate::rotations::{reconstruct_poses, RotationCurve};
    use crate::select::job::{SelectJob, Selector};
    use inbetween_core::cancel::Cancel;
    use inbetween_core::procedural::{gait, GaitParams};
    use inbetween_io::Progress;

    #[test]
    #[allow(clippy::needless_range_loop)] // f is a frame number and an index
    fn a_dccs_bezier_evaluation_of_the_handles_is_the_engines_quaternion_bezier_curve() {
        let motion = gait(&GaitParams { frames: 90, ..GaitParams::walk() });
        let clip = PreparedClip::inferred(motion).unwrap();
        let job = SelectJob {
            method: Selector::ErrorBounded,
            bound_cm: Some(1.0),
            curve: RotationCurve::QuaternionBezier,
            ..SelectJob::default()
        };
        let report = job.run(&clip, &Cancel::new(), &Progress::hidden()).unwrap();
        // The bound holds on the rebuilt clip along the DCC curve.
        assert!(report.reconstruction.error.max_cm <= 1.0 + 1e-9, "{}", report.reconstruction.error.max_cm);
        let frames = report.keys().frames().to_vec();
        let bz = bezier_keys(&frames, &report.key_poses, None, clip.motion.frame_time).unwrap();
        let poses = reconstruct_poses(
            &clip.motion.skeleton,
            clip.motion.frame_time,
            &frames,
            &report.key_poses,
            RotationCurve::QuaternionBezier,
            None,
        )
        .unwrap();
        let mut worst = 0.0f64;
        for s in 0..frames.len() - 1 {
            let x = [frames[s] as f64, bz.right_frames[s], bz.left_frames[s + 1], frames[s + 1] as f64];
            for f in frames[s]..=frames[s + 1] {
                for j in 0..clip.motion.skeleton.len() {
                    let (a, b) = (&bz.rotations[s][j], &bz.rotations[s + 1][j]);
                    let q: Vec<f64> = (0..4)
                        .map(|i| eval_bezier(x, [a.value[i], a.right[i], b.left[i], b.value[i]], f as f64))
                        .collect();
                    let q = glam::DQuat::from_xyzw(q[0], q[1], q[2], q[3]).normalize();
                    let want = poses[f].rotations[j];
                    worst = worst.max(1.0 - q.dot(want).abs());
                    let (a, b) = (&bz.translations[s][j], &bz.translations[s + 1][j]);
                    for i in 0..3 {
                        let t = eval_bezier(x, [a.value[i], a.right[i], b.left[i], b.value[i]], f as f64);
                        assert!((t - poses[f].translations[j].to_array()[i]).abs() < 1e-6, "frame {f} joint {j}");
                    }
                }
            }
        }
        assert!(worst < 1e-10, "1 - |q·q'| up to {worst}");
        assert!(bz.left_frames[1] < frames[1] as f64 && bz.right_frames[1] > frames[1] as f64);
    }

    #[test]
    fn mismatched_keys_are_refused() {
        let err = bezier_keys(&[0, 5], &[], None, 0.01).unwrap_err().to_string();
        assert!(err.contains("2 key frames for 0 key poses"), "{err}");
    }
}
