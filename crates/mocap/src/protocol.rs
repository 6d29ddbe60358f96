//! The paper's protocol (§5.1–5.4): clips resampled to 30 fps, cut into 60-frame windows on the
//! 23 major joints, split 80/20 by clip; SIDQL trains on windows of the training split (or of every
//! take), the bench scores every selector on both splits. Production code (training, the corpus)
//! and the bench share it from here.

use crate::corpus::Clip;
use crate::representation::{JointFilter, SphericalMotion};
use crate::Result;
use inbetween_core::units::LengthUnit;
use inbetween_core::Motion;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// The protocol's knobs; [`Protocol::paper`] gives §5.2's values.
#[derive(Clone, Debug)]
pub struct Protocol {
    pub fps: f64,
    pub window: usize,
    pub stride: usize,
    pub filter: JointFilter,
    /// Drop the first frame of every clip (the cgspeed T-pose).
    pub skip_first_frame: bool,
    pub train_fraction: f64,
    pub seed: u64,
}

impl Protocol {
    pub fn paper() -> Protocol {
        Protocol {
            fps: 30.0,
            window: 60,
            stride: 60,
            filter: JointFilter::paper(),
            skip_first_frame: true,
            train_fraction: 0.8,
            seed: 0,
        }
    }
}

/// One 60-frame window of a clip, in the paper's representation.
#[derive(Clone, Debug)]
pub struct Window {
    pub clip: String,
    pub start: usize,
    pub rep: SphericalMotion,
    /// The window as a clip (filtered joints, 30 fps), for the rotation reconstruction.
    pub motion: Motion,
}

/// Resamples, filters and windows one clip.
pub fn clip_windows(clip: &Clip, p: &Protocol) -> Result<Vec<Window>> {
    let (name, motion) = (&clip.name, &clip.motion);
    let m = if p.skip_first_frame && motion.num_frames() > 1 {
        motion.crop(1, motion.num_frames())?
    } else {
        motion.clone()
    };
    let m = p.filter.apply(&m.resample(p.fps)?);
    let mut out = Vec::new();
    let stride = p.stride.max(1);
    for (i, w) in m.windows(p.window, stride).into_iter().enumerate() {
        let mut rep = SphericalMotion::from_motion(&w)?;
        rep.cm_per_unit = clip.cm_per_unit;
        out.push(Window { clip: name.to_string(), start: i * stride, rep, motion: w });
    }
    Ok(out)
}

/// Splits clip names 80/20 (seeded shuffle; at least one clip on each side when there are two).
pub fn split_clips(names: &[String], p: &Protocol) -> (Vec<String>, Vec<String>) {
    let mut v = names.to_vec();
    v.sort();
    v.shuffle(&mut ChaCha8Rng::seed_from_u64(p.seed));
    let mut n_train = (v.len() as f64 * p.train_fraction).round() as usize;
    if v.len() >= 2 {
        n_train = n_train.clamp(1, v.len() - 1);
    }
    let test = v.split_off(n_train.min(v.len()));
    (v, test)
}

/// Windows of the named clips at `stride` frames (overlapping windows when `stride` is below the
/// window length: more training data for SIDQL), in the paper's representation.
pub fn training_windows(
    clips: &[Clip],
    names: &[String],
    protocol: &Protocol,
    stride: usize,
) -> Result<Vec<SphericalMotion>> {
    let p = Protocol { stride, ..protocol.clone() };
    let mut out = Vec::new();
    for clip in clips.iter().filter(|c| names.contains(&c.name)) {
        out.extend(clip_windows(clip, &p)?.into_iter().map(|w| w.rep));
    }
    Ok(out)
}

/// `count` procedural gaits (our own data, `inbetween_core::procedural::gait_library`: 241 frames
/// at 30 fps each, seeded) as clips in CMU units, named `gait0`, `gait1`, …
pub fn procedural_clips(seed: u64, count: usize) -> Vec<Clip> {
    inbetween_core::procedural::gait_library(seed, count, 241, 30.0)
        .into_iter()
        .enumerate()
        .map(|(i, m)| Clip {
            name: format!("gait{i}"),
            source: "procedural",
            motion: m,
            cm_per_unit: inbetween_core::procedural::CM_PER_CMU_UNIT,
        })
        .collect()
}

/// Which windows SIDQL trains on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrainingData {
    /// 24 procedural gaits (our own data).
    Procedural,
    /// The CMU training split of the bench protocol (its test split held out).
    CmuSplit,
    /// Every CMU take of the corpus (the committed policy; the bench's k-fold is its held-out score).
    CmuAll,
}

/// SIDQL's training windows and their description in words (written in the policy's card).
pub fn training_set(
    data_choice: TrainingData,
    data: Option<&Path>,
    unit: Option<LengthUnit>,
    seed: u64,
    stride: usize,
) -> Result<(Vec<SphericalMotion>, String)> {
    let protocol = Protocol { seed, ..Protocol::paper() };
    if data_choice == TrainingData::Procedural {
        let clips = procedural_clips(seed, 24);
        let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
        let p = Protocol { skip_first_frame: false, ..protocol };
        let windows = training_windows(&clips, &names, &p, stride)?;
        let data = format!(
            "{} procedural gaits (seed {seed}), {} windows of 60 frames at stride {stride}",
            clips.len(),
            windows.len()
        );
        return Ok((windows, data));
    }
    let dir = crate::corpus::data_dir(data)?;
    let clips = crate::corpus::load(&dir, unit)?.clips;
    let names: Vec<String> = clips.iter().map(|c| c.name.clone()).collect();
    if data_choice == TrainingData::CmuAll {
        let windows = training_windows(&clips, &names, &protocol, stride)?;
        let data = format!(
            "every CMU take of the corpus ({} takes), {} windows of 60 frames at stride {stride}",
            clips.len(),
            windows.len()
        );
        return Ok((windows, data));
    }
    let (train, test) = split_clips(&names, &protocol);
    let windows = training_windows(&clips, &train, &protocol, stride)?;
    let data = format!(
        "CMU training split (seed {seed}) {train:?}, {} windows of 60 frames at stride {stride}; test split {test:?} held out",
        windows.len()
    );
    Ok((windows, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_is_by_clip_and_seeded() {
        let names: Vec<String> = (0..10).map(|i| format!("clip{i}")).collect();
        let (train, test) = split_clips(&names, &Protocol::paper());
        assert_eq!((train.len(), test.len()), (8, 2));
        assert!(test.iter().all(|t| !train.contains(t)));
        assert_eq!(split_clips(&names, &Protocol::paper()), (train, test));
        let four: Vec<String> = (0..4).map(|i| format!("c{i}")).collect();
        let (tr, te) = split_clips(&four, &Protocol::paper());
        assert_eq!((tr.len(), te.len()), (3, 1));
    }

    #[test]
    fn training_windows_overlap_and_keep_only_the_named_clips() {
        let clips = procedural_clips(3, 3);
        let p = Protocol { skip_first_frame: false, ..Protocol::paper() };
        let names = vec!["gait0".to_string(), "gait2".to_string()];
        // 241 frames at stride 60: 4 windows each; at stride 10: (241 - 60) / 10 + 1 = 19 each.
        assert_eq!(training_windows(&clips, &names, &p, 60).unwrap().len(), 8);
        assert_eq!(training_windows(&clips, &names, &p, 10).unwrap().len(), 38);
        assert!(training_windows(&clips, &[], &p, 10).unwrap().is_empty());
    }
}
