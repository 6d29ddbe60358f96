//! The evaluation metrics of §6.3: stability M_D (Eq. 21) and the degree of difference Δo
//! (Eq. 22–23).

use image::RgbImage;

use crate::VideoError;

/// M_D of Eq. 21: the mean over the transitions of `order` of `D = ‖F_t − F_{t−1}‖`, taken as the
/// RMS per-channel difference with pixel values scaled to [0, 1] (so D and M_D lie in [0, 1] and
/// do not grow with the frame size; the paper does not say its normalisation, its values
/// 0.037–0.067 fit this range). The source order `0, 1, …, n − 1` gives the ground-truth M_D.
/// An order with fewer than two frames has no transition: 0. An index out of range or frames of
/// different sizes give NaN (see [`try_stability_md`] for the error that says which).
pub fn stability_md(frames: &[RgbImage], order: &[usize]) -> f64 {
    try_stability_md(frames, order).unwrap_or(f64::NAN)
}

/// [`stability_md`], with an error naming the frame out of range or the frames whose sizes differ.
pub fn try_stability_md(frames: &[RgbImage], order: &[usize]) -> Result<f64, VideoError> {
    if let Some(&bad) = order.iter().find(|&&i| i >= frames.len()) {
        return Err(VideoError::Invalid(format!(
            "M_D: frame {bad} is out of range (the clip has {} frames)",
            frames.len()
        )));
    }
    if order.len() < 2 {
        return Ok(0.0);
    }
    let diffs =
        order.windows(2).map(|w| frame_rms(&frames[w[0]], &frames[w[1]], w[0], w[1])).collect::<Result<Vec<_>, _>>()?;
    Ok(diffs.iter().sum::<f64>() / diffs.len() as f64)
}

/// M_D of the source order itself (the "ground truth" column of Table 2).
pub fn source_md(frames: &[RgbImage]) -> f64 {
    stability_md(frames, &(0..frames.len()).collect::<Vec<_>>())
}

/// `D` of Eq. 21 for one transition: RMS difference in [0, 1].
pub fn frame_rms(a: &RgbImage, b: &RgbImage, ia: usize, ib: usize) -> Result<f64, VideoError> {
    if a.dimensions() != b.dimensions() {
        return Err(VideoError::Invalid(format!(
            "M_D: frame {ia} is {}x{} but frame {ib} is {}x{}",
            a.width(),
            a.height(),
            b.width(),
            b.height()
        )));
    }
    let n = a.as_raw().len();
    if n == 0 {
        return Ok(0.0);
    }
    let sq: f64 = a.as_raw().iter().zip(b.as_raw()).map(|(&x, &y)| ((x as f64 - y as f64) / 255.0).powi(2)).sum();
    Ok((sq / n as f64).sqrt())
}

/// P, R and Δo of Eq. 22–23 for one generated order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overlap {
    /// δ: transitions of the new order that are source transitions `f → f + 1`.
    pub overlap: usize,
    /// d_G: transitions of the new order; d_T: transitions of the source.
    pub generated: usize,
    pub source: usize,
    pub precision: f64,
    pub recall: f64,
    /// Δo = 2PR / (P + R), as a fraction in [0, 1] (Table 2 prints it so; the paper's "× 100%"
    /// is the same number as a percentage). Smaller means a more novel order.
    pub delta_o: f64,
}

/// Eq. 22–23. Durations are counted in transitions (frame pairs): the "temporal overlap" δ is the
/// number of steps `f → f + 1` of the new order, which play exactly as in the source; d_G is the
/// new order's step count and d_T the source's (`source_len − 1`). The source order itself has
/// P = R = Δo = 1. With no step on either side P or R is 0, and so is Δo.
pub fn overlap(order: &[usize], source_len: usize) -> Overlap {
    let overlap = order.windows(2).filter(|w| w[1] == w[0] + 1 && w[1] < source_len).count();
    let generated = order.len().saturating_sub(1);
    let source = source_len.saturating_sub(1);
    let ratio = |d: usize| if d == 0 { 0.0 } else { overlap as f64 / d as f64 };
    let (precision, recall) = (ratio(generated), ratio(source));
    let delta_o = if precision + recall > 0.0 { 2.0 * precision * recall / (precision + recall) } else { 0.0 };
    Overlap { overlap, generated, source, precision, recall, delta_o }
}

/// Δo of Eq. 23 for `order` against a source of `source_len` frames.
pub fn overlap_delta_o(order: &[usize], source_len: usize) -> f64 {
    overlap(order, source_len).delta_o
}

/// The share of a source of `source_len` frames that `order` shows at least once, in [0, 1]
/// (issue 41: a new order of the source's length should show most of it, not a few frames over
/// and over). Indices out of range are ignored.
pub fn distinct_fraction(order: &[usize], source_len: usize) -> f64 {
    if source_len == 0 {
        return 0.0;
    }
    let mut seen = vec![false; source_len];
    order.iter().filter(|&&f| f < source_len).for_each(|&f| seen[f] = true);
    seen.iter().filter(|&&s| s).count() as f64 / source_len as f64
}

/// A block of frames played several times in a row in an order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Cycle {
    /// Frames in one play of the block.
    pub period: usize,
    /// Complete plays in a row (at least 2 for a repeated cycle).
    pub repeats: usize,
    /// Position of its first frame in the order.
    pub at: usize,
}

impl Cycle {
    /// Frames the repeats cover, `period × repeats`.
    pub fn frames(&self) -> usize {
        self.period * self.repeats
    }
}

/// For every period `p`, the block of `p` frames played most times in a row in `order` (only those
/// played at least twice), found by runs of `order[i] == order[i + p]`: a run of `r` such positions
/// is a block of `p` frames played `1 + r / p` times. O(len²).
fn cycles_by_period(order: &[usize]) -> Vec<Cycle> {
    let len = order.len();
    let mut out = Vec::new();
    for p in 1..=len / 2 {
        let mut best = Cycle::default();
        let mut run = 0usize;
        for i in 0..len - p {
            if order[i] == order[i + p] {
                run += 1;
                let repeats = 1 + run / p;
                if repeats > best.repeats {
                    best = Cycle { period: p, repeats, at: i + 1 - run };
                }
            } else {
                run = 0;
            }
        }
        if best.repeats >= 2 {
            out.push(best);
        }
    }
    out
}

/// The repeated cycle of `order` that covers the most frames (`period × repeats`; among equals the
/// shorter period, which is the one a viewer sees), or `None` when no block of frames is played twice
/// in a row (issue 41's "longest repeated cycle").
pub fn longest_repeated_cycle(order: &[usize]) -> Option<Cycle> {
    cycles_by_period(order).into_iter().max_by(|a, b| a.frames().cmp(&b.frames()).then(b.period.cmp(&a.period)))
}

/// The most plays in a row of any block shorter than `min_period` frames (0 when none repeats): a
/// loop shorter than a second played more than twice reads as a stutter (issue 41's limit: at most 2).
pub fn short_cycle_repeats(order: &[usize], min_period: usize) -> usize {
    cycles_by_period(order).iter().filter(|c| c.period < min_period).map(|c| c.repeats).max().unwrap_or(0)
}

/// Steps of `order` between frames of different shots (`shot[f]`: the shot of source frame `f`);
/// for the source order itself, its shot changes. Frames without a shot count as shot 0.
pub fn shot_changes(order: &[usize], shot: &[usize]) -> usize {
    let of = |f: usize| shot.get(f).copied().unwrap_or(0);
    order.windows(2).filter(|w| of(w[0]) != of(w[1])).count()
}

/// `count` per 100 frames of an order of `len` frames (0 for an empty order).
pub fn per_100_frames(count: usize, len: usize) -> f64 {
    if len == 0 {
        0.0
    } else {
        100.0 * count as f64 / len as f64
    }
}
