//! Scene-cut detection (beyond the paper): SDPF must not jump between shots, whose frames can be
//! close in latent distance (similar colours) yet never follow each other.
//!
//! Each pair of adjacent frames gets a score in [0, 1]: the mean of (a) the total-variation
//! distance of their coarse colour histograms and (b) the mean absolute difference of their
//! thumbnails. A cut is a score that is both large in itself (`min_score`) and a jump against its
//! neighbours (`ratio` × the median score of the `window` pairs on either side), so that a clip with
//! fast motion everywhere does not read as cuts everywhere.

use image::RgbImage;
use rayon::prelude::*;

use crate::metric::input::frame_planes;

/// Settings of [`detect_cuts_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct CutParams {
    /// Thumbnail side in pixels (frames are squashed to `side × side`).
    pub side: u32,
    /// Histogram bins per channel (`bins³` colour cells).
    pub bins: u32,
    /// Smallest score that can be a cut.
    pub min_score: f32,
    /// A cut scores at least `ratio` × the median of its neighbours' scores.
    pub ratio: f32,
    /// Neighbouring pairs looked at on each side.
    pub window: usize,
}

impl Default for CutParams {
    fn default() -> Self {
        CutParams { side: 32, bins: 4, min_score: 0.25, ratio: 3.0, window: 4 }
    }
}

/// `cuts[i]`: a cut lies between frames `i − 1` and `i` (`cuts[0]` is false), with the defaults.
pub fn detect_cuts(frames: &[RgbImage]) -> Vec<bool> {
    detect_cuts_with(frames, &CutParams::default())
}

/// Shot index of every frame (0, 0, …, 1, 1, …): a new shot starts after each detected cut. This
/// is what [`MotionInfo::shot`](super::MotionInfo::shot) holds.
pub fn detect_shots(frames: &[RgbImage]) -> Vec<usize> {
    shots_from_cuts(&detect_cuts(frames))
}

/// Shot indices from cut flags (`cuts[i]`: a cut between frames `i − 1` and `i`; `cuts[0]` ignored).
pub fn shots_from_cuts(cuts: &[bool]) -> Vec<usize> {
    let mut shot = 0;
    cuts.iter()
        .enumerate()
        .map(|(i, &cut)| {
            if i > 0 && cut {
                shot += 1;
            }
            shot
        })
        .collect()
}

/// [`detect_cuts`] with explicit settings.
pub fn detect_cuts_with(frames: &[RgbImage], p: &CutParams) -> Vec<bool> {
    let scores = cut_scores(frames, p);
    (0..scores.len()).map(|i| i > 0 && is_jump(&scores, i, p)).collect()
}

/// The score of every adjacent pair: `scores[i]` compares frames `i − 1` and `i`; `scores[0] = 0`.
/// Frames of different sizes are compared through their thumbnails; an empty (0-pixel) frame
/// scores 0 against anything.
pub fn cut_scores(frames: &[RgbImage], p: &CutParams) -> Vec<f32> {
    let side = p.side.max(1);
    let thumbs: Vec<Option<RgbImage>> =
        frames.par_iter().map(|f| (f.width() > 0 && f.height() > 0).then(|| thumbnail(f, side))).collect();
    let hists: Vec<Option<Vec<f32>>> = thumbs.iter().map(|t| t.as_ref().map(|t| histogram(t, p.bins))).collect();
    (0..frames.len())
        .map(|i| {
            if i == 0 {
                return 0.0;
            }
            match (&thumbs[i - 1], &thumbs[i], &hists[i - 1], &hists[i]) {
                (Some(a), Some(b), Some(ha), Some(hb)) => 0.5 * (total_variation(ha, hb) + mean_abs_diff(a, b)),
                _ => 0.0,
            }
        })
        .collect()
}

/// Whether `scores[i]` is a cut: large, and `ratio` times above its neighbours' median.
fn is_jump(scores: &[f32], i: usize, p: &CutParams) -> bool {
    let s = scores[i];
    if s.is_nan() || s < p.min_score {
        return false;
    }
    let lo = i.saturating_sub(p.window).max(1);
    let hi = (i + p.window).min(scores.len() - 1);
    let mut others: Vec<f32> = (lo..=hi).filter(|&j| j != i).map(|j| scores[j]).collect();
    if others.is_empty() {
        return true;
    }
    others.sort_by(f32::total_cmp);
    s >= p.ratio * others[others.len() / 2]
}

/// `side × side` area-average thumbnail (cheap at any source size, unlike a filtered resize).
fn thumbnail(f: &RgbImage, side: u32) -> RgbImage {
    let s = side as usize;
    let planes = frame_planes(f, s);
    RgbImage::from_fn(side, side, |x, y| {
        let at = |c: usize| (planes[(c * s + y as usize) * s + x as usize] * 255.0).round().clamp(0.0, 255.0) as u8;
        image::Rgb([at(0), at(1), at(2)])
    })
}

/// Normalised joint colour histogram with `bins` cells per channel.
fn histogram(img: &RgbImage, bins: u32) -> Vec<f32> {
    let b = bins.clamp(1, 16) as usize;
    let mut h = vec![0.0f32; b * b * b];
    let cell = |v: u8| (v as usize * b) / 256;
    for px in img.pixels() {
        h[(cell(px[0]) * b + cell(px[1])) * b + cell(px[2])] += 1.0;
    }
    let total = (img.width() * img.height()).max(1) as f32;
    h.iter_mut().for_each(|x| *x /= total);
    h
}

/// Total-variation distance of two distributions, in [0, 1].
fn total_variation(a: &[f32], b: &[f32]) -> f32 {
    0.5 * a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f32>()
}

/// Mean absolute channel difference of two same-size images, in [0, 1].
fn mean_abs_diff(a: &RgbImage, b: &RgbImage) -> f32 {
    let sum: u64 = a.as_raw().iter().zip(b.as_raw()).map(|(&x, &y)| x.abs_diff(y) as u64).sum();
    sum as f32 / (a.as_raw().len().max(1) as f32 * 255.0)
}
