//! The keyframe MDP of §4.1. State: the window's motion features, the current keyframe mask and
//! each frame's current reconstruction error (a function of the mask, given to the network so it
//! need not learn the reconstruction). Action: make one non-key frame a keyframe. Reward (Eq. 21–22):
//! the change of the normalised relative error ε(s) = (E(s₀) − E(s)) / E(s₀), where s₀ keeps only the
//! first and last frame; ε reaches 1 when every frame is a key.

use crate::error::{Scratch, SegmentModel};
use crate::representation::SphericalMotion;
use crate::{MocapError, Result};

/// One training or test window, prepared for the network.
pub struct EnvWindow {
    pub rep: SphericalMotion,
    /// Motion features, frame-major, `frames × features_per_frame`.
    pub features: Vec<f32>,
    /// E(s₀): the angle error sum with only the first and last frame as keys.
    pub e0: f64,
}

impl EnvWindow {
    pub fn new(rep: SphericalMotion, frames: usize, features_per_frame: usize) -> Result<EnvWindow> {
        if rep.num_frames != frames || rep.num_frames > 64 {
            return Err(MocapError::Model(format!(
                "the network takes {frames}-frame windows (≤ 64), got {}",
                rep.num_frames
            )));
        }
        let mut features = Vec::with_capacity(frames * features_per_frame);
        for f in 0..frames {
            rep.frame_features(f, &mut features);
        }
        if features.len() != frames * features_per_frame {
            return Err(MocapError::Model(format!(
                "the network takes {} features per frame ({} joints), this window has {} ({} joints)",
                features_per_frame,
                features_per_frame / 4,
                features.len() / frames,
                rep.num_joints
            )));
        }
        let mut s = rep.scratch();
        let e0 = rep.segment_cost(0, frames - 1, &mut s).angle_sum;
        Ok(EnvWindow { rep, features, e0 })
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

    /// The state vector for `mask`: features, mask, normalised per-frame error. Returns E(s).
    pub fn state(&self, mask: u64, scratch: &mut Scratch, out: &mut Vec<f32>) -> f64 {
        let n = self.frames();
        let mut errs = vec![0.0; n];
        let total = self.frame_errors(mask, scratch, &mut errs);
        out.extend_from_slice(&self.features);
        out.extend((0..n).map(|f| (mask >> f & 1) as f32));
        // Scaled so that the average frame under s₀ is about 1.
        let scale = n as f64 / self.e0.max(1e-12);
        out.extend(errs.iter().map(|e| (e * scale).min(20.0) as f32));
        total
    }

    /// Reward of going from error `e_before` to `e_after` (Eq. 22).
    pub fn reward(&self, e_before: f64, e_after: f64) -> f32 {
        ((e_before - e_after) / self.e0.max(1e-12)) as f32
    }
}
