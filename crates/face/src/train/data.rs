//! Training batches (§3.1): windows of clips at the model rate with a random mask, the constraint of
//! the network's kind, and noise, laid out by [`crate::model::input`].
//!
//! Clips come as [`TrainClip`]s in a [`ClipPool`]: procedural clips carry their viseme labels, real
//! captures (Live Link Face CSV read with [`crate::data::read_live_link`]) have none, so they train
//! every network but the viseme one. Every random choice of a batch draws from the seed it is given
//! (a training step's seed), one stream per sample, so a resumed run draws the same batches.

use burn::tensor::{Device, Tensor, TensorData};
use inbetween_core::seed::{derive, rng};
use inbetween_nn::burn;
use rand::Rng;

use crate::data::{BlendshapeClip, FaceError, MODEL_FPS, NUM_ARKIT};
use crate::edit::constraints::{noisy_guide, sample_keyframes, TrackerNoise};
use crate::edit::mask::{random_mask, MaskSampling};
use crate::edit::{Constraint, ConstraintKind, Frame};
use crate::model::input::{assemble_into, input_dim, noise};
use crate::visemes::Viseme;

/// One training clip at [`MODEL_FPS`]: its ARKit frames and, when known, the viseme of every frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainClip {
    pub frames: Vec<Frame>,
    pub visemes: Option<Vec<Viseme>>,
}

impl TrainClip {
    /// The ARKit weights of `clip` (resampled to [`MODEL_FPS`] first when its rate differs), with
    /// `visemes` per frame at the model rate when known.
    pub fn from_clip(clip: &BlendshapeClip, visemes: Option<Vec<Viseme>>) -> Result<TrainClip, FaceError> {
        let resampled;
        let clip = if (clip.fps() - MODEL_FPS).abs() > 1e-9 {
            resampled = clip.resample(MODEL_FPS)?;
            &resampled
        } else {
            clip
        };
        let frames: Vec<Frame> = (0..clip.num_frames())
            .map(|f| {
                let mut frame = [0.0; NUM_ARKIT];
                frame.copy_from_slice(clip.arkit(f));
                frame
            })
            .collect();
        if let Some(v) = &visemes {
            if v.len() != frames.len() {
                return Err(FaceError::Invalid(format!(
                    "{} viseme labels for a clip of {} frames at {MODEL_FPS} fps",
                    v.len(),
                    frames.len()
                )));
            }
        }
        Ok(TrainClip { frames, visemes })
    }
}

/// The clips a network trains on, and where they came from (written in the weights card).
#[derive(Clone, Debug)]
pub struct ClipPool {
    pub clips: Vec<TrainClip>,
    /// Where the clips came from, in words (e.g. "procedural, 64 clips × 20 s, seed 3").
    pub description: String,
}

impl ClipPool {
    pub fn new(clips: Vec<TrainClip>, description: impl Into<String>) -> ClipPool {
        ClipPool { clips, description: description.into() }
    }

    /// `n_clips` procedural clips of `duration_s` seconds with their viseme labels
    /// ([`crate::procedural::generate_corpus`]).
    pub fn procedural(n_clips: usize, duration_s: f64, seed: u64) -> Result<ClipPool, FaceError> {
        let clips = crate::procedural::generate_corpus(n_clips, duration_s, seed)
            .into_iter()
            .map(|p| TrainClip::from_clip(&p.clip, Some(p.visemes)))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(ClipPool::new(clips, format!("procedural, {n_clips} clips × {duration_s} s, seed {seed}")))
    }

    /// Live Link Face captures (resampled to [`MODEL_FPS`], no viseme labels); errors name the file.
    pub fn live_link(paths: &[std::path::PathBuf]) -> Result<ClipPool, FaceError> {
        let clips = paths
            .iter()
            .map(|p| TrainClip::from_clip(&crate::data::read_live_link(p)?, None))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(ClipPool::new(clips, format!("{} Live Link Face captures", paths.len())))
    }

    /// Clips usable for `kind` with windows of `window` frames: long enough, and labelled with
    /// visemes for the viseme network. Errors say why none is.
    pub fn usable(&self, kind: ConstraintKind, window: usize) -> Result<Vec<usize>, String> {
        let usable: Vec<usize> = (0..self.clips.len())
            .filter(|&i| {
                let c = &self.clips[i];
                c.frames.len() >= window && (kind != ConstraintKind::Visemes || c.visemes.is_some())
            })
            .collect();
        if usable.is_empty() {
            let labelled = if kind == ConstraintKind::Visemes { " with viseme labels" } else { "" };
            return Err(format!(
                "{}: no clip{labelled} holds a {window}-frame window ({} clips, longest {} frames)",
                self.description,
                self.clips.len(),
                self.clips.iter().map(|c| c.frames.len()).max().unwrap_or(0)
            ));
        }
        Ok(usable)
    }
}

/// How batches are drawn.
#[derive(Clone, Debug)]
pub struct SamplerConfig {
    /// The network's constraint kind.
    pub kind: ConstraintKind,
    /// Frames per window.
    pub window: usize,
    /// Windows per batch.
    pub batch: usize,
    /// Masks (§3.1).
    pub mask: MaskSampling,
    /// Noise of the noisy guide (§4.3.2).
    pub tracker: TrackerNoise,
}

/// A batch in plain memory: `batch` windows of `window` frames.
#[derive(Clone, Debug, PartialEq)]
pub struct HostBatch {
    pub batch: usize,
    pub window: usize,
    /// Input features per frame.
    pub d_input: usize,
    /// `[window][batch][d_input]`: step-major, so each frame is one contiguous `[batch, d_input]`.
    pub inputs: Vec<f32>,
    /// `[batch][window][52]` ground truth.
    pub target: Vec<f32>,
    /// `[batch][window][52]`, 1 where erased.
    pub mask: Vec<f32>,
}

/// A batch on a device: one `[batch, d_input]` tensor per frame, target and mask `[batch, window, 52]`.
#[derive(Clone, Debug)]
pub struct Batch {
    pub inputs: Vec<Tensor<2>>,
    pub target: Tensor<3>,
    pub mask: Tensor<3>,
}

impl HostBatch {
    /// The batch as tensors on `device`.
    pub fn to_device(&self, device: &Device) -> Batch {
        let step = self.batch * self.d_input;
        let inputs = (0..self.window)
            .map(|t| {
                let v = self.inputs[t * step..(t + 1) * step].to_vec();
                Tensor::from_data(TensorData::new(v, [self.batch, self.d_input]), device)
            })
            .collect();
        let shape = [self.batch, self.window, NUM_ARKIT];
        Batch {
            inputs,
            target: Tensor::from_data(TensorData::new(self.target.clone(), shape), device),
            mask: Tensor::from_data(TensorData::new(self.mask.clone(), shape), device),
        }
    }
}

/// One training window: truth, mask, constraint and noise, then the network input.
struct Sample {
    truth: Vec<Frame>,
    mask: crate::edit::Mask,
    input: Vec<f32>,
}

fn draw_sample(pool: &ClipPool, usable: &[usize], cfg: &SamplerConfig, seed: u64) -> Sample {
    let mut r = rng(seed);
    // A clip with probability proportional to its number of windows, then a window in it.
    let counts: Vec<usize> = usable.iter().map(|&i| pool.clips[i].frames.len() + 1 - cfg.window).collect();
    let mut pick = r.random_range(0..counts.iter().sum::<usize>());
    let mut which = 0;
    while pick >= counts[which] {
        pick -= counts[which];
        which += 1;
    }
    let clip = &pool.clips[usable[which]];
    let (start, end) = (pick, pick + cfg.window);
    let truth = clip.frames[start..end].to_vec();
    let mask = random_mask(&mut r, cfg.window, &cfg.mask);
    let constraint = match cfg.kind {
        ConstraintKind::None => Constraint::None,
        ConstraintKind::Keyframes => Constraint::Keyframes(sample_keyframes(&mut r, &truth, &mask, MODEL_FPS)),
        ConstraintKind::Noisy => Constraint::Noisy(noisy_guide(&mut r, &truth, &cfg.tracker)),
        ConstraintKind::Visemes => {
            let labels = clip.visemes.as_ref().expect("usable() keeps labelled clips for the viseme network");
            Constraint::Visemes(labels[start..end].to_vec())
        }
    };
    let z = noise(&mut r, cfg.window);
    let mut input = Vec::new();
    assemble_into(&truth, &mask, &constraint, &z, &mut input);
    Sample { truth, mask, input }
}

/// Draws a batch from `pool` with every random choice from `seed` (sample `b` from
/// `derive(seed, b)`). Errors when no clip is usable ([`ClipPool::usable`]).
pub fn sample_batch(pool: &ClipPool, cfg: &SamplerConfig, seed: u64) -> Result<HostBatch, String> {
    let usable = pool.usable(cfg.kind, cfg.window)?;
    Ok(sample_batch_from(pool, &usable, cfg, seed))
}

/// [`sample_batch`] with the usable clips already known.
pub fn sample_batch_from(pool: &ClipPool, usable: &[usize], cfg: &SamplerConfig, seed: u64) -> HostBatch {
    let (b_n, t_n, d) = (cfg.batch, cfg.window, input_dim(cfg.kind));
    let mut out = HostBatch {
        batch: b_n,
        window: t_n,
        d_input: d,
        inputs: vec![0.0; t_n * b_n * d],
        target: Vec::with_capacity(b_n * t_n * NUM_ARKIT),
        mask: Vec::with_capacity(b_n * t_n * NUM_ARKIT),
    };
    for b in 0..b_n {
        let s = draw_sample(pool, usable, cfg, derive(seed, b as u64));
        for t in 0..t_n {
            out.inputs[(t * b_n + b) * d..(t * b_n + b + 1) * d].copy_from_slice(&s.input[t * d..(t + 1) * d]);
            out.target.extend_from_slice(&s.truth[t]);
            out.mask.extend(s.mask.frame(t).iter().map(|e| f32::from(u8::from(*e))));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::fill::{interpolate, Interp};
    use crate::edit::{Frame, Mask, Segment};
    use crate::model::input::{CONSTRAINT_OFFSET, MASK_OFFSET};
    use crate::visemes::NUM_VISEMES;

    /// A clip whose frame f holds f/1000 + c/10⁵ in channel c, so a value names its frame.
    fn ramp_clip(frames: usize, visemes: bool) -> TrainClip {
        TrainClip {
            frames: (0..frames)
                .map(|f| {
                    let mut x = [0.0; NUM_ARKIT];
                    for (c, v) in x.iter_mut().enumerate() {
                        *v = f as f32 / 1000.0 + c as f32 * 1e-5;
                    }
                    x
                })
                .collect(),
            visemes: visemes.then(|| (0..frames).map(|f| Viseme::ALL[f % NUM_VISEMES]).collect()),
        }
    }

    fn cfg(kind: ConstraintKind) -> SamplerConfig {
        SamplerConfig { kind, window: 16, batch: 4, mask: MaskSampling::default(), tracker: TrackerNoise::default() }
    }

    #[test]
    fn train_batches_are_seeded_contiguous_windows_with_consistent_inputs() {
        let pool = ClipPool::new(vec![ramp_clip(40, true), ramp_clip(20, true)], "ramps");
        for kind in ConstraintKind::ALL {
            let c = cfg(kind);
            let a = sample_batch(&pool, &c, 7).unwrap();
            assert_eq!(a, sample_batch(&pool, &c, 7).unwrap(), "{kind:?}: same seed, same batch");
            assert_ne!(a.target, sample_batch(&pool, &c, 8).unwrap().target);
            let d = input_dim(kind);
            assert_eq!((a.d_input, a.inputs.len(), a.target.len()), (d, 16 * 4 * d, 4 * 16 * NUM_ARKIT));
            for b in 0..4 {
                let frame = |t: usize| a.target[(b * 16 + t) * NUM_ARKIT];
                for t in 1..16 {
                    assert!((frame(t) - frame(t - 1) - 0.001).abs() < 1e-6, "window is contiguous");
                }
                // The input's first 52 features: the kept values, and the linear prior through the
                // keys (read back from the constraint features) where erased.
                let row_of = |t: usize| &a.inputs[(t * 4 + b) * d..(t * 4 + b + 1) * d];
                let truth: Vec<Frame> = (0..16)
                    .map(|t| a.target[(b * 16 + t) * NUM_ARKIT..(b * 16 + t + 1) * NUM_ARKIT].try_into().unwrap())
                    .collect();
                let erased = |t: usize, ch: usize| a.mask[(b * 16 + t) * NUM_ARKIT + ch] > 0.0;
                // One channel's mask at a time (group edits erase some channels only).
                let channel_mask = |ch: usize| {
                    let segments: Vec<Segment> =
                        (0..16).filter(|t| erased(*t, ch)).map(|t| Segment { start: t, end: t + 1 }).collect();
                    let mut only = [false; NUM_ARKIT];
                    only[ch] = true;
                    Mask::from_segments(16, &segments, &only)
                };
                let keys: Vec<(usize, Frame)> = if kind == ConstraintKind::Keyframes {
                    (0..16)
                        .filter(|t| row_of(*t)[d - 1] > 0.0)
                        .map(|t| (t, row_of(t)[CONSTRAINT_OFFSET..CONSTRAINT_OFFSET + NUM_ARKIT].try_into().unwrap()))
                        .collect()
                } else {
                    Vec::new()
                };
                let prior: Vec<Vec<f32>> = (0..NUM_ARKIT)
                    .map(|ch| {
                        interpolate(&truth, &channel_mask(ch), &keys, Interp::Linear).iter().map(|f| f[ch]).collect()
                    })
                    .collect();
                for t in 0..16 {
                    let row = row_of(t);
                    for ch in 0..NUM_ARKIT {
                        let m = a.mask[(b * 16 + t) * NUM_ARKIT + ch];
                        assert_eq!(row[MASK_OFFSET + ch], m);
                        let expected = if m > 0.0 { prior[ch][t] } else { truth[t][ch] };
                        assert_eq!(row[ch], expected);
                    }
                    if kind == ConstraintKind::Visemes && row[d - 1] > 0.0 {
                        let hot: f32 = row[CONSTRAINT_OFFSET..CONSTRAINT_OFFSET + NUM_VISEMES].iter().sum();
                        assert_eq!(hot, 1.0);
                        // The label is that of the window's source frame.
                        let f = (a.target[(b * 16 + t) * NUM_ARKIT] * 1000.0).round() as usize;
                        assert_eq!(row[CONSTRAINT_OFFSET + f % NUM_VISEMES], 1.0);
                    }
                }
            }
            assert!(a.mask.iter().any(|m| *m > 0.0));
        }
    }

    #[test]
    fn train_pool_refuses_what_cannot_train() {
        let pool = ClipPool::new(vec![ramp_clip(40, false), ramp_clip(10, true)], "mixed");
        assert_eq!(pool.usable(ConstraintKind::None, 16).unwrap(), vec![0]);
        let err = pool.usable(ConstraintKind::Visemes, 16).unwrap_err();
        assert!(err.contains("mixed") && err.contains("viseme labels"), "{err}");
        assert!(pool.usable(ConstraintKind::None, 50).unwrap_err().contains("longest 40"));
    }

    #[test]
    fn train_pool_of_procedural_clips_has_viseme_labels() {
        let pool = ClipPool::procedural(2, 6.0, 3).unwrap();
        assert!(pool.description.contains("procedural"));
        assert_eq!(pool.usable(ConstraintKind::Visemes, 100).unwrap().len(), 2);
        let batch = sample_batch(&pool, &SamplerConfig { window: 100, ..cfg(ConstraintKind::Visemes) }, 1).unwrap();
        assert!(batch.target.iter().all(|v| (0.0..=1.0).contains(v)));
        let err = ClipPool::live_link(&["/nonexistent/capture.csv".into()]).unwrap_err().to_string();
        assert!(err.contains("capture.csv"), "{err}");
    }

    #[test]
    fn train_clip_from_a_60_fps_capture_is_resampled() {
        let times: Vec<f64> = (0..121).map(|f| f as f64 / 60.0).collect();
        let values: Vec<f32> = (0..121).flat_map(|f| [f as f32 / 120.0; NUM_ARKIT]).collect();
        let clip = BlendshapeClip::new(60.0, times, false, Vec::new(), values).unwrap();
        let tc = TrainClip::from_clip(&clip, None).unwrap();
        assert_eq!(tc.frames.len(), 51);
        assert!((tc.frames[25][0] - 0.5).abs() < 1e-4);
        assert!(TrainClip::from_clip(&clip, Some(vec![Viseme::Sil; 3])).unwrap_err().to_string().contains("3 viseme"));
    }
}
