//! The keyframe MDP of §4.1. State: the window's motion, the current keyframe mask and each frame's
//! current reconstruction error (a function of the mask, given to the network so it need not learn
//! the reconstruction). Action: make one non-key frame a keyframe. Reward (Eq. 21–22): the change of
//! the normalised relative error ε(s) = (E(s₀) − E(s)) / E(s₀), where s₀ keeps only the first and last
//! frame; ε reaches 1 when every frame is a key.
//!
//! The state is laid out per frame (`frames × INPUTS`): each frame's row describes that frame as a
//! candidate action, from quantities that mean the same on any skeleton and at any frame rate (errors
//! relative to the current E(s), speeds in m/s and rad/s). The Q-network reads every row with the
//! same weights (see [`super::model`]), so one policy serves windows of any length up to 64 and any
//! skeleton. The last input of every row is E(s)/E(s₀), the scale of the rewards still to come.

use crate::error::{Scratch, SegmentModel};
use crate::representation::{direction, SphericalMotion};
use crate::{MocapError, Result};
use glam::DVec3;

/// Frames on each side of a candidate whose mask and error its row carries.
pub const CONTEXT: usize = 4;
/// Per-frame motion descriptors (see [`motion_descriptors`]).
const MOTION_INPUTS: usize = 5;
/// Candidate's segment: distance to the previous and next key, the segment's share of E(s₀), its
/// largest frame error, whether the candidate is a key already.
const SEGMENT_INPUTS: usize = 5;
/// Episode progress: keys so far, current E(s)/E(s₀) (last, see [`SCALE_INPUT`]).
const GLOBAL_INPUTS: usize = 2;
/// Inputs per frame row.
pub const INPUTS: usize = 3 * (2 * CONTEXT + 1) + SEGMENT_INPUTS + MOTION_INPUTS + GLOBAL_INPUTS;
/// Index of E(s)/E(s₀) in a row: the Q-network scales its output by it.
pub const SCALE_INPUT: usize = INPUTS - 1;
/// Largest window a mask can hold.
pub const MAX_FRAMES: usize = 64;

/// One training or test window, prepared for the network.
pub struct EnvWindow {
    pub rep: SphericalMotion,
    /// [`motion_descriptors`] of every frame.
    motion: Vec<[f32; MOTION_INPUTS]>,
    /// E(s₀): the angle error sum with only the first and last frame as keys.
    pub e0: f64,
}

impl EnvWindow {
    pub fn new(rep: SphericalMotion) -> Result<EnvWindow> {
        let n = rep.num_frames;
        if !(3..=MAX_FRAMES).contains(&n) {
            return Err(MocapError::Model(format!("SIDQL takes windows of 3 to {MAX_FRAMES} frames, got {n}")));
        }
        if rep.angle_joint_count() == 0 {
            return Err(MocapError::Model("SIDQL needs a skeleton with at least one bone".into()));
        }
        let motion = (0..n).map(|f| motion_descriptors(&rep, f)).collect();
        let mut s = rep.scratch();
        let e0 = rep.segment_cost(0, n - 1, &mut s).angle_sum;
        Ok(EnvWindow { rep, motion, e0 })
    }

    pub fn frames(&self) -> usize {
        self.rep.num_frames
    }

    /// The starting mask: first and last frame.
    pub fn initial_mask(&self) -> u64 {
        1 | 1 << (self.frames() - 1)
    }

    /// Per-frame angle error under `mask` and the total E(s).
    pub fn frame_errors(&self, mask: u64, scratch: &mut Scratch, out: &mut [f64]) -> f64 {
        let n = self.frames();
        let keys: Vec<usize> = (0..n).filter(|&f| mask >> f & 1 == 1).collect();
        out.iter_mut().for_each(|e| *e = 0.0);
        let mut total = 0.0;
        for w in keys.windows(2) {
            for (f, slot) in out.iter_mut().enumerate().take(w[1]).skip(w[0] + 1) {
                *slot = self.rep.frame_cost(w[0], w[1], f, scratch).angle_sum;
                total += *slot;
            }
        }
        total
    }

    /// Appends the state for `mask` (`frames × INPUTS`, frame-major) to `out`. Returns E(s).
    pub fn state(&self, mask: u64, scratch: &mut Scratch, out: &mut Vec<f32>) -> f64 {
        let n = self.frames();
        let mut errs = vec![0.0; n];
        let total = self.frame_errors(mask, scratch, &mut errs);
        let e0 = self.e0.max(1e-12);
        // Errors relative to the current E(s), so the average frame is about 1 at every step: a
        // step late in an episode looks like an early one, only the reward scale differs.
        let now = total.max(1e-12 * e0);
        let rel: Vec<f32> = errs.iter().map(|e| (e * n as f64 / now).min(50.0) as f32).collect();
        let is_key = |f: usize| mask >> f & 1 == 1;
        let keys = mask.count_ones() as f32;
        let progress = (total / e0) as f32;
        let (mut prev, mut seg) = (0usize, Segment::default());
        for f in 0..n {
            if is_key(f) {
                prev = f;
            }
            if f == prev {
                let next = (f + 1..n).find(|&g| is_key(g)).unwrap_or(f);
                seg = Segment::of(&errs, prev, next, now);
            }
            for d in -(CONTEXT as isize)..=CONTEXT as isize {
                match f.checked_add_signed(d).filter(|&g| g < n) {
                    Some(g) => out.extend_from_slice(&[is_key(g) as u8 as f32, rel[g], 0.0]),
                    None => out.extend_from_slice(&[0.0, 0.0, 1.0]),
                }
            }
            let key_here = is_key(f);
            let (to_prev, to_next) = if key_here { (0, 0) } else { (f - seg.start, seg.end - f) };
            out.extend_from_slice(&[
                to_prev as f32 / 30.0,
                to_next as f32 / 30.0,
                if key_here { 0.0 } else { seg.share },
                if key_here { 0.0 } else { seg.max_rel },
                key_here as u8 as f32,
            ]);
            out.extend_from_slice(&self.motion[f]);
            out.extend_from_slice(&[keys / 16.0, progress]);
        }
        total
    }

    /// Reward of going from error `e_before` to `e_after` (Eq. 22).
    pub fn reward(&self, e_before: f64, e_after: f64) -> f32 {
        ((e_before - e_after) / self.e0.max(1e-12)) as f32
    }
}

/// The keys around a run of in-between frames and what that run costs now.
#[derive(Default, Clone, Copy)]
struct Segment {
    start: usize,
    end: usize,
    /// The segment's error as a share of E(s).
    share: f32,
    /// Its worst frame, scaled like the per-frame errors.
    max_rel: f32,
}

impl Segment {
    fn of(errs: &[f64], start: usize, end: usize, total: f64) -> Segment {
        let inner = &errs[(start + 1).min(end)..end];
        let sum: f64 = inner.iter().sum();
        let max = inner.iter().copied().fold(0.0, f64::max);
        Segment {
            start,
            end,
            share: (sum / total) as f32,
            max_rel: (max * errs.len() as f64 / total).min(50.0) as f32,
        }
    }
}

/// How the body moves at frame `f`, in units that mean the same on any skeleton: root speed (m/s),
/// mean and largest bone angular speed (rad/s, ÷10), mean bone angular acceleration (rad/s², ÷100)
/// and root acceleration (m/s², ÷10). Accelerations are what a cubic between far keys misses.
pub fn motion_descriptors(rep: &SphericalMotion, f: usize) -> [f32; MOTION_INPUTS] {
    let n = rep.num_frames;
    let dt = rep.frame_time.max(1e-9);
    let metres = rep.cm_per_unit / 100.0;
    let (lo, hi) = (f.saturating_sub(1), (f + 1).min(n - 1));
    let root_speed = rep.root_vel[f].length() * metres;
    let root_acc = if hi > lo {
        (rep.root_vel[hi] - rep.root_vel[lo]).length() / ((hi - lo) as f64 * dt) * metres
    } else {
        0.0
    };
    let (mut sum_w, mut max_w, mut sum_a, mut bones) = (0.0, 0.0f64, 0.0, 0usize);
    let dir = |j: usize, g: usize| -> DVec3 { direction(rep.theta[j * n + g], rep.phi[j * n + g]) };
    for j in (0..rep.num_joints).filter(|&j| rep.has_angles[j]) {
        let i = j * n + f;
        let w = (rep.dtheta[i].powi(2) + (rep.theta[i].sin() * rep.dphi[i]).powi(2)).sqrt();
        sum_w += w;
        max_w = max_w.max(w);
        if f > 0 && f + 1 < n {
            sum_a += (dir(j, f + 1) - 2.0 * dir(j, f) + dir(j, f - 1)).length() / (dt * dt);
        }
        bones += 1;
    }
    let b = bones.max(1) as f64;
    [
        root_speed.min(20.0) as f32,
        (sum_w / b / 10.0).min(10.0) as f32,
        (max_w / 10.0).min(10.0) as f32,
        (sum_a / b / 100.0).min(10.0) as f32,
        (root_acc / 10.0).min(10.0) as f32,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::representation::JointFilter;
    use inbetween_core::procedural::{gait, GaitParams};

    fn window(frames: usize) -> EnvWindow {
        let m = JointFilter::paper().apply(&gait(&GaitParams { frames, fps: 30.0, ..GaitParams::walk() }));
        EnvWindow::new(SphericalMotion::from_motion(&m).unwrap()).unwrap()
    }

    #[test]
    fn state_rows_describe_each_candidate() {
        let w = window(20);
        let mut s = w.rep.scratch();
        let mut out = Vec::new();
        let e = w.state(w.initial_mask(), &mut s, &mut out);
        assert_eq!(out.len(), 20 * INPUTS);
        assert!((e - w.e0).abs() < 1e-9 * w.e0.max(1.0), "the start state's error is E(s₀)");
        assert!(out.iter().all(|v| v.is_finite()));
        let row = |f: usize| &out[f * INPUTS..(f + 1) * INPUTS];
        let centre = 3 * CONTEXT;
        // Frame 0 is a key with zero error; its left context lies outside the window.
        assert_eq!(&row(0)[centre..centre + 3], &[1.0, 0.0, 0.0]);
        assert_eq!(&row(0)[0..3], &[0.0, 0.0, 1.0]);
        // Frame 10 is 10 frames from either key and its segment holds all of E(s₀).
        let seg = &row(10)[3 * (2 * CONTEXT + 1)..];
        assert_eq!(seg[0], 10.0 / 30.0);
        assert_eq!(seg[1], 9.0 / 30.0);
        assert!((seg[2] - 1.0).abs() < 1e-5);
        // Adding a key at 10 splits it.
        let mut after = Vec::new();
        let e2 = w.state(w.initial_mask() | 1 << 10, &mut s, &mut after);
        assert!(e2 < e);
        assert_eq!(after[10 * INPUTS + centre], 1.0);
        assert!(w.reward(e, e2) > 0.0);
    }

    #[test]
    fn rejects_windows_a_mask_cannot_hold() {
        let m = JointFilter::paper().apply(&gait(&GaitParams { frames: 70, fps: 30.0, ..GaitParams::walk() }));
        assert!(EnvWindow::new(SphericalMotion::from_motion(&m).unwrap()).is_err());
    }
}
