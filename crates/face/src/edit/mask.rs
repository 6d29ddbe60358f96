//! Masks (§3.1): which frames and channels are erased and must be generated.
//!
//! The paper erases all blendshape coefficients of a frame. Here the mask is per frame *and* channel,
//! so an edit can regenerate only some groups (the mouth) while the network still sees the others.

use rand::Rng;

use crate::data::NUM_ARKIT;

use super::groups::Group;

/// Frames `start..end` (end exclusive) at the model rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// First erased frame.
    pub start: usize,
    /// One past the last erased frame.
    pub end: usize,
}

impl Segment {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.end.saturating_sub(self.start)
    }

    /// Whether the segment holds no frame.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether frame `f` lies in the segment.
    pub fn contains(&self, f: usize) -> bool {
        f >= self.start && f < self.end
    }
}

/// Erased (`true`) or kept entries of a `frames × 52` animation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask {
    frames: usize,
    erased: Vec<bool>,
}

impl Mask {
    /// Nothing erased.
    pub fn none(frames: usize) -> Mask {
        Mask { frames, erased: vec![false; frames * NUM_ARKIT] }
    }

    /// `segments` erased in the selected `channels` (all 52 for the paper's masks).
    pub fn from_segments(frames: usize, segments: &[Segment], channels: &[bool; NUM_ARKIT]) -> Mask {
        let mut m = Mask::none(frames);
        for s in segments {
            for f in s.start..s.end.min(frames) {
                for (c, on) in channels.iter().enumerate() {
                    if *on {
                        m.erased[f * NUM_ARKIT + c] = true;
                    }
                }
            }
        }
        m
    }

    /// Every channel erased on frames `start..end`.
    pub fn span(frames: usize, start: usize, end: usize) -> Mask {
        Mask::from_segments(frames, &[Segment { start, end }], &[true; NUM_ARKIT])
    }

    /// The whole clip erased (the Table 4 protocol and generation from scratch).
    pub fn all(frames: usize) -> Mask {
        Mask { frames, erased: vec![true; frames * NUM_ARKIT] }
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Whether channel `c` of frame `f` is erased.
    pub fn erased(&self, f: usize, c: usize) -> bool {
        self.erased[f * NUM_ARKIT + c]
    }

    /// Every flag, frame-major (`frames × 52`, in [`crate::data::ARKIT_NAMES`] order).
    pub fn flags(&self) -> &[bool] {
        &self.erased
    }

    /// The 52 flags of frame `f`.
    pub fn frame(&self, f: usize) -> &[bool] {
        &self.erased[f * NUM_ARKIT..(f + 1) * NUM_ARKIT]
    }

    /// Whether any channel of frame `f` is erased.
    pub fn frame_erased(&self, f: usize) -> bool {
        self.frame(f).iter().any(|e| *e)
    }

    /// Maximal runs of frames with at least one erased channel.
    pub fn segments(&self) -> Vec<Segment> {
        let mut out = Vec::new();
        let mut start = None;
        for f in 0..=self.frames {
            let on = f < self.frames && self.frame_erased(f);
            match (on, start) {
                (true, None) => start = Some(f),
                (false, Some(s)) => {
                    out.push(Segment { start: s, end: f });
                    start = None;
                }
                _ => {}
            }
        }
        out
    }

    /// Fraction of erased entries.
    pub fn erased_fraction(&self) -> f64 {
        if self.erased.is_empty() {
            return 0.0;
        }
        self.erased.iter().filter(|e| **e).count() as f64 / self.erased.len() as f64
    }

    /// Channels erased anywhere.
    pub fn channels(&self) -> [bool; NUM_ARKIT] {
        let mut ch = [false; NUM_ARKIT];
        for f in 0..self.frames {
            for (c, flag) in ch.iter_mut().enumerate() {
                *flag |= self.erased(f, c);
            }
        }
        ch
    }
}

/// How training masks are drawn (§3.1: "the number and the length of masked segments … are chosen
/// randomly", up to the whole sequence).
#[derive(Clone, Debug)]
pub struct MaskSampling {
    /// Most segments per window.
    pub max_segments: usize,
    /// Probability that the whole window is erased.
    pub whole_clip: f64,
    /// Probability that only some blendshape groups are erased (our extension for group edits).
    pub group_subset: f64,
}

impl Default for MaskSampling {
    fn default() -> Self {
        MaskSampling { max_segments: 3, whole_clip: 0.1, group_subset: 0.2 }
    }
}

/// A random training mask for a window of `frames`: 1..=`max_segments` segments whose lengths are
/// log-uniform between one frame and the whole window.
pub fn random_mask(rng: &mut impl Rng, frames: usize, sampling: &MaskSampling) -> Mask {
    if frames == 0 {
        return Mask::none(0);
    }
    let channels = random_channels(rng, sampling.group_subset);
    if rng.random::<f64>() < sampling.whole_clip {
        return Mask::from_segments(frames, &[Segment { start: 0, end: frames }], &channels);
    }
    let n = rng.random_range(1..=sampling.max_segments.max(1));
    let segments: Vec<Segment> = (0..n)
        .map(|_| {
            let len = ((frames as f64).ln() * rng.random::<f64>()).exp().round().clamp(1.0, frames as f64) as usize;
            let start = rng.random_range(0..=frames - len);
            Segment { start, end: start + len }
        })
        .collect();
    Mask::from_segments(frames, &segments, &channels)
}

fn random_channels(rng: &mut impl Rng, group_subset: f64) -> [bool; NUM_ARKIT] {
    if rng.random::<f64>() >= group_subset {
        return [true; NUM_ARKIT];
    }
    let mut ch = [false; NUM_ARKIT];
    let pick: Vec<Group> = Group::ALL.iter().copied().filter(|_| rng.random::<bool>()).collect();
    let pick = if pick.is_empty() { vec![Group::Mouth, Group::Jaw] } else { pick };
    for (c, flag) in ch.iter_mut().enumerate() {
        *flag = pick.iter().any(|g| g.contains(c));
    }
    ch
}

/// A span as written on the command line: seconds or frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpanSpec {
    /// `4.0s..6.5s` or `4..6.5`.
    Seconds(f64, f64),
    /// `100f..160f` (end exclusive).
    Frames(usize, usize),
}

/// Parse `4.0s..6.5s`, `4..6.5` (seconds) or `100f..160f` (frames); the message says what was expected.
pub fn parse_span_spec(text: &str) -> Result<SpanSpec, String> {
    let expected = "expected START..END in seconds (4.0s..6.5s) or frames (100f..160f)";
    let (a, b) = text.split_once("..").ok_or_else(|| format!("mask '{text}': {expected}"))?;
    let parse = |s: &str| -> Result<(f64, bool), String> {
        let s = s.trim();
        let (num, is_frames) = match s.strip_suffix('f') {
            Some(n) => (n, true),
            None => (s.strip_suffix('s').unwrap_or(s), false),
        };
        let v: f64 = num.trim().parse().map_err(|_| format!("mask '{text}': '{s}' is not a number; {expected}"))?;
        if !v.is_finite() || v < 0.0 {
            return Err(format!("mask '{text}': '{s}' must be a non-negative number; {expected}"));
        }
        Ok((v, is_frames))
    };
    let ((va, fa), (vb, fb)) = (parse(a)?, parse(b)?);
    if fa != fb {
        return Err(format!("mask '{text}': mixes frames and seconds; {expected}"));
    }
    if vb <= va {
        return Err(format!("mask '{text}': the end must come after the start"));
    }
    Ok(if fa { SpanSpec::Frames(va.round() as usize, vb.round() as usize) } else { SpanSpec::Seconds(va, vb) })
}

/// Parse a span (see [`parse_span_spec`]) into model frames `start..end` at `fps`, clipped to a clip of
/// `frames` frames, or a message saying what was expected.
pub fn parse_span(text: &str, fps: f64, frames: usize) -> Result<Segment, String> {
    let (start, end) = match parse_span_spec(text)? {
        SpanSpec::Seconds(a, b) => ((a * fps).round() as usize, ((b * fps).round() as usize).min(frames)),
        SpanSpec::Frames(a, b) => (a, b.min(frames)),
    };
    if start >= frames || end <= start {
        return Err(format!(
            "mask '{text}' lies outside the clip ({frames} frames, {:.2} s at {fps} fps)",
            frames as f64 / fps
        ));
    }
    Ok(Segment { start, end })
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::seed::rng;

    #[test]
    fn segments_round_trip_through_a_mask() {
        let segs = [Segment { start: 2, end: 5 }, Segment { start: 8, end: 10 }];
        let m = Mask::from_segments(12, &segs, &[true; NUM_ARKIT]);
        assert_eq!(m.segments(), segs.to_vec());
        assert!(m.frame_erased(4) && !m.frame_erased(5));
        assert!((m.erased_fraction() - 5.0 / 12.0).abs() < 1e-12);
        assert_eq!(Mask::all(3).segments(), vec![Segment { start: 0, end: 3 }]);
    }

    #[test]
    fn random_masks_cover_short_long_and_whole_segments_and_are_seeded() {
        let sampling = MaskSampling::default();
        let (mut short, mut long, mut whole) = (0, 0, 0);
        for i in 0..400 {
            let m = random_mask(&mut rng(i), 100, &sampling);
            assert_eq!(m, random_mask(&mut rng(i), 100, &sampling));
            let segs = m.segments();
            assert!(!segs.is_empty());
            for s in &segs {
                short += (s.len() <= 5) as usize;
                long += (s.len() >= 50) as usize;
            }
            whole += (segs == vec![Segment { start: 0, end: 100 }]) as usize;
        }
        assert!(short > 20 && long > 20 && whole > 20, "short {short} long {long} whole {whole}");
    }

    #[test]
    fn spans_parse_in_seconds_and_frames() {
        assert_eq!(parse_span("4.0s..6.5s", 25.0, 1000).unwrap(), Segment { start: 100, end: 163 });
        assert_eq!(parse_span("4..6.5", 25.0, 1000).unwrap(), Segment { start: 100, end: 163 });
        assert_eq!(parse_span("10f..20f", 25.0, 1000).unwrap(), Segment { start: 10, end: 20 });
        assert_eq!(parse_span("1s..100s", 25.0, 50).unwrap(), Segment { start: 25, end: 50 });
        for bad in ["4.0", "a..b", "5..4", "-1..2", "100s..200s"] {
            let e = parse_span(bad, 25.0, 50).unwrap_err();
            assert!(e.contains(bad), "{e}");
        }
    }
}
