//! Shared pieces of the real-capture edit tests: the cases a user edits, the noise kinds of a noisy
//! take, and the statistics the tests compare.
#![allow(dead_code)]

use std::sync::OnceLock;

use inbetween_core::seed::rng;
use inbetween_face::bench::plausibility::GapStats;
use inbetween_face::data::{BlendshapeClip, MODEL_FPS, NUM_ARKIT};
use inbetween_face::edit::constraints::sample_keyframes;
use inbetween_face::edit::{ConstraintKind, Frame, Mask, MotionLibrary, RetrievalOptions};
use inbetween_face::infer::{EditJob, EditLimits, EditOutcome, Guide, Inpainter, KeyPose, Method};
use inbetween_face::visemes::{phoneme_viseme, text_to_phonemes};
use inbetween_face::weights::{self, Network};
use rand::Rng;

pub const TEXT_SPOKEN: &str = "I never thought it would end like this";

/// What the user asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Case {
    Unguided,
    Text,
    Noisy,
    Keys,
}

/// How (`Auto` is `face edit`'s default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum M {
    Auto,
    Linear,
    Cubic,
    Network,
    Retrieval,
}

impl Case {
    pub const ALL: [Case; 4] = [Case::Unguided, Case::Text, Case::Noisy, Case::Keys];

    pub fn methods(self) -> Vec<M> {
        match self {
            Case::Text => vec![M::Auto, M::Linear, M::Cubic, M::Network],
            _ => vec![M::Auto, M::Linear, M::Cubic, M::Network, M::Retrieval],
        }
    }

    /// The guidance over `span` (seconds); `truth` is the clip at the model rate.
    pub fn guide(self, clip: &BlendshapeClip, truth: &[Frame], span: (f64, f64), seed: u64) -> Guide {
        match self {
            Case::Unguided => Guide::None,
            Case::Text => {
                let ph = text_to_phonemes(TEXT_SPOKEN, span.0, span.1).unwrap();
                Guide::Visemes(
                    ph.spans.iter().map(|s| (s.start_s, s.end_s, phoneme_viseme(&s.phoneme).unwrap())).collect(),
                )
            }
            Case::Noisy => Guide::Noisy(Noise::White.apply(clip, seed)),
            Case::Keys => {
                let (a, b) = ((span.0 * MODEL_FPS).round() as usize, (span.1 * MODEL_FPS).round() as usize);
                let mask = Mask::span(truth.len(), a, b);
                let keys = sample_keyframes(&mut rng(seed), truth, &mask, MODEL_FPS);
                Guide::Keys(
                    keys.into_iter()
                        .map(|(f, k)| KeyPose {
                            time_s: f as f64 / MODEL_FPS,
                            shapes: k.iter().copied().enumerate().collect(),
                        })
                        .collect(),
                )
            }
        }
    }
}

fn nets() -> &'static Vec<Network> {
    static NETS: OnceLock<Vec<Network>> = OnceLock::new();
    NETS.get_or_init(|| ConstraintKind::ALL.iter().map(|k| weights::committed(*k).unwrap()).collect())
}

/// One edit as `face edit` makes it with its default groups.
pub fn edit(
    clip: &BlendshapeClip,
    spans: &[(f64, f64)],
    guide: Guide,
    method: M,
    library: &MotionLibrary,
    seed: u64,
) -> Result<EditOutcome, inbetween_face::FaceError> {
    let kind = guide.kind();
    let net = nets().iter().find(|n| n.kind() == kind).unwrap();
    let method = match method {
        M::Auto => match kind {
            ConstraintKind::None | ConstraintKind::Noisy => {
                Method::Retrieval(library, RetrievalOptions::for_kind(kind))
            }
            _ => Method::Network(net),
        },
        M::Linear => Method::Linear,
        M::Cubic => Method::Cubic,
        M::Network => Method::Network(net),
        M::Retrieval => Method::Retrieval(library, RetrievalOptions::for_kind(kind)),
    };
    EditJob {
        clip,
        spans: spans.to_vec(),
        channels: None,
        guide,
        method,
        seed,
        limits: EditLimits::default(),
        cancel: inbetween_core::cancel::Cancel::new(),
        guide_file: None,
        library: Some(library),
    }
    .run()
}

/// Kinds of noise in a noisy take, applied at the capture's rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Noise {
    /// Gaussian, σ 0.06 per value.
    White,
    /// Each row sampled up to ±1.5 rows off its time (a tracker's uneven timing).
    Jitter,
    /// One row in ten on average dropped (the tracker holds its last value, 1–8 rows).
    Dropped,
    /// Exponentially smoothed (0.6) and 4 rows (67 ms) late.
    SmoothedLagged,
}

impl Noise {
    pub const ALL: [Noise; 4] = [Noise::White, Noise::Jitter, Noise::Dropped, Noise::SmoothedLagged];

    pub fn apply(self, clip: &BlendshapeClip, seed: u64) -> BlendshapeClip {
        let mut r = rng(1000 + seed);
        let n = clip.num_frames();
        let stride = clip.num_channels();
        let src = clip.values();
        let mut v = src.to_vec();
        let at = |i: usize, c: usize| src[i * stride + c];
        match self {
            Noise::White => {
                for i in 0..n {
                    for c in 0..NUM_ARKIT {
                        let g: f32 = (0..12).map(|_| r.random::<f32>()).sum::<f32>() - 6.0;
                        v[i * stride + c] = (at(i, c) + 0.06 * g).clamp(0.0, 1.0);
                    }
                }
            }
            Noise::Jitter => {
                for i in 0..n {
                    let x = (i as f32 + r.random_range(-1.5f32..1.5)).clamp(0.0, (n - 1) as f32);
                    let (i0, w) = (x.floor() as usize, x.fract());
                    let i1 = (i0 + 1).min(n - 1);
                    for c in 0..NUM_ARKIT {
                        v[i * stride + c] = at(i0, c) * (1.0 - w) + at(i1, c) * w;
                    }
                }
            }
            Noise::Dropped => {
                let mut hold = 0;
                for i in 1..n {
                    if hold == 0 && r.random::<f64>() < 0.022 {
                        hold = r.random_range(1..=8);
                    }
                    if hold > 0 {
                        hold -= 1;
                        for c in 0..NUM_ARKIT {
                            v[i * stride + c] = v[(i - 1) * stride + c];
                        }
                    }
                }
            }
            Noise::SmoothedLagged => {
                let mut state: Vec<f32> = (0..NUM_ARKIT).map(|c| at(0, c)).collect();
                for i in 0..n {
                    let s = i.saturating_sub(4);
                    for c in 0..NUM_ARKIT {
                        state[c] = 0.6 * state[c] + 0.4 * at(s, c);
                        v[i * stride + c] = state[c];
                    }
                }
            }
        }
        BlendshapeClip::new(clip.fps(), clip.times().to_vec(), clip.has_head_eye(), clip.extra_names().to_vec(), v)
            .unwrap()
    }
}

/// Runs of `true`: `(start, end)`.
pub fn runs(flags: &[bool]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, f) in flags.iter().chain([&false]).enumerate() {
        match (f, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Rows of `clip` inside any span (seconds from its first row), as the edit job counts them.
pub fn inside_rows(clip: &BlendshapeClip, spans: &[(f64, f64)]) -> Vec<bool> {
    let t0 = clip.times()[0];
    clip.times().iter().map(|t| spans.iter().any(|(a, b)| t - t0 >= *a && t - t0 <= *b)).collect()
}

/// 99th percentile of the absolute row-to-row step of `x` between rows both outside the spans.
pub fn p99_step(x: &[f32], inside: &[bool]) -> f32 {
    let mut steps: Vec<f32> =
        (1..x.len()).filter(|&i| !inside[i] && !inside[i - 1]).map(|i| (x[i] - x[i - 1]).abs()).collect();
    steps.sort_by(f32::total_cmp);
    steps.get(((steps.len() as f64 * 0.99) as usize).min(steps.len().saturating_sub(1))).copied().unwrap_or(0.0)
}

/// Mean squared error over the erased entries.
pub fn masked_mse(a: &[Frame], b: &[Frame], mask: &Mask) -> f64 {
    let (mut s, mut k) = (0.0f64, 0usize);
    for f in 0..mask.frames().min(a.len()) {
        for c in 0..NUM_ARKIT {
            if mask.erased(f, c) {
                s += f64::from(a[f][c] - b[f][c]).powi(2);
                k += 1;
            }
        }
    }
    s / k.max(1) as f64
}

/// Gap statistics inside the edited spans and outside them (model rate), pooled over edits.
#[derive(Default)]
pub struct Stats {
    pub inside: GapStats,
    pub outside: GapStats,
}

impl Stats {
    pub fn add(&mut self, frames: &[Frame], mask: &Mask) {
        let segs = mask.segments();
        let mut prev = 0;
        for s in &segs {
            self.inside.add(&GapStats::of(&frames[s.start..s.end]));
            self.outside.add(&GapStats::of(&frames[prev..s.start]));
            prev = s.end;
        }
        self.outside.add(&GapStats::of(&frames[prev..]));
    }

    /// Inside/outside ratios: blinks per second, eye-closed fraction, mouth/jaw speed.
    pub fn ratios(&self) -> [f64; 3] {
        let (i, o) = (self.inside.values(), self.outside.values());
        [0, 1, 2].map(|k| i[k] / o[k].max(1e-9))
    }
}
