//! The retrieval prior (issue 25): fill each erased span with a segment of real or procedural motion,
//! motion-graph style, instead of a curve between the borders. A fill made of recorded motion cannot be
//! the mean: it carries whole blinks, speech-like mouth motion and expression changes.
//!
//! For a span of `L` frames the candidates are every `L`-frame segment of the library clips and of the
//! edited clip itself outside its spans. Each is scored on
//! * the **borders**: squared difference of [`RetrievalOptions::context`] frames before and after the
//!   segment against the frames around the span (nearer frames weigh more);
//! * the **constraint**: the keys' weights at their frames (keyframe edits) or the noisy guide inside
//!   the span (noisy edits), weighted by [`RetrievalOptions::key_weight`] / [`RetrievalOptions::guide_weight`].
//!
//! With [`RetrievalOptions::by_region`] (keyframe edits) each face region ([`REGIONS`]: eyes, brows,
//! lower face) is scored on its own channels and drawn apart, so dense keys on the eyes and the mouth
//! can each be met by a segment that passes near them; a region keeps its own channels together (a
//! blink stays both eyes, speech stays jaw and lips).
//!
//! Segments of the library cost [`RetrievalOptions::library_cost`] times their score (issue 40): the
//! person's own motion, the clip outside the span, is preferred to anyone else's or to procedural
//! motion, which only wins where it matches clearly better (on captures the library never saw, the
//! procedural library's speech made unguided mouths move 2.7× their speed outside the span).
//!
//! A noisy guide is **cleaned, not replaced** ([`RetrievalOptions::clean_guide`], issue 40): the
//! calibrated guide itself is the fill, each shape smoothed by the filter that best reproduces the
//! kept frames around the span from the guide there ([`clean_guide`]); no segment is drawn.
//!
//! The seed picks one of the best [`RetrievalOptions::candidates`] non-overlapping segments (rank
//! `seed mod k`), so consecutive seeds give different plausible fills and the same seed the same one. The segment is joined by offsets that fade out over [`RetrievalOptions::blend`]
//! frames from each border (a blink in the segment stays a whole blink; a long fade would hold an eye
//! half closed), and with a noisy guide the low frequencies of `guide − segment` are added (the guide says
//! what happened slowly, the segment how a face moves quickly). The edit's post-processing then hits keys
//! exactly ([`super::correct`]).

use inbetween_core::interp::smoothstep;

use crate::data::NUM_ARKIT;

use std::sync::Arc;

use super::constraints::{Constraint, ConstraintKind};
use super::groups::Group;
use super::mask::{Mask, Segment};
use super::Frame;

/// Motion to fill gaps from: clips at the model rate (25 fps). A clone shares the frames (the
/// default library is made once per process and handed to every edit,
/// [`crate::infer::setup::default_library`]).
#[derive(Clone, Debug, Default)]
pub struct MotionLibrary {
    clips: Arc<Vec<Vec<Frame>>>,
}

impl MotionLibrary {
    /// A library of clips (each at the model rate).
    pub fn new(clips: Vec<Vec<Frame>>) -> Self {
        MotionLibrary { clips: Arc::new(clips) }
    }

    /// `seconds` of procedural faces (blinks, speech, expressions, gaze) in 20 s clips, drawn with `seed`.
    pub fn procedural(seconds: f64, seed: u64) -> Self {
        let n = (seconds / 20.0).ceil().max(1.0) as usize;
        let clips =
            crate::procedural::generate_corpus(n, 20.0, seed).into_iter().map(|p| p.clip.arkit_frames()).collect();
        MotionLibrary::new(clips)
    }

    /// Add a clip (to this library only: a clone that shared the frames keeps its own).
    pub fn push(&mut self, clip: Vec<Frame>) {
        Arc::make_mut(&mut self.clips).push(clip);
    }

    /// Frames in all clips.
    pub fn frames(&self) -> usize {
        self.clips.iter().map(Vec::len).sum()
    }

    /// The clips.
    pub fn clips(&self) -> &[Vec<Frame>] {
        &self.clips
    }
}

/// How segments are scored, drawn and joined.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RetrievalOptions {
    /// Frames compared on each side of the span (default 8: 0.32 s).
    pub context: usize,
    /// Frames over which the border offsets fade out (default 6: 0.24 s).
    pub blend: usize,
    /// Best non-overlapping segments the seed picks from (default 4; consecutive seeds give this many
    /// different fills).
    pub candidates: usize,
    /// Weight of the keys' cost against the borders' (per entry; default 4).
    pub key_weight: f64,
    /// Weight of the noisy guide's cost against the borders' (per entry; default 1).
    pub guide_weight: f64,
    /// Frames of the moving average, applied twice, taken of `guide − fill` (default 37: 1.5 s; shorter
    /// lets the tracker's jitter through, measured in `face bench`).
    pub guide_smoothing: usize,
    /// Scale of the segment's motion around its own border line, on every channel but the eyelids
    /// (default 1: the segment's motion as recorded).
    pub detail: f64,
    /// Draw one segment per face region (eyes, brows, lower face: [`REGIONS`]) instead of one for the
    /// whole face, each scored on its own channels' borders and keys (default false;
    /// [`RetrievalOptions::for_kind`] sets it for keyframes, where it is measured to help).
    pub by_region: bool,
    /// Factor on the cost of the library's segments against the edited clip's own (default 2: the
    /// person's own motion is preferred).
    pub library_cost: f64,
    /// With a noisy guide, fill with the guide itself, calibrated and cleaned ([`clean_guide`]),
    /// instead of drawing a segment (default true; false is the segment matched to the guide with
    /// the guide's slow residual added, as before issue 40).
    pub clean_guide: bool,
}

impl Default for RetrievalOptions {
    fn default() -> Self {
        RetrievalOptions {
            context: 8,
            blend: 6,
            candidates: 4,
            key_weight: 16.0,
            guide_weight: 1.0,
            guide_smoothing: 37,
            detail: 1.0,
            by_region: false,
            library_cost: 2.0,
            clean_guide: true,
        }
    }
}

impl RetrievalOptions {
    /// The defaults for a constraint type: regions drawn apart for keyframe edits (`face bench` on
    /// held-out captures: masked MSE 1.62× → 1.27× linear's and the two-sample AUC 0.87 → 0.82 with
    /// the real split, as dense keys are hit by smaller bends), one draw for the whole face otherwise
    /// (with the procedural library, regions raised the noisy AUC 0.64 → 0.78).
    pub fn for_kind(kind: ConstraintKind) -> Self {
        RetrievalOptions { by_region: kind == ConstraintKind::Keyframes, ..Default::default() }
    }

    /// [`RetrievalOptions::for_kind`] with enough candidates that seeds `S … S + variants − 1`
    /// each draw a different segment (`face edit --variants`, the studio's variants).
    pub fn for_variants(kind: ConstraintKind, variants: usize) -> Self {
        let o = RetrievalOptions::for_kind(kind);
        RetrievalOptions { candidates: o.candidates.max(variants), ..o }
    }
}

/// Where a segment comes from: `clip` indexes the library, `None` the edited clip itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Source {
    /// Library clip, or `None` for the edited clip.
    pub clip: Option<usize>,
    /// First frame of the segment.
    pub start: usize,
    /// Its cost (lower is a better match).
    pub cost: f64,
}

/// Fill every erased span of `anim` from `library` (and from `anim` outside its spans). Entries outside
/// the mask are `anim`'s; inside, the drawn segments joined as the module docs say. Returns the frames and,
/// per span, the sources drawn: one for the whole face, or one per region with
/// [`RetrievalOptions::by_region`] (none when no segment of the span's length exists anywhere: those
/// channels keep `anim`'s values, and the caller's post-processing interpolates them; none when a
/// noisy guide was cleaned).
pub fn retrieve(
    anim: &[Frame],
    mask: &Mask,
    constraint: &Constraint,
    library: &MotionLibrary,
    options: &RetrievalOptions,
    seed: u64,
) -> (Vec<Frame>, Vec<Vec<Source>>) {
    let n = anim.len();
    let spans = mask.segments();
    let mut out = anim.to_vec();
    let mut sources = Vec::with_capacity(spans.len());
    for span in &spans {
        let erased: Vec<usize> =
            (0..NUM_ARKIT).filter(|c| (span.start..span.end).any(|f| mask.erased(f, *c))).collect();
        if let (Constraint::Noisy(g), true) = (constraint, options.clean_guide) {
            let cleaned = clean_guide(anim, mask, g, *span);
            for (t, row) in cleaned.iter().enumerate() {
                for &c in &erased {
                    out[span.start + t][c] = row[c];
                }
            }
            sources.push(Vec::new());
            continue;
        }
        let guide = match constraint {
            Constraint::Noisy(g) => Some(calibrate_guide(anim, mask, g, *span)),
            _ => None,
        };
        let regions: Vec<Vec<usize>> = if options.by_region {
            REGIONS
                .iter()
                .map(|r| erased.iter().copied().filter(|&c| r.iter().any(|g| g.contains(c))).collect::<Vec<_>>())
                .filter(|r| !r.is_empty())
                .collect()
        } else {
            vec![erased]
        };
        let mut drawn = Vec::with_capacity(regions.len());
        for (ri, channels) in regions.iter().enumerate() {
            let scorer = Scorer { anim, guide: guide.as_deref(), span: *span, channels, constraint, options, n };
            let mut cands: Vec<Source> = Vec::new();
            for (i, clip) in library.clips.iter().enumerate() {
                let from = cands.len();
                scorer.scan(clip, Some(i), &[], &mut cands);
                for c in &mut cands[from..] {
                    c.cost *= options.library_cost;
                }
            }
            scorer.scan(anim, None, &spans, &mut cands);
            let Some(chosen) = draw(&mut cands, span.len(), options.candidates, region_seed(seed, ri)) else {
                continue;
            };
            let seg: &[Frame] = match chosen.clip {
                Some(i) => &library.clips[i],
                None => anim,
            };
            join(&mut out, anim, seg, chosen.start, *span, channels, guide.as_deref(), options);
            drawn.push(chosen);
        }
        sources.push(drawn);
    }
    (out, sources)
}

/// Face regions drawn apart with [`RetrievalOptions::by_region`]: eyes, brows, lower face (jaw,
/// mouth, cheeks and nose, tongue move together in speech).
pub const REGIONS: [&[Group]; 3] =
    [&[Group::Eyes], &[Group::Brows], &[Group::Jaw, Group::Mouth, Group::Cheeks, Group::Tongue]];

/// The first region draws with `seed` itself (so a whole-face draw is unchanged), the others with
/// derived seeds.
fn region_seed(seed: u64, region: usize) -> u64 {
    if region == 0 {
        seed
    } else {
        inbetween_core::seed::derive(seed, region as u64)
    }
}

struct Scorer<'a> {
    anim: &'a [Frame],
    /// The calibrated noisy guide over the span, if any.
    guide: Option<&'a [Frame]>,
    span: Segment,
    channels: &'a [usize],
    constraint: &'a Constraint,
    options: &'a RetrievalOptions,
    n: usize,
}

impl Scorer<'_> {
    /// Push every segment of `clip` of the span's length (none overlapping `avoid` with its context).
    fn scan(&self, clip: &[Frame], id: Option<usize>, avoid: &[Segment], out: &mut Vec<Source>) {
        let (a, b, len) = (self.span.start, self.span.end, self.span.len());
        let before = self.options.context.min(a);
        let after = self.options.context.min(self.n - b);
        if clip.len() < before + len + after {
            return;
        }
        let keys: Vec<(usize, &Frame)> = match self.constraint {
            Constraint::Keyframes(k) => {
                k.iter().filter(|(f, _)| self.span.contains(*f)).map(|(f, v)| (*f, v)).collect()
            }
            _ => Vec::new(),
        };
        let guide = self.guide;
        let nc = self.channels.len().max(1) as f64;
        for s in before..=clip.len() - len - after {
            let (lo, hi) = (s - before, s + len + after);
            if avoid.iter().any(|v| lo < v.end && v.start < hi) {
                continue;
            }
            let (mut border, mut wsum) = (0.0f64, 0.0f64);
            for k in 1..=before {
                let w = 1.0 / k as f64;
                border += w * sq(&clip[s - k], &self.anim[a - k], self.channels);
                wsum += w;
            }
            for k in 0..after {
                let w = 1.0 / (k + 1) as f64;
                border += w * sq(&clip[s + len + k], &self.anim[b + k], self.channels);
                wsum += w;
            }
            let mut cost = if wsum > 0.0 { border / (wsum * nc) } else { 0.0 };
            if !keys.is_empty() {
                let e: f64 = keys.iter().map(|(f, v)| sq(&clip[s + f - a], v, self.channels)).sum();
                cost += self.options.key_weight * e / (keys.len() as f64 * nc);
            }
            if let Some(g) = guide {
                let e: f64 = (0..len).map(|t| sq(&clip[s + t], &g[t], self.channels)).sum();
                cost += self.options.guide_weight * e / (len as f64 * nc);
            }
            out.push(Source { clip: id, start: s, cost });
        }
    }
}

fn sq(x: &Frame, y: &Frame, channels: &[usize]) -> f64 {
    channels.iter().map(|&c| f64::from(x[c] - y[c]).powi(2)).sum()
}

/// The best `k` non-overlapping candidates by cost (two overlap when they come from the same clip and start
/// less than half a span apart); the seed picks rank `seed mod` their number, so seeds `S, S+1, …, S+k−1`
/// give `k` different segments.
fn draw(cands: &mut [Source], len: usize, k: usize, seed: u64) -> Option<Source> {
    cands.sort_by(|x, y| x.cost.total_cmp(&y.cost).then(x.start.cmp(&y.start)));
    let mut best: Vec<Source> = Vec::new();
    for c in cands.iter() {
        if best.len() >= k.max(1) {
            break;
        }
        if best.iter().any(|b| b.clip == c.clip && b.start.abs_diff(c.start) * 2 < len.max(2)) {
            continue;
        }
        best.push(*c);
    }
    if best.is_empty() {
        return None;
    }
    Some(best[(seed % best.len() as u64) as usize])
}

/// Write segment `seg[start..start + len]` into `out` over `span` (see the module docs for the join).
#[allow(clippy::too_many_arguments)]
fn join(
    out: &mut [Frame],
    anim: &[Frame],
    seg: &[Frame],
    start: usize,
    span: Segment,
    channels: &[usize],
    guide: Option<&[Frame]>,
    options: &RetrievalOptions,
) {
    let (a, b, len) = (span.start, span.end, span.len());
    let n = anim.len();
    let fade = |t: usize| 1.0 - smoothstep((t + 1) as f64 / (options.blend + 1) as f64);
    let blink = [crate::data::arkit_index("EyeBlinkLeft"), crate::data::arkit_index("EyeBlinkRight")];
    for &c in channels {
        // Values just outside the span, in the clip and in the segment's source.
        let (x0, x1) = ((a > 0).then(|| anim[a - 1][c]), (b < n).then(|| anim[b][c]));
        let (s0, s1) = ((start > 0).then(|| seg[start - 1][c]), (start + len < seg.len()).then(|| seg[start + len][c]));
        let d0 = x0.zip(s0).map(|(x, s)| f64::from(x - s));
        let d1 = x1.zip(s1).map(|(x, s)| f64::from(x - s));
        let mut v: Vec<f64> = if blink.contains(&Some(c)) {
            // Eyelids: short fades, so a blink at a border closes or opens in time, never held.
            (0..len)
                .map(|t| {
                    f64::from(seg[start + t][c])
                        + d0.map_or(0.0, |d| d * fade(t))
                        + d1.map_or(0.0, |d| d * fade(len - 1 - t))
                })
                .collect()
        } else {
            // Level from the borders, motion from the segment (scaled by `detail`).
            (0..len)
                .map(|t| {
                    // An eased level (no straight ramp where the segment itself is still).
                    let w = smoothstep((t + 1) as f64 / (len + 1) as f64);
                    let lerp = |p: Option<f64>, q: Option<f64>| match (p, q) {
                        (Some(p), Some(q)) => p + (q - p) * w,
                        (Some(p), None) | (None, Some(p)) => p,
                        (None, None) => 0.0,
                    };
                    let level = lerp(x0.map(f64::from), x1.map(f64::from));
                    let seg_level = lerp(s0.map(f64::from), s1.map(f64::from));
                    let has_level = x0.is_some() || x1.is_some();
                    let detail = f64::from(seg[start + t][c]) - if has_level { seg_level } else { 0.0 };
                    if has_level {
                        level + options.detail * detail
                    } else {
                        detail
                    }
                })
                .collect()
        };
        // Eyelids take no guide residual: the segment was drawn to blink with the guide, and a tracker's
        // smoothed blink added as a slow bump would hold the eye half closed.
        if let (Some(g), false) = (guide, blink.contains(&Some(c))) {
            let raw: Vec<f64> = (0..len).map(|t| f64::from(g[t][c]) - v[t]).collect();
            for (x, r) in v
                .iter_mut()
                .zip(moving_average(&moving_average(&raw, options.guide_smoothing), options.guide_smoothing))
            {
                *x += r;
            }
        }
        for (t, x) in v.into_iter().enumerate() {
            out[a + t][c] = x.clamp(0.0, 1.0) as f32;
        }
    }
}

/// Frames on each side of a span used to calibrate the noisy guide (2 s).
const CALIBRATION_FRAMES: usize = 50;
/// Largest lag, in frames, searched between the guide and the clip.
const MAX_LAG: isize = 8;

/// The noisy guide over `span`, calibrated on the kept frames around it: one lag for all shapes (the one
/// that best lines the guide up with the clip), then per shape a gain and bias fitted by least squares
/// (pulled towards gain 1, bias 0 by a ridge term, gain kept in [0.25, 4]). A tracker's lag, gain and
/// bias are what the kept frames can reveal; jitter and dropouts are left to the smoothing in [`join`].
pub fn calibrate_guide(anim: &[Frame], mask: &Mask, guide: &[Frame], span: Segment) -> Vec<Frame> {
    let n = anim.len().min(guide.len());
    let (a, b) = (span.start, span.end.min(n));
    let (lag, fit) = calibration(anim, mask, guide, span);
    calibrated(guide, lag, &fit, a..b)
}

/// Per shape `(gain, bias)`.
type Fit = [(f64, f64); NUM_ARKIT];

/// The guide's frames `range`, moved by `lag` frames and mapped by `fit`.
fn calibrated(guide: &[Frame], lag: isize, fit: &Fit, range: std::ops::Range<usize>) -> Vec<Frame> {
    let n = guide.len();
    range
        .map(|f| {
            let g = &guide[(f as isize + lag).clamp(0, n as isize - 1) as usize];
            std::array::from_fn(|c| (fit[c].0 * f64::from(g[c]) + fit[c].1).clamp(0.0, 1.0) as f32)
        })
        .collect()
}

/// The lag and per-shape gain and bias of [`calibrate_guide`].
fn calibration(anim: &[Frame], mask: &Mask, guide: &[Frame], span: Segment) -> (isize, Fit) {
    let n = anim.len().min(guide.len());
    let (a, b) = (span.start, span.end.min(n));
    let kept: Vec<usize> = (a.saturating_sub(CALIBRATION_FRAMES)..a)
        .chain(b..(b + CALIBRATION_FRAMES).min(n))
        .filter(|f| !mask.frame_erased(*f))
        .collect();
    let at = |f: usize, lag: isize| -> usize { (f as isize + lag).clamp(0, n as isize - 1) as usize };
    let lag = (-MAX_LAG..=MAX_LAG)
        .min_by(|x, y| {
            let e = |l: isize| -> f64 { kept.iter().map(|&f| sq(&anim[f], &guide[at(f, l)], &ALL)).sum() };
            e(*x).total_cmp(&e(*y)).then(x.abs().cmp(&y.abs()))
        })
        .unwrap_or(0);
    let mut fit = [(1.0f64, 0.0f64); NUM_ARKIT];
    if kept.len() >= 4 {
        let k = kept.len() as f64;
        for (c, fc) in fit.iter_mut().enumerate() {
            let (mut mg, mut my) = (0.0, 0.0);
            for &f in &kept {
                mg += f64::from(guide[at(f, lag)][c]);
                my += f64::from(anim[f][c]);
            }
            mg /= k;
            my /= k;
            let (mut cov, mut var) = (0.0, 0.0);
            for &f in &kept {
                let g = f64::from(guide[at(f, lag)][c]) - mg;
                cov += g * (f64::from(anim[f][c]) - my);
                var += g * g;
            }
            // Ridge towards gain 1: a flat guide around the span says nothing about its gain.
            let ridge = 0.01 * k * 0.01;
            let gain = ((cov + ridge) / (var + ridge)).clamp(0.25, 4.0);
            *fc = (gain, my - gain * mg);
        }
    }
    (lag, fit)
}

/// Smoothing widths [`clean_guide`] chooses from (frames of a centred moving average; 1 = none).
const CLEAN_WIDTHS: [usize; 6] = [1, 3, 5, 7, 9, 13];

/// The noisy guide over `span`, calibrated as [`calibrate_guide`] does (or as it is, when that
/// reproduces the kept frames better) and cleaned: per shape, a
/// centred median (none, 3 or 5 frames: a dropout's held values and spikes) then a moving average
/// ([`CLEAN_WIDTHS`]), the pair that best reproduces the kept frames within
/// [`CALIBRATION_FRAMES`] of the span from the calibrated guide there. The kept frames show how noisy
/// the tracker is, so a clean take is left as it is and a noisy one smoothed as much as it needs.
pub fn clean_guide(anim: &[Frame], mask: &Mask, guide: &[Frame], span: Segment) -> Vec<Frame> {
    let n = anim.len().min(guide.len());
    let (a, b) = (span.start, span.end.min(n));
    let (w0, w1) = (a.saturating_sub(CALIBRATION_FRAMES), (b + CALIBRATION_FRAMES).min(n));
    let (lag, fit) = calibration(anim, mask, guide, span);
    let g = calibrated(guide, lag, &fit, w0..w1);
    // The take as it is competes too: a clean take needs no calibration.
    let raw = calibrated(guide, 0, &[(1.0, 0.0); NUM_ARKIT], w0..w1);
    let mut out: Vec<Frame> = g[a - w0..b - w0].to_vec();
    for c in 0..NUM_ARKIT {
        let kept: Vec<usize> = (w0..w1).filter(|f| !mask.erased(*f, c)).collect();
        if kept.is_empty() {
            continue;
        }
        let mut best = (f64::INFINITY, Vec::new());
        for source in [&g, &raw] {
            let x: Vec<f64> = source.iter().map(|f| f64::from(f[c])).collect();
            for median in [1, 3, 5] {
                let m = moving_median(&x, median);
                for width in CLEAN_WIDTHS {
                    let y = moving_average(&m, width);
                    let e: f64 = kept.iter().map(|&f| (y[f - w0] - f64::from(anim[f][c])).powi(2)).sum();
                    if e < best.0 {
                        best = (e, y);
                    }
                }
            }
        }
        for (t, row) in out.iter_mut().enumerate() {
            row[c] = best.1[a - w0 + t].clamp(0.0, 1.0) as f32;
        }
    }
    out
}

/// Centred moving median over `width` samples (shrinking at the ends).
fn moving_median(x: &[f64], width: usize) -> Vec<f64> {
    let h = width / 2;
    (0..x.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(h), (i + h + 1).min(x.len()));
            let mut w = x[lo..hi].to_vec();
            w.sort_by(f64::total_cmp);
            w[w.len() / 2]
        })
        .collect()
}

const ALL: [usize; NUM_ARKIT] = {
    let mut a = [0; NUM_ARKIT];
    let mut i = 0;
    while i < NUM_ARKIT {
        a[i] = i;
        i += 1;
    }
    a
};

/// Centred moving average over `width` samples (shrinking at the ends).
fn moving_average(x: &[f64], width: usize) -> Vec<f64> {
    let h = width / 2;
    (0..x.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(h), (i + h + 1).min(x.len()));
            x[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clip whose channel 0 blinks (0 → 1 → 0 over 5 frames) every 40 frames and whose channel 1 ramps.
    fn blinking(n: usize, phase: usize) -> Vec<Frame> {
        (0..n)
            .map(|f| {
                let mut x = [0.1f32; NUM_ARKIT];
                let p = (f + phase) % 40;
                x[0] = if p < 5 { [0.3, 0.8, 1.0, 0.8, 0.3][p] } else { 0.05 };
                x[1] = 0.3 + 0.2 * ((f as f32) * 0.05).sin();
                x
            })
            .collect()
    }

    fn gap(n: usize, a: usize, b: usize) -> Mask {
        Mask::span(n, a, b)
    }

    #[test]
    fn a_fill_from_recorded_motion_keeps_whole_blinks_and_the_kept_frames() {
        let anim = blinking(400, 0);
        let mask = gap(400, 150, 250);
        let lib = MotionLibrary::new(vec![blinking(300, 17)]);
        let (out, src) = retrieve(&anim, &mask, &Constraint::None, &lib, &RetrievalOptions::default(), 3);
        assert_eq!(src[0].len(), 1);
        for f in (0..150).chain(250..400) {
            assert_eq!(out[f], anim[f], "frame {f} outside the gap changed");
        }
        // 100 frames at one blink per 40: two whole blinks inside, each closing and opening again.
        let closed: Vec<bool> = (150..250).map(|f| out[f][0] > 0.5).collect();
        let onsets = closed.windows(2).filter(|w| !w[0] && w[1]).count();
        assert!(onsets >= 2, "expected whole blinks in the fill, got {onsets} onsets");
        let longest = closed.split(|c| !c).map(<[bool]>::len).max().unwrap_or(0);
        assert!(longest <= 5, "an eye stayed closed {longest} frames: not a blink");
    }

    #[test]
    fn the_seed_draws_the_fill_and_the_same_seed_repeats_it() {
        let anim = blinking(300, 0);
        let mask = gap(300, 100, 160);
        let lib = MotionLibrary::new((0..6).map(|p| blinking(200, 3 * p)).collect());
        let opts = RetrievalOptions { candidates: 8, ..Default::default() };
        let run = |s| retrieve(&anim, &mask, &Constraint::None, &lib, &opts, s).1[0].first().copied();
        assert_eq!(run(1), run(1));
        let distinct: std::collections::HashSet<_> =
            (0..12).map(|s| format!("{:?}", run(s).map(|x| (x.clip, x.start)))).collect();
        assert!(distinct.len() > 1, "twelve seeds drew the same segment");
    }

    #[test]
    fn the_candidates_never_read_the_erased_frames_of_the_clip_itself() {
        // The truth inside the gap is a unique bump; an empty library leaves only the clip itself.
        let mut anim = blinking(300, 0);
        for f in &mut anim[120..140] {
            f[5] = 0.9;
        }
        let mask = gap(300, 120, 140);
        let (_, src) =
            retrieve(&anim, &mask, &Constraint::None, &MotionLibrary::default(), &RetrievalOptions::default(), 0);
        let s = src[0].first().copied().expect("the clip outside the gap has 20-frame segments");
        assert!(s.start + 20 + 8 <= 120 || s.start >= 140 + 8, "segment {s:?} overlaps the gap or its context");
    }

    #[test]
    fn keys_pull_the_draw_towards_segments_that_pass_near_them() {
        let anim = blinking(300, 0);
        let mask = gap(300, 100, 140);
        // Library: one clip where channel 7 is 0.9 in the middle of every 40-frame stretch, one where it is 0.
        let mut high = blinking(200, 0);
        for (f, x) in high.iter_mut().enumerate() {
            x[7] = if f % 40 >= 15 && f % 40 < 25 { 0.9 } else { 0.1 };
        }
        let lib = MotionLibrary::new(vec![blinking(200, 0), high]);
        let mut key = anim[120];
        key[7] = 0.9;
        let cons = Constraint::Keyframes(vec![(120, key)]);
        let opts = RetrievalOptions { candidates: 1, ..Default::default() };
        let (out, src) = retrieve(&anim, &mask, &cons, &lib, &opts, 0);
        assert_eq!(src[0][0].clip, Some(1));
        assert!(out[120][7] > 0.7, "the drawn segment passes near the key ({})", out[120][7]);
    }

    #[test]
    fn regions_draw_their_own_segments_so_keys_on_eyes_and_mouth_are_both_met() {
        let (eye, jaw) =
            (crate::data::arkit_index("EyeSquintLeft").unwrap(), crate::data::arkit_index("JawOpen").unwrap());
        let anim = blinking(300, 0);
        let mask = gap(300, 100, 140);
        // Clip 0 squints mid-stretch with the mouth shut, clip 1 opens the mouth with the eyes relaxed.
        let stretch = |f: usize| f % 40 >= 15 && f % 40 < 25;
        let mut squint = blinking(200, 0);
        let mut talk = blinking(200, 0);
        for f in 0..200 {
            squint[f][eye] = if stretch(f) { 0.9 } else { 0.1 };
            talk[f][jaw] = if stretch(f) { 0.9 } else { 0.1 };
        }
        let lib = MotionLibrary::new(vec![squint, talk]);
        let mut key = anim[120];
        (key[eye], key[jaw]) = (0.9, 0.9);
        let cons = Constraint::Keyframes(vec![(120, key)]);
        let whole = RetrievalOptions { candidates: 1, ..Default::default() };
        let (out, src) = retrieve(&anim, &mask, &cons, &lib, &whole, 0);
        assert_eq!(src[0].len(), 1);
        assert!(out[120][eye].min(out[120][jaw]) < 0.5, "one segment cannot meet both keys");
        let regions = RetrievalOptions { by_region: true, ..whole };
        assert_eq!(
            RetrievalOptions::for_kind(ConstraintKind::Keyframes),
            RetrievalOptions { candidates: 4, ..regions }
        );
        let (out, src) = retrieve(&anim, &mask, &cons, &lib, &regions, 0);
        assert_eq!(src[0].len(), REGIONS.len(), "eyes, brows and lower face each drawn");
        assert_eq!((src[0][0].clip, src[0][2].clip), (Some(0), Some(1)));
        assert!(out[120][eye] > 0.7 && out[120][jaw] > 0.7, "{} {}", out[120][eye], out[120][jaw]);
        for f in (0..100).chain(140..300) {
            assert_eq!(out[f], anim[f], "frame {f} outside the gap changed");
        }
    }

    #[test]
    fn no_segment_long_enough_leaves_the_span_to_the_post_processing() {
        let anim = blinking(60, 0);
        let mask = gap(60, 10, 50);
        let (out, src) =
            retrieve(&anim, &mask, &Constraint::None, &MotionLibrary::default(), &RetrievalOptions::default(), 0);
        assert_eq!(src, vec![Vec::<Source>::new()]);
        assert_eq!(out, anim);
    }
}
