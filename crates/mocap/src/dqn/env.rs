//! The keyframe MDP of §4.1. State: the window's motion, the current keyframe mask, each frame's
//! current reconstruction error and the budget left, K − |keys|. Action: make one non-key frame a
//! keyframe. Reward (Eq. 21–22): the change of the normalised relative error ε(s) = (E(s₀) − E(s)) /
//! E(s₀), where s₀ keeps only the first and last frame.
//!
//! The state is laid out per frame (`frames × INPUTS`): each frame's row describes that frame as a
//! candidate action, from quantities that mean the same on any skeleton and at any frame rate (errors
//! relative to the current E(s), speeds in m/s and rad/s). The Q-network reads every row with the
//! same weights (see [`super::model`]), so one policy serves windows of any length up to 64, any
//! skeleton and any K. Each row carries the candidate's exact one-step gain c(a,f) + c(f,b) − c(a,b)
//! (a, b: the keys around candidate f; c: a segment's cost), read from a table of segment costs:
//! filled once per window for training, filled on demand (only segments that start or end at a
//! key) when a policy selects. The last input of every row is E(s)/E(s₀), the scale of the rewards
//! still to come.

use crate::metrics::SegmentModel;
use crate::representation::{direction, SphericalMotion};
use crate::select::angle_segment_costs;
use crate::select::optimal::AngleFrames;
use crate::{MocapError, Result};
use glam::DVec3;

/// Frames on each side of a candidate whose mask and error its row carries.
pub const CONTEXT: usize = 2;
/// Per-frame motion descriptors (see [`motion_descriptors`]).
const MOTION_INPUTS: usize = 5;
/// Candidate's segment: distance to the previous and next key, the segment's share of E(s), its
/// largest frame error, where the candidate sits in it.
const SEGMENT_INPUTS: usize = 5;
/// One-step gain: the two halves' costs, the gain (all ÷ E(s)), the gain ÷ the window's best gain,
/// the segment's best gain ÷ the window's best.
const GAIN_INPUTS: usize = 5;
/// Episode: keys so far, budget left, budget left × the segment's share of the window, E(s)/E(s₀)
/// (last, see [`SCALE_INPUT`]).
const GLOBAL_INPUTS: usize = 4;
/// Inputs per frame row.
pub const INPUTS: usize = 3 * (2 * CONTEXT + 1) + SEGMENT_INPUTS + GAIN_INPUTS + MOTION_INPUTS + GLOBAL_INPUTS;
/// Index of E(s)/E(s₀) in a row: the Q-network scales its output by it.
pub const SCALE_INPUT: usize = INPUTS - 1;
/// Index of the candidate's one-step gain ÷ E(s) in a row: the Q-network learns a correction to it.
pub const GAIN_INPUT: usize = 3 * (2 * CONTEXT + 1) + SEGMENT_INPUTS + 2;
/// Largest window a mask can hold.
pub const MAX_FRAMES: usize = 64;

/// One training or test window, prepared for the network.
pub struct EnvWindow {
    frames_model: AngleFrames,
    n: usize,
    /// [`motion_descriptors`] of every frame.
    motion: Vec<[f32; MOTION_INPUTS]>,
    /// Every segment's cost (`n × n`), or None: computed on demand in [`StateScratch`].
    costs: Option<Vec<f64>>,
    /// E(s₀): the angle error sum with only the first and last frame as keys.
    pub e0: f64,
}

/// Buffers a state build reuses, and the on-demand segment costs of a window without a table.
#[derive(Clone, Debug, Default)]
pub struct StateScratch {
    term: Vec<f64>,
    buf: Vec<f64>,
    /// Per-frame errors under the current mask.
    pub errs: Vec<f64>,
    /// On-demand costs (NaN: not yet computed) of the window last prepared with [`EnvWindow::scratch`].
    lazy: Vec<f64>,
}

impl EnvWindow {
    /// A window with its whole segment-cost table (for training: every step is look-ups).
    pub fn new(rep: &SphericalMotion) -> Result<EnvWindow> {
        let mut w = Self::lazy(rep)?;
        w.costs = Some(angle_segment_costs(rep));
        Ok(w)
    }

    /// A window whose segment costs are computed when first needed (for selection).
    pub fn lazy(rep: &SphericalMotion) -> Result<EnvWindow> {
        let n = rep.num_frames;
        if !(3..=MAX_FRAMES).contains(&n) {
            return Err(MocapError::Model(format!("SIDQL takes windows of 3 to {MAX_FRAMES} frames, got {n}")));
        }
        if rep.angle_joint_count() == 0 {
            return Err(MocapError::Model("SIDQL needs a skeleton with at least one bone".into()));
        }
        let motion = (0..n).map(|f| motion_descriptors(rep, f)).collect();
        let frames_model = AngleFrames::new(rep);
        let mut s = rep.scratch();
        let e0 = rep.segment_cost(0, n - 1, &mut s).angle_sum;
        Ok(EnvWindow { frames_model, n, motion, costs: None, e0 })
    }

    pub fn frames(&self) -> usize {
        self.n
    }

    /// The full cost table, when the window has one.
    pub fn cost_table(&self) -> Option<&[f64]> {
        self.costs.as_deref()
    }

    /// Buffers for this window's states (on-demand costs reset).
    pub fn scratch(&self) -> StateScratch {
        StateScratch {
            term: vec![0.0; self.frames_model.joints()],
            buf: vec![0.0; self.n],
            errs: vec![0.0; self.n],
            lazy: if self.costs.is_some() { Vec::new() } else { vec![f64::NAN; self.n * self.n] },
        }
    }

    /// Makes `scratch` fit this window (windows of a training set share one).
    pub fn fit_scratch(&self, scratch: &mut StateScratch) {
        scratch.term.resize(scratch.term.len().max(self.frames_model.joints()), 0.0);
        scratch.buf.resize(scratch.buf.len().max(self.n), 0.0);
        scratch.errs.resize(scratch.errs.len().max(self.n), 0.0);
    }

    /// The cost of segment `(a, b)`.
    pub fn cost(&self, a: usize, b: usize, s: &mut StateScratch) -> f64 {
        let n = self.n;
        if let Some(c) = &self.costs {
            return c[a * n + b];
        }
        let slot = a * n + b;
        if s.lazy[slot].is_nan() {
            s.lazy[slot] = self.frames_model.segment(a, b, &mut s.buf, &mut s.term);
        }
        s.lazy[slot]
    }

    /// The starting mask: first and last frame.
    pub fn initial_mask(&self) -> u64 {
        1 | 1 << (self.frames() - 1)
    }

    /// Per-frame angle error under `mask` into `s.errs` and the total E(s) (the sum of its
    /// segments' costs, each summed in frame order: the numbers of [`SegmentModel::error`]).
    pub fn frame_errors(&self, mask: u64, s: &mut StateScratch) -> f64 {
        let n = self.n;
        s.errs[..n].iter_mut().for_each(|e| *e = 0.0);
        let mut total = 0.0;
        let mut a = 0;
        for b in (1..n).filter(|&f| mask >> f & 1 == 1) {
            if b > a + 1 {
                self.frames_model.eval(a, b, a + 1, b, &mut s.errs[a + 1..b], &mut s.term);
            }
            total += s.errs[a + 1..b].iter().fold(0.0, |acc, t| acc + t);
            a = b;
        }
        total
    }

    /// E(s) of `mask` from the cost table (the same number as [`EnvWindow::frame_errors`]).
    pub fn error(&self, mask: u64, s: &mut StateScratch) -> f64 {
        let mut total = 0.0;
        let mut a = 0;
        for b in (1..self.n).filter(|&f| mask >> f & 1 == 1) {
            total += self.cost(a, b, s);
            a = b;
        }
        total
    }

    /// Appends the state for `mask` with `budget` keys still to add (`frames × INPUTS`,
    /// frame-major) to `out`. Returns E(s).
    pub fn state(&self, mask: u64, budget: usize, s: &mut StateScratch, out: &mut Vec<f32>) -> f64 {
        let n = self.n;
        let total = self.frame_errors(mask, s);
        let e0 = self.e0.max(1e-12);
        // Errors relative to the current E(s), so the average frame is about 1 at every step: a
        // step late in an episode looks like an early one, only the reward scale differs.
        let now = total.max(1e-12 * e0);
        let is_key = |f: usize| mask >> f & 1 == 1;
        let rel = |e: f64| (e * n as f64 / now).min(50.0) as f32;
        // One-step gains of every candidate, and the best per segment and overall.
        let mut gains = [0.0f64; MAX_FRAMES];
        let mut halves = [(0.0f64, 0.0f64); MAX_FRAMES];
        let mut seg_of = [(0usize, 0usize); MAX_FRAMES];
        let mut best_in_seg = [0.0f64; MAX_FRAMES];
        let mut best = 0.0f64;
        let mut a = 0;
        for b in (1..n).filter(|&f| is_key(f)) {
            let whole = if b > a + 1 { self.cost(a, b, s) } else { 0.0 };
            let mut seg_best = 0.0f64;
            for f in a + 1..b {
                let (l, r) = (self.cost(a, f, s), self.cost(f, b, s));
                gains[f] = whole - l - r;
                halves[f] = (l, r);
                seg_of[f] = (a, b);
                seg_best = seg_best.max(gains[f]);
            }
            for slot in &mut best_in_seg[a + 1..b] {
                *slot = seg_best;
            }
            best = best.max(seg_best);
            seg_of[a] = (a, a);
            a = b;
        }
        seg_of[n - 1] = (n - 1, n - 1);
        let best = best.max(1e-12 * now);
        let keys = mask.count_ones() as f32;
        let progress = (total / e0) as f32;
        for f in 0..n {
            for d in -(CONTEXT as isize)..=CONTEXT as isize {
                match f.checked_add_signed(d).filter(|&g| g < n) {
                    Some(g) => out.extend_from_slice(&[is_key(g) as u8 as f32, rel(s.errs[g]), 0.0]),
                    None => out.extend_from_slice(&[0.0, 0.0, 1.0]),
                }
            }
            if is_key(f) {
                out.extend(std::iter::repeat_n(0.0, SEGMENT_INPUTS + GAIN_INPUTS));
            } else {
                let (a, b) = seg_of[f];
                let inner = &s.errs[a + 1..b];
                let seg_sum = inner.iter().sum::<f64>();
                let seg_max = inner.iter().copied().fold(0.0, f64::max);
                let (l, r) = halves[f];
                out.extend_from_slice(&[
                    (f - a) as f32 / 30.0,
                    (b - f) as f32 / 30.0,
                    (seg_sum / now) as f32,
                    rel(seg_max),
                    (f - a) as f32 / (b - a) as f32,
                    (l / now) as f32,
                    (r / now) as f32,
                    (gains[f] / now) as f32,
                    (gains[f] / best) as f32,
                    (best_in_seg[f] / best) as f32,
                ]);
            }
            out.extend_from_slice(&self.motion[f]);
            let (a, b) = seg_of[f];
            out.extend_from_slice(&[
                keys / 16.0,
                budget as f32 / 16.0,
                budget as f32 * (b - a) as f32 / (n - 1) as f32,
                progress,
            ]);
        }
        total
    }

    /// Reward of going from error `e_before` to `e_after` (Eq. 22).
    pub fn reward(&self, e_before: f64, e_after: f64) -> f32 {
        ((e_before - e_after) / self.e0.max(1e-12)) as f32
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
    let root_acc =
        if hi > lo { (rep.root_vel[hi] - rep.root_vel[lo]).length() / ((hi - lo) as f64 * dt) * metres } else { 0.0 };
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
    use inbetween_core::KeyframeSet;

    fn rep(frames: usize) -> SphericalMotion {
        let m = JointFilter::paper().apply(&gait(&GaitParams { frames, fps: 30.0, ..GaitParams::walk() }));
        SphericalMotion::from_motion(&m).unwrap()
    }

    const GAIN: usize = GAIN_INPUT - 2;

    #[test]
    fn state_rows_describe_each_candidate() {
        let w = EnvWindow::new(&rep(20)).unwrap();
        let mut s = w.scratch();
        let mut out = Vec::new();
        let e = w.state(w.initial_mask(), 7, &mut s, &mut out);
        assert_eq!(out.len(), 20 * INPUTS);
        assert!((e - w.e0).abs() < 1e-9 * w.e0.max(1.0), "the start state's error is E(s₀)");
        assert!(out.iter().all(|v| v.is_finite()));
        let row = |out: &[f32], f: usize| out[f * INPUTS..(f + 1) * INPUTS].to_vec();
        let centre = 3 * CONTEXT;
        // Frame 0 is a key with zero error; its left context lies outside the window.
        assert_eq!(&row(&out, 0)[centre..centre + 3], &[1.0, 0.0, 0.0]);
        assert_eq!(&row(&out, 0)[0..3], &[0.0, 0.0, 1.0]);
        // Frame 10 is 10 frames from the first key, 9 from the last, and its segment holds all of E(s₀).
        let seg = &row(&out, 10)[3 * (2 * CONTEXT + 1)..];
        assert_eq!((seg[0], seg[1]), (10.0 / 30.0, 9.0 / 30.0));
        assert!((seg[2] - 1.0).abs() < 1e-5);
        // The budget is in every row.
        assert_eq!(row(&out, 3)[INPUTS - 3], 7.0 / 16.0);
        // Adding a key at 10 splits it.
        let mut after = Vec::new();
        let e2 = w.state(w.initial_mask() | 1 << 10, 6, &mut s, &mut after);
        assert!(e2 < e);
        assert_eq!(after[10 * INPUTS + centre], 1.0);
        assert!(w.reward(e, e2) > 0.0);
    }

    /// The gain in each row is c(a,f) + c(f,b) − c(a,b) of the model's own segment costs, with
    /// and without a cost table, and E(s) is the model's error.
    #[test]
    fn one_step_gains_are_the_direct_segment_costs() {
        let r = rep(30);
        let (full, lazy) = (EnvWindow::new(&r).unwrap(), EnvWindow::lazy(&r).unwrap());
        let mask = full.initial_mask() | 1 << 9 | 1 << 20;
        let mut ms = r.scratch();
        let c = |a: usize, b: usize, ms: &mut crate::metrics::Scratch| r.segment_cost(a, b, ms).angle_sum;
        for w in [&full, &lazy] {
            let mut s = w.scratch();
            let mut out = Vec::new();
            let e = w.state(mask, 3, &mut s, &mut out);
            let keys = KeyframeSet::new(vec![9, 20], 30).unwrap();
            let want_e = r.error(&keys).mean_angle * (30 * r.angle_terms_per_frame()) as f64;
            assert!((e - want_e).abs() <= 1e-12 * want_e, "{e} vs {want_e}");
            assert_eq!(w.error(mask, &mut s).to_bits(), e.to_bits());
            for (f, (a, b)) in [(4, (0, 9)), (12, (9, 20)), (25, (20, 29))] {
                let direct = c(a, b, &mut ms) - c(a, f, &mut ms) - c(f, b, &mut ms);
                let got = out[f * INPUTS + GAIN + 2] as f64 * e;
                assert!((got - direct).abs() <= 1e-5 * direct.abs().max(1e-3 * e), "frame {f}: {got} vs {direct}");
                let left = out[f * INPUTS + GAIN] as f64 * e;
                assert!((left - c(a, f, &mut ms)).abs() <= 1e-5 * e, "frame {f}");
            }
            // The best candidate's gain reads 1 relative to the window's best.
            let best = (0..30).map(|f| out[f * INPUTS + GAIN + 3]).fold(f32::MIN, f32::max);
            assert!((best - 1.0).abs() < 1e-6, "{best}");
        }
    }

    #[test]
    fn rejects_windows_a_mask_cannot_hold() {
        assert!(EnvWindow::new(&rep(70)).is_err());
    }
}
