//! The guiding constraints of §3.1: sparse keyframes, a dense noisy guide, one-hot visemes.
//!
//! Each constraint becomes a matrix `C` (frames × features) that is non-zero only where the
//! animation is erased, plus a constraint mask `M_C` with ones on the frames where `C` holds
//! information. One network is trained per [`ConstraintKind`].

use inbetween_core::seed::normal;
use rand::Rng;

use crate::data::NUM_ARKIT;
use crate::visemes::{Viseme, NUM_VISEMES};

use super::groups::SPEECH_GROUPS;
use super::mask::Mask;
use super::Frame;

/// The type of guidance a network is trained for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConstraintKind {
    /// Unguided motion filling (§4.2).
    None,
    /// Sparse keyframes (§4.3.1).
    Keyframes,
    /// A dense noisy animation, as from a webcam tracker (§4.3.2).
    Noisy,
    /// One-hot visemes (§4.3.3).
    Visemes,
}

/// The shapes a guidance acts on when the edit names no groups: the speech groups
/// ([`SPEECH_GROUPS`]) for visemes, every shape otherwise (keys and a noisy take say something about
/// the whole face).
pub fn guided_channels(kind: ConstraintKind) -> [bool; NUM_ARKIT] {
    match kind {
        ConstraintKind::Visemes => std::array::from_fn(|c| SPEECH_GROUPS.iter().any(|g| g.contains(c))),
        _ => [true; NUM_ARKIT],
    }
}

impl ConstraintKind {
    /// Every kind, in the order networks are listed.
    pub const ALL: [ConstraintKind; 4] =
        [ConstraintKind::None, ConstraintKind::Keyframes, ConstraintKind::Noisy, ConstraintKind::Visemes];

    /// Name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ConstraintKind::None => "unguided",
            ConstraintKind::Keyframes => "keyframes",
            ConstraintKind::Noisy => "noisy",
            ConstraintKind::Visemes => "visemes",
        }
    }

    /// The kind named `name` (as [`Self::name`] writes it).
    pub fn from_name(name: &str) -> Option<ConstraintKind> {
        ConstraintKind::ALL.iter().copied().find(|k| k.name().eq_ignore_ascii_case(name))
    }

    /// Features per frame of the constraint matrix `C`.
    pub fn dim(self) -> usize {
        match self {
            ConstraintKind::None => 0,
            ConstraintKind::Keyframes | ConstraintKind::Noisy => NUM_ARKIT,
            ConstraintKind::Visemes => NUM_VISEMES,
        }
    }
}

/// A concrete constraint for one clip (frames at the model rate).
#[derive(Clone, Debug, PartialEq)]
pub enum Constraint {
    /// No guidance.
    None,
    /// Expressions to reach at given frames.
    Keyframes(Vec<(usize, Frame)>),
    /// A guide animation covering every frame of the clip.
    Noisy(Vec<Frame>),
    /// The viseme of every frame of the clip.
    Visemes(Vec<Viseme>),
}

impl Constraint {
    /// The kind of network this constraint needs.
    pub fn kind(&self) -> ConstraintKind {
        match self {
            Constraint::None => ConstraintKind::None,
            Constraint::Keyframes(_) => ConstraintKind::Keyframes,
            Constraint::Noisy(_) => ConstraintKind::Noisy,
            Constraint::Visemes(_) => ConstraintKind::Visemes,
        }
    }

    /// Check the constraint against a clip of `frames` frames; the message says what is wrong.
    pub fn validate(&self, frames: usize) -> Result<(), String> {
        let in_range = |v: &f32| v.is_finite() && (0.0..=1.0).contains(v);
        match self {
            Constraint::None => Ok(()),
            Constraint::Keyframes(keys) => {
                for (f, k) in keys {
                    if *f >= frames {
                        return Err(format!("keyframe at frame {f} lies past the clip's {frames} frames"));
                    }
                    if let Some(c) = k.iter().position(|v| !in_range(v)) {
                        return Err(format!(
                            "keyframe at frame {f}: {} = {} lies outside [0, 1]",
                            crate::data::ARKIT_NAMES[c],
                            k[c]
                        ));
                    }
                }
                Ok(())
            }
            Constraint::Noisy(g) if g.len() != frames => {
                Err(format!("the guide has {} frames at the model rate, the clip {frames}", g.len()))
            }
            Constraint::Noisy(_) => Ok(()),
            Constraint::Visemes(v) if v.len() != frames => {
                Err(format!("the viseme track has {} frames, the clip {frames}", v.len()))
            }
            Constraint::Visemes(_) => Ok(()),
        }
    }

    /// The constraint restricted to frames `start..end`, renumbered from 0.
    pub fn crop(&self, start: usize, end: usize) -> Constraint {
        match self {
            Constraint::None => Constraint::None,
            Constraint::Keyframes(keys) => Constraint::Keyframes(
                keys.iter().filter(|(f, _)| (start..end).contains(f)).map(|(f, k)| (f - start, *k)).collect(),
            ),
            Constraint::Noisy(g) => Constraint::Noisy(g[start.min(g.len())..end.min(g.len())].to_vec()),
            Constraint::Visemes(v) => Constraint::Visemes(v[start.min(v.len())..end.min(v.len())].to_vec()),
        }
    }

    /// The constraint matrix `C` (`frames × kind().dim()`, frame-major) and the constraint mask `M_C`
    /// (`frames`): information only on frames the mask erases (§3.1).
    pub fn features(&self, mask: &Mask) -> (Vec<f32>, Vec<f32>) {
        let frames = mask.frames();
        let dim = self.kind().dim();
        let mut c = vec![0.0f32; frames * dim];
        let mut m = vec![0.0f32; frames];
        let mut put = |f: usize, values: &[f32]| {
            if f < frames && mask.frame_erased(f) {
                c[f * dim..(f + 1) * dim].copy_from_slice(values);
                m[f] = 1.0;
            }
        };
        match self {
            Constraint::None => {}
            Constraint::Keyframes(keys) => keys.iter().for_each(|(f, k)| put(*f, k)),
            Constraint::Noisy(g) => g.iter().enumerate().for_each(|(f, k)| put(f, k)),
            Constraint::Visemes(v) => {
                let mut one_hot = [0.0f32; NUM_VISEMES];
                for (f, vis) in v.iter().enumerate() {
                    one_hot.fill(0.0);
                    one_hot[vis.index()] = 1.0;
                    put(f, &one_hot);
                }
            }
        }
        (c, m)
    }
}

/// Sparse keyframes from the ground truth inside the erased frames, 0–0.8 s apart (§3.1). The first
/// key falls within the first gap of each segment; spacing is drawn uniformly in (0, 0.8] s, at least
/// one frame; a segment the draws skip gets one key at a random frame.
pub fn sample_keyframes(rng: &mut impl Rng, truth: &[Frame], mask: &Mask, fps: f64) -> Vec<(usize, Frame)> {
    let max_gap = (0.8 * fps).max(1.0);
    let mut keys = Vec::new();
    for seg in mask.segments() {
        let before = keys.len();
        let mut f = seg.start as f64 + rng.random::<f64>() * max_gap;
        while (f as usize) < seg.end {
            let i = f as usize;
            keys.push((i, truth[i]));
            f += (rng.random::<f64>() * max_gap).max(1.0);
        }
        if keys.len() == before {
            // A gap shorter than the first draw still gets one key, so every erased segment is guided.
            let i = rng.random_range(seg.start..seg.end);
            keys.push((i, truth[i]));
        }
    }
    keys
}

/// Tracker noise for the noisy guide (§4.3.2): what a webcam blendshape tracker does to the truth.
#[derive(Clone, Debug)]
pub struct TrackerNoise {
    /// Standard deviation of frame-to-frame jitter (weight units).
    pub jitter: f32,
    /// Per-shape gain error (standard deviation around 1).
    pub gain: f32,
    /// Per-shape bias (standard deviation).
    pub bias: f32,
    /// Largest lag in frames (drawn per clip in 0..=max_lag).
    pub max_lag: usize,
    /// Probability per frame that tracking drops out (the tracker holds its last value).
    pub dropout: f64,
    /// Longest dropout in frames.
    pub max_dropout: usize,
    /// Exponential smoothing the tracker applies (0 none, towards 1 heavy), which flattens fast motion.
    pub smoothing: f32,
}

impl Default for TrackerNoise {
    fn default() -> Self {
        TrackerNoise { jitter: 0.04, gain: 0.2, bias: 0.04, max_lag: 3, dropout: 0.02, max_dropout: 8, smoothing: 0.4 }
    }
}

/// A noisy guide from the ground truth: per-shape gain and bias, lag, smoothing, jitter and dropouts,
/// clamped to [0, 1].
pub fn noisy_guide(rng: &mut impl Rng, truth: &[Frame], noise: &TrackerNoise) -> Vec<Frame> {
    let n = truth.len();
    let gains: Vec<f32> = (0..NUM_ARKIT).map(|_| 1.0 + gauss(rng, noise.gain)).collect();
    let biases: Vec<f32> = (0..NUM_ARKIT).map(|_| gauss(rng, noise.bias)).collect();
    let lag = rng.random_range(0..=noise.max_lag);
    let mut out = Vec::with_capacity(n);
    let mut state: Frame = truth.first().copied().unwrap_or([0.0; NUM_ARKIT]);
    let mut hold = 0usize;
    for f in 0..n {
        let src = truth[f.saturating_sub(lag)];
        if hold == 0 && rng.random::<f64>() < noise.dropout {
            hold = rng.random_range(1..=noise.max_dropout.max(1));
        }
        if hold > 0 {
            hold -= 1;
        } else {
            for c in 0..NUM_ARKIT {
                let target = gains[c] * src[c] + biases[c];
                state[c] = noise.smoothing * state[c] + (1.0 - noise.smoothing) * target;
            }
        }
        let mut frame = state;
        for v in frame.iter_mut() {
            *v = (*v + gauss(rng, noise.jitter)).clamp(0.0, 1.0);
        }
        out.push(frame);
    }
    out
}

fn gauss(rng: &mut impl Rng, sd: f32) -> f32 {
    sd * normal(rng) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::mask::Segment;
    use inbetween_core::seed::rng;

    fn ramp(n: usize) -> Vec<Frame> {
        (0..n).map(|f| [f as f32 / n as f32; NUM_ARKIT]).collect()
    }

    #[test]
    fn keyframes_lie_in_the_gap_at_most_0_8_s_apart_and_are_the_truth() {
        let truth = ramp(200);
        let mask = Mask::from_segments(200, &[Segment { start: 50, end: 150 }], &[true; NUM_ARKIT]);
        for seed in 0..50 {
            let keys = sample_keyframes(&mut rng(seed), &truth, &mask, 25.0);
            assert!(!keys.is_empty());
            assert!(keys[0].0 - 50 <= 20);
            for w in keys.windows(2) {
                assert!(w[1].0 > w[0].0 && w[1].0 - w[0].0 <= 20, "{:?}", (w[0].0, w[1].0));
            }
            for (f, k) in &keys {
                assert!((50..150).contains(f));
                assert_eq!(k, &truth[*f]);
            }
        }
    }

    #[test]
    fn features_are_zero_outside_the_erased_frames() {
        let mask = Mask::from_segments(10, &[Segment { start: 3, end: 6 }], &[true; NUM_ARKIT]);
        let c = Constraint::Visemes(vec![Viseme::MBP; 10]);
        let (feat, m) = c.features(&mask);
        assert_eq!(feat.len(), 10 * NUM_VISEMES);
        assert_eq!(m, vec![0., 0., 0., 1., 1., 1., 0., 0., 0., 0.]);
        assert_eq!(feat[4 * NUM_VISEMES + Viseme::MBP.index()], 1.0);
        assert_eq!(feat.iter().sum::<f32>(), 3.0);
        let keys = Constraint::Keyframes(vec![(1, [0.5; NUM_ARKIT]), (4, [0.25; NUM_ARKIT])]);
        let (feat, m) = keys.features(&mask);
        assert_eq!(m.iter().sum::<f32>(), 1.0);
        assert_eq!(feat[4 * NUM_ARKIT], 0.25);
        assert_eq!(feat[NUM_ARKIT], 0.0);
    }

    #[test]
    fn noisy_guide_stays_in_range_follows_the_truth_and_is_seeded() {
        let truth: Vec<Frame> = (0..300).map(|f| [0.5 + 0.4 * (f as f32 * 0.1).sin(); NUM_ARKIT]).collect();
        let a = noisy_guide(&mut rng(3), &truth, &TrackerNoise::default());
        assert_eq!(a, noisy_guide(&mut rng(3), &truth, &TrackerNoise::default()));
        assert!(a.iter().flatten().all(|v| (0.0..=1.0).contains(v)));
        let err: f32 = a.iter().zip(&truth).map(|(x, y)| (x[0] - y[0]).abs()).sum::<f32>() / 300.0;
        assert!(err > 0.01 && err < 0.3, "mean error {err}");
    }

    #[test]
    fn validation_names_the_problem() {
        assert!(Constraint::Keyframes(vec![(12, [0.0; NUM_ARKIT])]).validate(10).unwrap_err().contains("frame 12"));
        let mut k = [0.0; NUM_ARKIT];
        k[17] = 1.5;
        assert!(Constraint::Keyframes(vec![(2, k)]).validate(10).unwrap_err().contains("JawOpen"));
        assert!(Constraint::Noisy(vec![[0.0; NUM_ARKIT]; 3]).validate(10).is_err());
        assert!(Constraint::Visemes(vec![Viseme::Sil; 10]).validate(10).is_ok());
    }
}
