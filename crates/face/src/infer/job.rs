//! The edit job: a clip, the spans to regenerate, optional guidance and a method in; the edited clip
//! out, at the clip's own frame times. Validation comes first and names every problem; nothing is
//! written here (the caller writes atomically).
//!
//! Steps (§3.1, §4): resample to the model rate (25 fps) → mask (spans × selected groups) → constraint
//! → network input → generator → recomposition `X ⊙ (1 − M) + G ⊙ M` → post-processing (exact keys, C1
//! borders, [0, 1]) → the shapes the guidance does not act on filled unguided (issue 40) → no eye held
//! closed longer than the capture does ([`limit_eye_holds`]; not with a noisy take, which shows the
//! performance's own holds, nor where a key holds it) → back to the capture's frame times, touching
//! only frames inside the spans, each border joined at the capture's own rate ([`join_borders`]) and
//! the holds checked again there ([`limit_hold`]).

use std::collections::BTreeMap;

use crate::data::{BlendshapeClip, FaceError, MODEL_FPS, NUM_ARKIT, NUM_HEAD_EYE};
use crate::edit::fill::{knot_curve, Knot};
use crate::edit::seam::{is_eye_channel, join_borders, limit_eye_holds, limit_hold, JOIN_FADE_S};
use crate::edit::{
    correct, interpolate, retrieve, Constraint, ConstraintKind, Frame, Interp, Mask, MotionLibrary, RetrievalOptions,
    Segment,
};
use crate::model::input;
use crate::visemes::Viseme;

use super::keys::KeyPose;
use crate::edit::constraints::guided_channels;
use inbetween_core::cancel::Cancel;
use inbetween_core::curve::Curve;
use inbetween_io::LimitExceeded;

/// The limits of an edit, checked by [`EditJob::validate`] before any work: the cost of an edit
/// grows with the clip's rows (resampling, recomposition) and with the stretch the generator runs
/// over (the masked stretch plus [`CONTEXT_FRAMES`] on each side).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditLimits {
    /// Most frames (rows) in the input clip or a noisy guide. Default 216 000: one hour at 60 fps.
    pub max_rows: usize,
    /// Longest stretch, in seconds, from the first span's start to the last span's end. Default
    /// 600 s (ten minutes; the networks are trained on 4 s windows).
    pub max_mask_s: f64,
}

impl Default for EditLimits {
    fn default() -> Self {
        EditLimits { max_rows: 216_000, max_mask_s: 600.0 }
    }
}

/// Something that fills erased entries from the network input (the trained generator).
pub trait Inpainter: Sync {
    /// The constraint type the network was trained for.
    fn kind(&self) -> ConstraintKind;
    /// Generated frames for `frames` frames of input laid out by [`crate::model::input`].
    fn generate(&self, input: &[f32], frames: usize) -> Vec<Frame>;
}

/// How the erased entries are filled.
#[derive(Clone, Copy)]
pub enum Method<'a> {
    /// A trained generator.
    Network(&'a dyn Inpainter),
    /// Linear interpolation through the borders and keys.
    Linear,
    /// Cubic Hermite interpolation through the borders (values and slopes) and keys.
    Cubic,
    /// Segments of recorded motion from the library and the clip itself ([`crate::edit::retrieve`]),
    /// drawn with the job's seed; unguided, keyframe or noisy guidance.
    Retrieval(&'a MotionLibrary, RetrievalOptions),
}

impl Method<'_> {
    /// Name for tables and messages.
    pub fn name(&self) -> String {
        match self {
            Method::Network(n) => format!("network ({})", n.kind().name()),
            Method::Linear => "linear".into(),
            Method::Cubic => "cubic".into(),
            Method::Retrieval(..) => "retrieval".into(),
        }
    }
}

/// Guidance for the edited spans, with times in seconds from the clip's first frame.
#[derive(Clone, Debug)]
pub enum Guide {
    /// Unguided filling.
    None,
    /// Expressions to hit.
    Keys(Vec<KeyPose>),
    /// A noisy take of the same performance, aligned on its first frame.
    Noisy(BlendshapeClip),
    /// The viseme of each span of time: `(start_s, end_s, viseme)`; uncovered time is silence.
    Visemes(Vec<(f64, f64, Viseme)>),
}

impl Guide {
    /// The network type this guidance needs.
    pub fn kind(&self) -> ConstraintKind {
        match self {
            Guide::None => ConstraintKind::None,
            Guide::Keys(_) => ConstraintKind::Keyframes,
            Guide::Noisy(_) => ConstraintKind::Noisy,
            Guide::Visemes(_) => ConstraintKind::Visemes,
        }
    }
}

/// An edit to run.
pub struct EditJob<'a> {
    /// The clip to edit, at any frame rate.
    pub clip: &'a BlendshapeClip,
    /// Spans to regenerate, seconds from the first frame (`start < end`).
    pub spans: Vec<(f64, f64)>,
    /// ARKit shapes to regenerate (others stay exactly as they are), the guidance acting on all of
    /// them; `None` (the default of `face edit` and the studio): every shape, the guidance acting on
    /// the shapes it means something for ([`crate::edit::constraints::guided_channels`]: the speech groups for
    /// visemes) and the others filled as an unguided edit is, by retrieval from `library` and the
    /// clip itself.
    pub channels: Option<[bool; NUM_ARKIT]>,
    /// Guidance.
    pub guide: Guide,
    /// How to fill.
    pub method: Method<'a>,
    /// Seed of the generator's noise.
    pub seed: u64,
    /// The input sizes this job accepts.
    pub limits: EditLimits,
    /// Checked between the edit's stages; a cancelled edit returns [`FaceError::Cancelled`].
    pub cancel: Cancel,
    /// The file the guidance was read from (keys, noisy take, visemes), named in messages.
    pub guide_file: Option<String>,
    /// Motion the shapes the guidance does not act on are drawn from (with the clip itself outside
    /// the spans, which is preferred); `None`: the clip alone.
    pub library: Option<&'a MotionLibrary>,
}

/// What an edit produced.
#[derive(Clone, Debug)]
pub struct EditOutcome {
    /// The edited clip, at the input's frame times; frames outside the spans are the input's, bit for bit.
    pub clip: BlendshapeClip,
    /// The input at the model rate.
    pub before: Vec<Frame>,
    /// The edit at the model rate.
    pub after: Vec<Frame>,
    /// The mask at the model rate.
    pub mask: Mask,
    /// The keys at the model rate (full frames), if any.
    pub keys: Vec<(usize, Frame)>,
}

impl EditOutcome {
    /// Mean squared difference between the edit and what was there, over the erased entries at the
    /// model rate (blendshape weight², how much the fill departs from the input it replaced).
    pub fn masked_mse(&self) -> f64 {
        let (mut sq, mut count) = (0.0f64, 0usize);
        // Frames with an erased entry only (the same entries in the same order as every frame).
        for f in self.mask.segments().into_iter().flat_map(|s| s.start..s.end) {
            for c in 0..NUM_ARKIT {
                if self.mask.erased(f, c) {
                    sq += f64::from(self.after[f][c] - self.before[f][c]).powi(2);
                    count += 1;
                }
            }
        }
        sq / count.max(1) as f64
    }

    /// The rows of `input` (the clip the job edited) that the edit changed (any value not bit for bit
    /// the input's), `first..last + 1` (`0..0` when none), and the ARKit shapes changed there.
    pub fn changed(&self, input: &BlendshapeClip) -> (std::ops::Range<usize>, [bool; NUM_ARKIT]) {
        let (old, new) = (input.values(), self.clip.values());
        let stride = input.num_channels();
        // Bits compared without an early exit inside a row, so the scan of the unchanged rows
        // vectorises (a face edit's report reads this for every variant).
        let differs = |f: &usize| {
            let row = f * stride..(f + 1) * stride;
            old[row.clone()].iter().zip(&new[row]).fold(0u32, |acc, (a, b)| acc | (a.to_bits() ^ b.to_bits())) != 0
        };
        let first = (0..input.num_frames()).find(differs);
        let last = (0..input.num_frames()).rev().find(differs);
        let rows = match (first, last) {
            (Some(a), Some(b)) => a..b + 1,
            _ => 0..0,
        };
        let mut shapes = [false; NUM_ARKIT];
        for f in rows.clone() {
            for (c, ch) in shapes.iter_mut().enumerate() {
                *ch |= old[f * stride + c].to_bits() != new[f * stride + c].to_bits();
            }
        }
        (rows, shapes)
    }

    /// Mean absolute difference from `other` (another variant of the same edit) over the edited
    /// frames at the model rate, every shape (blendshape weight, 0..1): how far two variants lie apart.
    pub fn mean_abs_difference(&self, other: &EditOutcome) -> f64 {
        let (a, b) = (&self.after, &other.after);
        let (mut sum, mut n) = (0.0f64, 0usize);
        for s in self.mask.segments() {
            for f in s.start..s.end.min(a.len()).min(b.len()) {
                for (x, y) in a[f].iter().zip(&b[f]) {
                    sum += f64::from((x - y).abs());
                    n += 1;
                }
            }
        }
        sum / n.max(1) as f64
    }
}

fn invalid(m: impl Into<String>) -> FaceError {
    FaceError::Invalid(m.into())
}

impl EditJob<'_> {
    /// The shapes the guidance and method act on, and the shapes filled unguided by retrieval
    /// (empty unless [`EditJob::channels`] is `None` and the guidance acts on part of the face).
    pub fn channel_split(&self) -> ([bool; NUM_ARKIT], [bool; NUM_ARKIT]) {
        match self.channels {
            Some(ch) => (ch, [false; NUM_ARKIT]),
            None => {
                let guided = guided_channels(self.guide.kind());
                (guided, guided.map(|g| !g))
            }
        }
    }

    /// Check everything that can be checked before running.
    pub fn validate(&self) -> Result<(), FaceError> {
        let duration = self.clip.duration();
        if self.clip.num_frames() < 2 {
            return Err(invalid("the clip has a single frame; an edit needs at least two"));
        }
        if self.spans.is_empty() {
            return Err(invalid("no span to edit: `spans` is empty; give at least one span (start s .. end s)"));
        }
        LimitExceeded::check_count("the clip", self.clip.num_frames(), self.limits.max_rows, "rows", "max_rows")?;
        // A span may end one frame past the last frame's time (a span in frames that covers the last frame).
        let end_ok = duration + 1.0 / self.clip.fps() + 1e-9;
        for (a, b) in &self.spans {
            if !(a.is_finite() && b.is_finite() && *a >= 0.0 && b > a) {
                return Err(invalid(format!("span {a} s..{b} s: expected 0 ≤ start < end")));
            }
            if *a >= duration {
                return Err(invalid(format!("span {a:.3} s..{b:.3} s starts after the clip ends ({duration:.3} s)")));
            }
            if *b > end_ok {
                return Err(invalid(format!(
                    "span {a:.3} s..{b:.3} s runs past the clip's end ({duration:.3} s); end it at {duration:.3} s at the latest"
                )));
            }
        }
        let first = self.spans.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
        let last = self.spans.iter().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max);
        LimitExceeded::check_seconds(
            "the mask (first span's start to last span's end)",
            last - first,
            self.limits.max_mask_s,
            "max_mask_s",
        )?;
        if !self.channel_split().0.iter().any(|c| *c) {
            return Err(invalid("no blendshape selected to edit"));
        }
        if let Method::Network(net) = self.method {
            if net.kind() != self.guide.kind() {
                return Err(invalid(format!(
                    "the {} network cannot take {} guidance; use the {} network",
                    net.kind().name(),
                    self.guide.kind().name(),
                    self.guide.kind().name()
                )));
            }
        }
        if matches!(self.method, Method::Retrieval(..)) && matches!(self.guide, Guide::Visemes(_)) {
            return Err(invalid(
                "retrieval cannot follow visemes (its library has no phoneme labels); use the viseme network",
            ));
        }
        let file = self.guide_file.as_deref().map_or(String::new(), |f| format!("{f}: "));
        match &self.guide {
            Guide::Keys(keys) => {
                if keys.is_empty() {
                    return Err(invalid(format!("{file}the keys file holds no key")));
                }
                for (i, k) in keys.iter().enumerate() {
                    if !self.spans.iter().any(|(a, b)| k.time_s >= *a && k.time_s <= *b) {
                        return Err(invalid(format!(
                            "{file}key {i} at {:.3} s lies outside every edited span ({}); keys guide the edit only \
                             inside the mask",
                            k.time_s,
                            self.spans_text()
                        )));
                    }
                }
                self.check_key_conflicts(keys, &file)?;
            }
            Guide::Noisy(g) => {
                LimitExceeded::check_count(
                    format!("{}the noisy take", file),
                    g.num_frames(),
                    self.limits.max_rows,
                    "rows",
                    "max_rows",
                )?;
            }
            Guide::Visemes(runs) => {
                if !runs.is_empty() && runs.iter().all(|(a, _, _)| *a >= duration) {
                    let first = runs.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
                    return Err(invalid(format!(
                        "{file}every phoneme lies after the clip's end (the first starts at {first:.3} s, the clip is \
                         {duration:.3} s long); expected times in seconds from the clip's first frame"
                    )));
                }
                if runs.is_empty() {
                    return Err(invalid(format!("{file}no phoneme to guide the edit")));
                }
            }
            Guide::None => {}
        }
        Ok(())
    }

    /// The spans as `a s..b s` for messages.
    fn spans_text(&self) -> String {
        self.spans.iter().map(|(a, b)| format!("{a:.3} s..{b:.3} s")).collect::<Vec<_>>().join(", ")
    }

    /// Keys that land on the same model-rate frame are merged; the same shape with two different
    /// weights there is refused (which one was meant cannot be told).
    fn check_key_conflicts(&self, keys: &[KeyPose], file: &str) -> Result<(), FaceError> {
        merge_keys(keys).map(|_| ()).map_err(|(ia, ib, c, va, vb)| {
            invalid(format!(
                "{file}keys {ia} ({:.3} s) and {ib} ({:.3} s) fall on the same frame at {MODEL_FPS} fps and set {} \
                 to different weights ({va} and {vb}); expected one weight per shape and frame",
                keys[ia].time_s,
                keys[ib].time_s,
                crate::data::ARKIT_NAMES[c]
            ))
        })
    }

    /// Run the edit.
    pub fn run(&self) -> Result<EditOutcome, FaceError> {
        self.validate()?;
        self.cancel.check()?;
        let model = self.clip.resample(MODEL_FPS)?;
        self.cancel.check()?;
        let before: Vec<Frame> = model.arkit_frames();
        let n = before.len();
        let segments = self.segments(n);
        let (guided, rest) = self.channel_split();
        let mask = Mask::from_segments(n, &segments, &guided);
        let keys = self.model_keys(&before);
        let constraint = self.constraint(&model, &keys)?;
        self.cancel.check()?;
        // One generator call over a window bounded by `limits.max_mask_s`; the cancel token is
        // checked again right after it.
        let mut after = match self.method {
            Method::Network(net) => {
                // The residual at the borders is taken against the network's own output there (not the
                // recomposition, which equals the input outside the mask), so the join is C1.
                let generated = generate_in_window(net, &before, &segments, &guided, &constraint, self.seed);
                correct(&generated, &before, &mask, &keys)
            }
            Method::Linear => interpolate(&before, &mask, &keys, Interp::Linear),
            Method::Cubic => interpolate(&before, &mask, &keys, Interp::Cubic),
            Method::Retrieval(library, options) => {
                // Spans with no segment of their length anywhere keep the linear fill.
                let base = interpolate(&before, &mask, &keys, Interp::Linear);
                let (filled, _) = retrieve(&base, &mask, &constraint, library, &options, self.seed);
                correct(&filled, &before, &mask, &keys)
            }
        };
        self.cancel.check()?;
        if rest.iter().any(|c| *c) {
            // The shapes the guidance says nothing about: an unguided fill, as `face edit` makes one.
            let rest_mask = Mask::from_segments(n, &segments, &rest);
            let own_only = MotionLibrary::default();
            let library = self.library.unwrap_or(&own_only);
            let base = interpolate(&before, &rest_mask, &[], Interp::Linear);
            let options = RetrievalOptions::for_kind(ConstraintKind::None);
            let (drawn, _) = retrieve(&base, &rest_mask, &Constraint::None, library, &options, self.seed);
            let filled = correct(&drawn, &before, &rest_mask, &[]);
            for (f, row) in after.iter_mut().enumerate() {
                for c in (0..NUM_ARKIT).filter(|c| rest_mask.erased(f, *c)) {
                    row[c] = filled[f][c];
                }
            }
        }
        let mask = Mask::from_segments(n, &segments, &std::array::from_fn(|c| guided[c] || rest[c]));
        // A noisy take shows the performance's own holds: it is followed, not cut.
        let cut_holds = !matches!(self.guide, Guide::Noisy(_));
        if cut_holds {
            limit_eye_holds(&mut after, &before, &mask, &keys, MODEL_FPS);
        }
        self.cancel.check()?;
        let clip = self.back_to_capture_rate(&after, &mask, &keys, cut_holds)?;
        Ok(EditOutcome { clip, before, after, mask, keys })
    }

    /// Spans as model-rate frames (at least one frame each).
    fn segments(&self, n: usize) -> Vec<Segment> {
        self.spans
            .iter()
            .map(|(a, b)| {
                let start = ((a * MODEL_FPS).round() as usize).min(n - 1);
                let end = ((b * MODEL_FPS).round() as usize).clamp(start + 1, n);
                Segment { start, end }
            })
            .collect()
    }

    /// Keys at model-rate frames, unset shapes taken from the input there.
    fn model_keys(&self, before: &[Frame]) -> Vec<(usize, Frame)> {
        let Guide::Keys(keys) = &self.guide else { return Vec::new() };
        // Keys on the same frame are merged into one (validate refused conflicting weights).
        let merged = merge_keys(keys).unwrap_or_default();
        merged
            .into_iter()
            .map(|(f, shapes)| {
                let f = f.min(before.len() - 1);
                let mut frame = before[f];
                for (c, (v, _)) in shapes {
                    frame[c] = v;
                }
                (f, frame)
            })
            .collect()
    }

    fn constraint(&self, model: &BlendshapeClip, keys: &[(usize, Frame)]) -> Result<Constraint, FaceError> {
        let n = model.num_frames();
        Ok(match &self.guide {
            Guide::None => Constraint::None,
            Guide::Keys(_) => Constraint::Keyframes(keys.to_vec()),
            Guide::Noisy(guide) => {
                let g0 = guide.times()[0];
                let times: Vec<f64> = (0..n).map(|f| g0 + f as f64 / MODEL_FPS).collect();
                let g = guide.resample_at(&times, MODEL_FPS)?;
                Constraint::Noisy(g.arkit_frames())
            }
            Guide::Visemes(spans) => Constraint::Visemes(
                (0..n)
                    .map(|f| {
                        let t = f as f64 / MODEL_FPS;
                        spans.iter().find(|(a, b, _)| t >= *a && t < *b).map_or(Viseme::Sil, |s| s.2)
                    })
                    .collect(),
            ),
        })
    }

    /// The input clip with every frame inside an edited span replaced by the model-rate edit
    /// (linear between model frames) and joined to the rows around it ([`join_borders`]), head/eye
    /// rotations inside the spans filled by cubic Hermite interpolation (the networks do not model
    /// them).
    fn back_to_capture_rate(
        &self,
        after: &[Frame],
        mask: &Mask,
        keys: &[(usize, Frame)],
        cut_holds: bool,
    ) -> Result<BlendshapeClip, FaceError> {
        let clip = self.clip;
        let t0 = clip.times()[0];
        let stride = clip.num_channels();
        let mut values = clip.values().to_vec();
        let last = after.len() - 1;
        let inside: Vec<bool> =
            clip.times().iter().map(|t| self.spans.iter().any(|(a, b)| t - t0 >= *a && t - t0 <= *b)).collect();
        let rows = clip.num_frames();
        let mut edited = vec![[false; NUM_ARKIT]; rows];
        for (i, t) in clip.times().iter().enumerate() {
            let x = ((t - t0) * MODEL_FPS).clamp(0.0, last as f64);
            let (f0, f1) = (x.floor() as usize, (x.ceil() as usize).min(last));
            let w = (x - f0 as f64) as f32;
            // Rows outside every span keep the input bit for bit, even within one model frame of a span.
            if !inside[i] {
                continue;
            }
            for c in 0..NUM_ARKIT {
                if mask.erased(f0, c) || mask.erased(f1, c) {
                    values[i * stride + c] = after[f0][c] + (after[f1][c] - after[f0][c]) * w;
                    edited[i][c] = true;
                }
            }
        }
        let fade = (JOIN_FADE_S * clip.fps()).round() as usize;
        let orig = clip.values();
        for c in 0..NUM_ARKIT {
            let flags: Vec<bool> = edited.iter().map(|e| e[c]).collect();
            if !flags.iter().any(|e| *e) {
                continue;
            }
            let mut column: Vec<f32> = (0..rows).map(|i| values[i * stride + c]).collect();
            let before: Vec<f32> = (0..rows).map(|i| orig[i * stride + c]).collect();
            join_borders(&mut column, &before, &flags, fade);
            if cut_holds && is_eye_channel(c) {
                // Rows of keys above 0.5 on this shape pin their holds.
                let pinned: Vec<bool> = clip
                    .times()
                    .iter()
                    .map(|t| keys.iter().any(|(f, k)| k[c] > 0.5 && ((t - t0) * MODEL_FPS - *f as f64).abs() < 0.5))
                    .collect();
                limit_hold(&mut column, &before, &flags, &pinned, clip.fps());
            }
            for (i, v) in column.into_iter().enumerate() {
                values[i * stride + c] = v;
            }
        }
        if clip.has_head_eye() && mask.channels().iter().all(|c| *c) {
            fill_head_eye(&mut values, stride, clip.times(), &inside);
        }
        BlendshapeClip::new(clip.fps(), clip.times().to_vec(), clip.has_head_eye(), clip.extra_names().to_vec(), values)
    }
}

/// The model-rate frame of a time in seconds from the first frame (rounded to the nearest).
fn model_frame(time_s: f64) -> usize {
    (time_s * MODEL_FPS).round() as usize
}

/// A shape set by two keys on one frame to different weights: `(key, other key, shape, weight, other weight)`.
type KeyConflict = (usize, usize, usize, f32, f32);

/// Keys grouped by model-rate frame (ascending), each shape with its weight and the key that set it.
#[allow(clippy::type_complexity)]
fn merge_keys(keys: &[KeyPose]) -> Result<Vec<(usize, BTreeMap<usize, (f32, usize)>)>, KeyConflict> {
    let mut frames: BTreeMap<usize, BTreeMap<usize, (f32, usize)>> = BTreeMap::new();
    for (i, k) in keys.iter().enumerate() {
        let shapes = frames.entry(model_frame(k.time_s)).or_default();
        for (c, v) in &k.shapes {
            match shapes.get(c) {
                Some((w, j)) if w != v => return Err((*j, i, *c, *w, *v)),
                Some(_) => {}
                None => {
                    shapes.insert(*c, (*v, i));
                }
            }
        }
    }
    Ok(frames.into_iter().collect())
}

/// Context the network sees on each side of the edited spans (2 s at 25 fps): enough for the BiLSTM
/// to pick up the motion around the gap, and it bounds the cost of an edit in a long clip.
pub const CONTEXT_FRAMES: usize = 50;

/// Run the generator on the window spanning the segments plus [`CONTEXT_FRAMES`] on each side; frames
/// outside the window keep the input.
fn generate_in_window(
    net: &dyn Inpainter,
    before: &[Frame],
    segments: &[Segment],
    channels: &[bool; NUM_ARKIT],
    constraint: &Constraint,
    seed: u64,
) -> Vec<Frame> {
    let n = before.len();
    let first = segments.iter().map(|s| s.start).min().unwrap_or(0);
    let last = segments.iter().map(|s| s.end).max().unwrap_or(n);
    let (w0, w1) = (first.saturating_sub(CONTEXT_FRAMES), (last + CONTEXT_FRAMES).min(n));
    let local: Vec<Segment> =
        segments.iter().map(|s| Segment { start: s.start - w0, end: s.end.min(w1) - w0 }).collect();
    let mask = Mask::from_segments(w1 - w0, &local, channels);
    let noise = input::noise(&mut inbetween_core::seed::rng(seed), w1 - w0);
    let x = input::assemble(&before[w0..w1], &mask, &constraint.crop(w0, w1), &noise);
    let mut out = before.to_vec();
    out[w0..w1].copy_from_slice(&net.generate(&x, w1 - w0));
    out
}

/// Cubic Hermite across each run of `inside` frames for the head/eye channels, from the values and
/// slopes just outside the run.
fn fill_head_eye(values: &mut [f32], stride: usize, times: &[f64], inside: &[bool]) {
    let n = times.len();
    let mut f = 0;
    while f < n {
        if !inside[f] {
            f += 1;
            continue;
        }
        let start = f;
        while f < n && inside[f] {
            f += 1;
        }
        let end = f;
        for c in NUM_ARKIT..NUM_ARKIT + NUM_HEAD_EYE {
            let v = |i: usize| f64::from(values[i * stride + c]);
            let mut knots = Vec::new();
            if start > 0 {
                let a = start - 1;
                let slope = (a > 0).then(|| (v(a) - v(a - 1)) / (times[a] - times[a - 1]));
                knots.push(Knot { t: times[a], v: v(a), slope });
            }
            if end < n {
                let slope = (end + 1 < n).then(|| (v(end + 1) - v(end)) / (times[end + 1] - times[end]));
                knots.push(Knot { t: times[end], v: v(end), slope });
            }
            let Some(curve) = knot_curve(&knots, Interp::Cubic) else { continue };
            for i in start..end {
                values[i * stride + c] = curve.sample_clamped(times[i]) as f32;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::arkit_index;

    /// A 60 fps clip with head/eye channels: smooth waves per channel.
    fn capture(seconds: f64) -> BlendshapeClip {
        let n = (seconds * 60.0) as usize;
        let times: Vec<f64> = (0..n).map(|i| 100.0 + i as f64 / 60.0).collect();
        let stride = NUM_ARKIT + NUM_HEAD_EYE;
        let values = (0..n * stride)
            .map(|k| {
                let (i, c) = (k / stride, k % stride);
                0.5 + 0.3 * ((i as f32) * 0.05 + c as f32).sin()
            })
            .collect();
        BlendshapeClip::new(60.0, times, true, vec![], values).unwrap()
    }

    struct Constant(ConstraintKind, f32);
    impl Inpainter for Constant {
        fn kind(&self) -> ConstraintKind {
            self.0
        }
        fn generate(&self, input: &[f32], frames: usize) -> Vec<Frame> {
            assert_eq!(input.len(), frames * input::input_dim(self.0));
            vec![[self.1; NUM_ARKIT]; frames]
        }
    }

    fn job<'a>(clip: &'a BlendshapeClip, guide: Guide, method: Method<'a>) -> EditJob<'a> {
        EditJob {
            clip,
            spans: vec![(2.0, 3.5)],
            channels: Some([true; NUM_ARKIT]),
            guide,
            method,
            seed: 1,
            limits: EditLimits::default(),
            cancel: Cancel::new(),
            guide_file: None,
            library: None,
        }
    }

    #[test]
    fn frames_outside_the_span_are_untouched_and_inside_change() {
        let clip = capture(6.0);
        let net = Constant(ConstraintKind::None, 0.9);
        let out = job(&clip, Guide::None, Method::Network(&net)).run().unwrap();
        assert_eq!(out.clip.times(), clip.times());
        let t0 = clip.times()[0];
        for (i, t) in clip.times().iter().enumerate() {
            let rel = t - t0;
            if !(1.9..=3.6).contains(&rel) {
                assert_eq!(out.clip.frame(i), clip.frame(i), "frame {i} at {rel} s");
            }
        }
        let mid = clip.times().iter().position(|t| t - t0 >= 2.75).unwrap();
        assert!(out.clip.frame(mid)[..NUM_ARKIT].iter().zip(clip.frame(mid)).any(|(a, b)| (a - b).abs() > 0.05));
        assert!(out.clip.values().iter().take(NUM_ARKIT).all(|v| (0.0..=1.0).contains(v)));
    }

    #[test]
    fn keys_are_hit_exactly_and_unset_shapes_follow_the_input() {
        let clip = capture(6.0);
        let jaw = arkit_index("JawOpen").unwrap();
        let keys = vec![KeyPose { time_s: 3.0, shapes: vec![(jaw, 0.95)] }];
        let net = Constant(ConstraintKind::Keyframes, 0.2);
        let out = job(&clip, Guide::Keys(keys), Method::Network(&net)).run().unwrap();
        let (f, key) = out.keys[0];
        assert_eq!(f, 75);
        assert_eq!(out.after[75][jaw], 0.95);
        assert_eq!(out.after[75], key);
        assert_eq!(out.after[75][0], out.before[75][0]);
        // the 60 fps frame at exactly 3.0 s carries the key too
        let i = clip.times().iter().position(|t| (t - clip.times()[0] - 3.0).abs() < 1e-9).unwrap();
        assert!((out.clip.frame(i)[jaw] - 0.95).abs() < 1e-6);
    }

    #[test]
    fn group_edits_leave_other_groups_alone() {
        let clip = capture(6.0);
        let mut job = job(&clip, Guide::None, Method::Cubic);
        job.channels = Some(crate::edit::groups::parse_groups("mouth,jaw").unwrap());
        let out = job.run().unwrap();
        let blink = arkit_index("EyeBlinkLeft").unwrap();
        for i in 0..clip.num_frames() {
            assert_eq!(out.clip.frame(i)[blink], clip.frame(i)[blink]);
            assert_eq!(out.clip.frame(i)[NUM_ARKIT..], clip.frame(i)[NUM_ARKIT..]);
        }
    }

    /// A network whose output is far from the input at the borders still joins without a step.
    #[test]
    fn network_edits_join_the_input_without_a_step() {
        let clip = capture(6.0);
        let net = Constant(ConstraintKind::None, 0.95);
        let out = job(&clip, Guide::None, Method::Network(&net)).run().unwrap();
        let seg = out.mask.segments()[0];
        // Eye channels held at 0.95 over the whole span are opened in its middle (limit_eye_holds),
        // which at 25 fps moves as fast as a blink; their join is checked at 60 fps on the captures.
        for c in (0..NUM_ARKIT).filter(|c| !crate::edit::seam::is_eye_channel(*c)) {
            let v = |f: usize| out.after[f][c];
            let own = (v(seg.start - 1) - v(seg.start - 2)).abs().max((v(seg.end + 1) - v(seg.end)).abs());
            assert!((v(seg.start) - v(seg.start - 1)).abs() < 2.0 * own + 0.02, "channel {c} start");
            assert!((v(seg.end) - v(seg.end - 1)).abs() < 2.0 * own + 0.02, "channel {c} end");
        }
    }

    #[test]
    fn validation_names_mismatches() {
        let clip = capture(4.0);
        let net = Constant(ConstraintKind::None, 0.5);
        let keys = Guide::Keys(vec![KeyPose { time_s: 3.9, shapes: vec![(0, 0.5)] }]);
        let e = job(&clip, keys.clone(), Method::Network(&net)).validate().unwrap_err().to_string();
        assert!(e.contains("unguided network") && e.contains("keyframes"), "{e}");
        let e = job(&clip, keys, Method::Cubic).validate().unwrap_err().to_string();
        assert!(e.contains("3.900 s") && e.contains("outside"), "{e}");
        let mut late = job(&clip, Guide::None, Method::Linear);
        late.spans = vec![(5.0, 6.0)];
        assert!(late.validate().unwrap_err().to_string().contains("after the clip ends"));
    }

    #[test]
    fn limits_are_checked_before_any_work_and_name_their_field() {
        let clip = capture(6.0);
        let mut j = job(&clip, Guide::None, Method::Linear);
        j.limits.max_rows = 100;
        let e = j.run().unwrap_err();
        assert!(matches!(&e, FaceError::Limit(l) if l.field == "max_rows"), "{e}");
        assert_eq!(e.to_string(), "the clip: 360 rows, more than the limit of 100 rows (max_rows)");
        let mut j = job(&clip, Guide::None, Method::Linear);
        j.spans = vec![(0.5, 1.0), (4.0, 5.0)];
        j.limits.max_mask_s = 4.0;
        let e = j.validate().unwrap_err().to_string();
        assert!(e.contains("4.500 s, more than the limit of 4 s (max_mask_s)"), "{e}");
        j.limits.max_mask_s = 4.5;
        assert!(j.validate().is_ok());
        let mut j = job(&clip, Guide::Noisy(capture(7.0)), Method::Linear);
        j.limits.max_rows = 400;
        j.guide_file = Some("noisy.csv".into());
        let e = j.validate().unwrap_err().to_string();
        assert!(e.starts_with("noisy.csv: the noisy take: 420 rows") && e.contains("(max_rows)"), "{e}");
    }

    #[test]
    fn spans_past_the_end_and_late_visemes_are_refused() {
        let clip = capture(4.0);
        let mut j = job(&clip, Guide::None, Method::Linear);
        j.spans = vec![(3.0, 9.0)];
        let e = j.validate().unwrap_err().to_string();
        assert!(e.contains("runs past the clip's end"), "{e}");
        // A span ending one frame past the last frame's time covers the last frame: accepted.
        j.spans = vec![(3.0, clip.duration() + 1.0 / clip.fps())];
        assert!(j.validate().is_ok());
        let late = Guide::Visemes(vec![(10.0, 10.5, Viseme::Sil), (10.5, 11.0, Viseme::Sil)]);
        let mut j = job(&clip, late, Method::Linear);
        j.guide_file = Some("late.TextGrid".into());
        let e = j.validate().unwrap_err().to_string();
        assert!(e.contains("late.TextGrid: every phoneme lies after the clip's end"), "{e}");
    }

    #[test]
    fn keys_on_one_frame_merge_unless_they_disagree() {
        let clip = capture(6.0);
        let jaw = arkit_index("JawOpen").unwrap();
        let smile = arkit_index("MouthSmileLeft").unwrap();
        let agree = vec![
            KeyPose { time_s: 3.0, shapes: vec![(jaw, 0.9)] },
            KeyPose { time_s: 3.01, shapes: vec![(jaw, 0.9), (smile, 0.4)] },
        ];
        let out = job(&clip, Guide::Keys(agree), Method::Cubic).run().unwrap();
        assert_eq!(out.keys.len(), 1, "one key frame");
        assert_eq!((out.after[75][jaw], out.after[75][smile]), (0.9, 0.4), "both keys' shapes are hit");
        let disagree = vec![
            KeyPose { time_s: 3.0, shapes: vec![(jaw, 0.9)] },
            KeyPose { time_s: 2.0, shapes: vec![(smile, 0.1)] },
            KeyPose { time_s: 2.99, shapes: vec![(jaw, 0.2)] },
        ];
        let mut j = job(&clip, Guide::Keys(disagree), Method::Cubic);
        j.guide_file = Some("k.json".into());
        let e = j.validate().unwrap_err().to_string();
        assert!(e.contains("k.json: keys 0 (3.000 s) and 2 (2.990 s) fall on the same frame"), "{e}");
        assert!(e.contains("JawOpen") && e.contains("0.9 and 0.2"), "{e}");
        let outside = vec![KeyPose { time_s: 5.0, shapes: vec![(jaw, 0.9)] }];
        let mut j = job(&clip, Guide::Keys(outside), Method::Cubic);
        j.guide_file = Some("k.json".into());
        let e = j.validate().unwrap_err().to_string();
        assert!(e.contains("k.json: key 0 at 5.000 s lies outside every edited span (2.000 s..3.500 s)"), "{e}");
    }

    #[test]
    fn a_cancelled_edit_stops_with_the_reason() {
        let clip = capture(6.0);
        let j = job(&clip, Guide::None, Method::Linear);
        j.cancel.cancel();
        assert_eq!(j.run().unwrap_err().to_string(), "face job stopped: cancelled");
        let mut j = job(&clip, Guide::None, Method::Linear);
        j.cancel = Cancel::with_time_limit(std::time::Duration::ZERO);
        assert!(matches!(j.run(), Err(FaceError::Cancelled(inbetween_core::cancel::Cancelled::TimeLimit { .. }))));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED),
            ..proptest::prelude::ProptestConfig::with_cases(32)
        })]

        /// Inputs over a limit are refused by validation (no work done), naming the limit's field.
        #[test]
        fn oversized_edits_are_refused_naming_the_limit(
            rows in 3usize..2000, over in 1usize..500, spans in proptest::collection::vec((0.0f64..1.0, 0.0f64..1.0), 1..6)
        ) {
            let fps = 60.0;
            let n = rows + over;
            let times: Vec<f64> = (0..n).map(|i| i as f64 / fps).collect();
            let clip = BlendshapeClip::new(fps, times, false, vec![], vec![0.5; n * NUM_ARKIT]).unwrap();
            let duration = clip.duration();
            let spans: Vec<(f64, f64)> = spans
                .iter()
                .map(|(a, b)| (a * duration * 0.9, a * duration * 0.9 + (b * 0.09 + 0.001) * duration))
                .collect();
            let mut j = job(&clip, Guide::None, Method::Linear);
            j.spans = spans.clone();
            j.limits.max_rows = rows;
            let e = j.run().unwrap_err();
            proptest::prop_assert!(matches!(&e, FaceError::Limit(l) if l.field == "max_rows"), "{}", e);
            j.limits.max_rows = n;
            let first = spans.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
            let last = spans.iter().map(|s| s.1).fold(0.0, f64::max);
            j.limits.max_mask_s = (last - first) * 0.99;
            let e = j.run().unwrap_err();
            proptest::prop_assert!(matches!(&e, FaceError::Limit(l) if l.field == "max_mask_s"), "{}", e);
        }
    }

    #[test]
    fn head_and_eye_rotations_join_smoothly() {
        let clip = capture(6.0);
        let out = job(&clip, Guide::None, Method::Cubic).run().unwrap();
        let c = NUM_ARKIT;
        let t0 = clip.times()[0];
        let first = clip.times().iter().position(|t| t - t0 >= 2.0).unwrap();
        let v = |i: usize| out.clip.frame(i)[c];
        let step_in = (v(first) - v(first - 1)).abs();
        let step_before = (v(first - 1) - v(first - 2)).abs();
        assert!(step_in < 2.0 * step_before + 1e-4, "{step_in} vs {step_before}");
    }
}
