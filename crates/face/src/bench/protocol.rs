//! The evaluation's protocol: gap lengths, what a run reads ([`FaceBenchConfig`]), the held-out and
//! training captures, the guide each test edit gets, the methods compared and one edit through
//! [`crate::infer::EditJob`].

use std::path::{Path, PathBuf};

use inbetween_core::seed::rng;

use crate::data::split::{TEST_FILES, TRAIN_FILES};
use crate::data::{read_live_link, BlendshapeClip, FaceError, MODEL_FPS, NUM_ARKIT};
use crate::edit::constraints::{noisy_guide, sample_keyframes, TrackerNoise};
use crate::edit::{ConstraintKind, Frame, Mask, MotionLibrary, RetrievalOptions, Segment};
use crate::infer::{EditJob, Guide, KeyPose, Method};
use crate::visemes::Viseme;
use crate::weights::NetworkSet;

/// Gap lengths of the held-out evaluation, seconds.
pub const GAPS_S: [f64; 4] = [0.5, 1.0, 2.0, 3.0];

/// What to run.
pub struct FaceBenchConfig {
    /// `face/neurosync` folder of the shared data.
    pub captures: PathBuf,
    /// Edits per (clip, gap length, constraint).
    pub edits_per_gap: usize,
    /// Procedural held-out clips for the viseme evaluation.
    pub procedural_clips: usize,
    /// Seconds of each procedural clip.
    pub procedural_seconds: f64,
    /// Use only the first held-out file (quick runs).
    pub one_test_file: bool,
    /// Seed of every random choice.
    pub seed: u64,
}

impl FaceBenchConfig {
    /// The full evaluation.
    pub fn full(captures: PathBuf) -> Self {
        FaceBenchConfig {
            captures,
            edits_per_gap: 12,
            procedural_clips: 6,
            procedural_seconds: 20.0,
            one_test_file: false,
            seed: 2026,
        }
    }

    /// A small run for tests.
    pub fn quick(captures: PathBuf) -> Self {
        FaceBenchConfig {
            captures,
            edits_per_gap: 2,
            procedural_clips: 1,
            procedural_seconds: 10.0,
            one_test_file: true,
            seed: 7,
        }
    }
}

/// The guide a test edit gets, drawn from the truth.
pub(super) fn guide_for(
    kind: ConstraintKind,
    truth: &[Frame],
    mask: &Mask,
    visemes: Option<&[Viseme]>,
    seed: u64,
) -> Guide {
    let mut r = rng(seed);
    match kind {
        ConstraintKind::None => Guide::None,
        ConstraintKind::Keyframes => Guide::Keys(
            sample_keyframes(&mut r, truth, mask, MODEL_FPS)
                .into_iter()
                .map(|(f, k)| KeyPose { time_s: f as f64 / MODEL_FPS, shapes: k.iter().copied().enumerate().collect() })
                .collect(),
        ),
        ConstraintKind::Noisy => {
            Guide::Noisy(BlendshapeClip::from_model_frames(&noisy_guide(&mut r, truth, &TrackerNoise::default())))
        }
        ConstraintKind::Visemes => Guide::Visemes(viseme_runs(visemes.expect("viseme labels"))),
    }
}

/// Per-frame labels as `(start_s, end_s, viseme)` runs.
pub fn viseme_runs(labels: &[Viseme]) -> Vec<(f64, f64, Viseme)> {
    let mut runs: Vec<(f64, f64, Viseme)> = Vec::new();
    for (f, v) in labels.iter().enumerate() {
        let (a, b) = ((f as f64 - 0.5).max(0.0) / MODEL_FPS, (f as f64 + 0.5) / MODEL_FPS);
        match runs.last_mut() {
            Some(last) if last.2 == *v => last.1 = b,
            _ => runs.push((a, b, *v)),
        }
    }
    runs
}

/// The methods compared for one constraint type: linear, cubic, each network set's network, each
/// retrieval library (not for visemes: the libraries have no phoneme labels), and for the noisy guide
/// the guide itself.
pub(super) fn methods<'a>(
    kind: ConstraintKind,
    sets: &'a [NetworkSet],
    libs: &'a [Library],
) -> Vec<(String, Method<'a>)> {
    let mut m = vec![("linear".to_string(), Method::Linear), ("cubic".to_string(), Method::Cubic)];
    for s in sets {
        if let Some(net) = s.get(kind) {
            m.push((format!("ours ({})", s.label), Method::Network(net)));
        }
    }
    if kind != ConstraintKind::Visemes {
        for l in libs {
            m.push((
                format!("retrieval ({})", l.label),
                Method::Retrieval(&l.library, RetrievalOptions::for_kind(kind)),
            ));
        }
    }
    m
}

/// A retrieval library under its table label.
pub struct Library {
    /// Label in the tables ("real split", "procedural").
    pub label: String,
    /// The motion.
    pub library: MotionLibrary,
}

/// The bench's retrieval libraries: the real training split (never the held-out files) and the
/// procedural library that `face edit --method retrieval` uses by default.
pub fn libraries(cfg: &FaceBenchConfig) -> Result<Vec<Library>, FaceError> {
    let mut real = MotionLibrary::default();
    for f in TRAIN_FILES {
        real.push(read_live_link(&cfg.captures.join(f))?.resample(MODEL_FPS)?.arkit_frames());
    }
    Ok(vec![
        Library { label: "real split".into(), library: real },
        Library {
            label: "procedural".into(),
            library: MotionLibrary::procedural(crate::infer::DEFAULT_LIBRARY_S, crate::infer::DEFAULT_LIBRARY_SEED),
        },
    ])
}

/// One edit of `truth` (25 fps) on `seg` with `method`; returns the model-rate output and mask.
pub(super) fn edit(
    truth: &BlendshapeClip,
    seg: Segment,
    guide: &Guide,
    method: Method,
    seed: u64,
) -> Result<(Vec<Frame>, Mask), FaceError> {
    let spans = vec![(seg.start as f64 / MODEL_FPS, seg.end as f64 / MODEL_FPS)];
    let job = EditJob {
        clip: truth,
        spans,
        channels: Some([true; NUM_ARKIT]),
        guide: guide.clone(),
        method,
        seed,
        limits: crate::infer::EditLimits::default(),
        cancel: inbetween_core::cancel::Cancel::new(),
        guide_file: None,
        library: None,
    };
    let out = job.run()?;
    Ok((out.after, out.mask))
}

/// The guide recomposed into the gap (the "use the noisy take as is" baseline).
pub(super) fn guide_as_is(truth: &[Frame], mask: &Mask, guide: &Guide) -> Vec<Frame> {
    let Guide::Noisy(g) = guide else { return truth.to_vec() };
    crate::model::input::recompose(truth, mask, &g.arkit_frames())
}

/// Load the held-out captures at the model rate.
pub fn test_clips(captures: &Path, one: bool) -> Result<Vec<(String, BlendshapeClip)>, FaceError> {
    let files = if one { &TEST_FILES[..1] } else { &TEST_FILES[..] };
    files.iter().map(|f| Ok((f.to_string(), read_live_link(&captures.join(f))?.resample(MODEL_FPS)?))).collect()
}

/// Gap lengths of the plausibility evaluation, seconds.
pub const PLAUSIBILITY_GAPS_S: [f64; 4] = [1.0, 2.0, 3.0, 5.0];

/// Folds of the two-sample test's cross-validation.
pub(super) const AUC_FOLDS: usize = 5;
