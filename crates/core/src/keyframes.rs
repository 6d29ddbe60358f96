//! Keyframe sets: sorted, distinct frame indices of a clip that always include its first and last frame.

use crate::CoreError;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct KeyframeSet {
    frames: Vec<usize>,
    num_frames: usize,
}

impl KeyframeSet {
    /// Sorts and dedups `frames` and adds the first and last frame of an `num_frames`-long clip.
    pub fn new(mut frames: Vec<usize>, num_frames: usize) -> Result<KeyframeSet, CoreError> {
        if num_frames < 2 {
            return Err(CoreError::InvalidKeyframes(format!("a clip of {num_frames} frames has no segments")));
        }
        if let Some(&bad) = frames.iter().find(|&&f| f >= num_frames) {
            return Err(CoreError::InvalidKeyframes(format!(
                "keyframe {bad} is outside the clip's {num_frames} frames"
            )));
        }
        frames.push(0);
        frames.push(num_frames - 1);
        frames.sort_unstable();
        frames.dedup();
        Ok(KeyframeSet { frames, num_frames })
    }

    /// `k` keyframes spread as evenly as integer frames allow (the paper's UC baseline).
    pub fn uniform(num_frames: usize, k: usize) -> Result<KeyframeSet, CoreError> {
        if k < 2 || k > num_frames {
            return Err(CoreError::InvalidKeyframes(format!("{k} keyframes do not fit a clip of {num_frames} frames")));
        }
        let last = (num_frames - 1) as f64;
        let frames = (0..k).map(|i| (i as f64 * last / (k - 1) as f64).round() as usize).collect();
        KeyframeSet::new(frames, num_frames)
    }

    pub fn frames(&self) -> &[usize] {
        &self.frames
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    pub fn num_frames(&self) -> usize {
        self.num_frames
    }

    pub fn contains(&self, frame: usize) -> bool {
        self.frames.binary_search(&frame).is_ok()
    }

    /// Adds a keyframe; returns false when it was already present or out of range.
    pub fn insert(&mut self, frame: usize) -> bool {
        if frame >= self.num_frames {
            return false;
        }
        match self.frames.binary_search(&frame) {
            Ok(_) => false,
            Err(i) => {
                self.frames.insert(i, frame);
                true
            }
        }
    }

    /// Consecutive keyframe pairs `(a, b)`, each a segment to in-between.
    pub fn segments(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.frames.windows(2).map(|w| (w[0], w[1]))
    }

    /// Boolean mask over all frames (the SIDQL state's keyframe part).
    pub fn mask(&self) -> Vec<bool> {
        let mut m = vec![false; self.num_frames];
        for &f in &self.frames {
            m[f] = true;
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn always_has_ends_and_is_sorted() {
        let k = KeyframeSet::new(vec![7, 3, 7], 10).unwrap();
        assert_eq!(k.frames(), &[0, 3, 7, 9]);
        assert_eq!(k.segments().collect::<Vec<_>>(), vec![(0, 3), (3, 7), (7, 9)]);
        assert!(KeyframeSet::new(vec![10], 10).is_err());
        assert!(KeyframeSet::new(vec![], 1).is_err());
    }

    #[test]
    fn uniform_spreads_keys() {
        let k = KeyframeSet::uniform(60, 5).unwrap();
        assert_eq!(k.frames(), &[0, 15, 30, 44, 59]);
        assert_eq!(KeyframeSet::uniform(60, 10).unwrap().len(), 10);
        assert!(KeyframeSet::uniform(5, 6).is_err());
    }
}
