//! The paper's measures of a new order (§6.3) and our scene-cut detector.

use image::RgbImage;

/// RMS difference per pixel (channels in [0, 1]) of two frames of the same size.
fn rms_difference(a: &RgbImage, b: &RgbImage) -> f64 {
    let n = a.as_raw().len().min(b.as_raw().len()).max(1);
    let s: f64 = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| (f64::from(*x) - f64::from(*y)) / 255.0).map(|d| d * d).sum();
    (s / n as f64).sqrt()
}

/// M_D (Eq. 21): the mean over consecutive frames of `order` of ‖F_t − F_{t−1}‖, here the RMS per
/// pixel in [0, 1]. The source order (0, 1, 2, …) gives the clip's own value, the reference a new
/// order should stay close to. 0 for fewer than two frames.
pub fn stability_md(frames: &[RgbImage], order: &[usize]) -> f64 {
    if order.len() < 2 {
        return 0.0;
    }
    let s: f64 = order.windows(2).map(|w| rms_difference(&frames[w[0]], &frames[w[1]])).sum();
    s / (order.len() - 1) as f64
}

/// Δ_o (Eq. 22–23): the F-measure of the temporal overlap between a new order G and the source T.
/// The overlap δ counts G's transitions that are also source transitions (f → f + 1); d_G is G's
/// number of transitions and d_T the source's (n − 1 for an n-frame clip). 1 for the source itself,
/// 0 when no transition is kept.
pub fn overlap_delta_o(order: &[usize], clip_frames: usize) -> f64 {
    let d_g = order.len().saturating_sub(1);
    let d_t = clip_frames.saturating_sub(1);
    let overlap = order.windows(2).filter(|w| w[1] == w[0] + 1).count();
    if d_g == 0 || d_t == 0 || overlap == 0 {
        return 0.0;
    }
    let (p, r) = (overlap as f64 / d_g as f64, overlap as f64 / d_t as f64);
    2.0 * p * r / (p + r)
}

/// Scene cuts (beyond the paper): shot index per frame. A cut falls before frame i when its
/// colour-histogram distance to frame i − 1 is both large in absolute terms (> `min_jump`, half the
/// histogram mass changing) and much larger than the clip's typical step (> `ratio` × median).
pub fn detect_shots(frames: &[RgbImage]) -> Vec<usize> {
    detect_shots_with(frames, 0.5, 4.0)
}

/// [`detect_shots`] with its thresholds.
pub fn detect_shots_with(frames: &[RgbImage], min_jump: f64, ratio: f64) -> Vec<usize> {
    let hists: Vec<Vec<f64>> = frames.iter().map(histogram).collect();
    let steps: Vec<f64> = hists.windows(2).map(|w| l1(&w[0], &w[1]) / 2.0).collect();
    let mut sorted = steps.clone();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let mut shot = 0;
    let mut out = Vec::with_capacity(frames.len());
    for i in 0..frames.len() {
        if i > 0 && steps[i - 1] > min_jump && steps[i - 1] > ratio * median {
            shot += 1;
        }
        out.push(shot);
    }
    out
}

/// A normalised 4×4×4 RGB histogram.
fn histogram(img: &RgbImage) -> Vec<f64> {
    let mut h = vec![0.0; 64];
    for p in img.pixels() {
        let b = |v: u8| usize::from(v >> 6);
        h[b(p.0[0]) * 16 + b(p.0[1]) * 4 + b(p.0[2])] += 1.0;
    }
    let n = (img.width() * img.height()).max(1) as f64;
    h.iter_mut().for_each(|v| *v /= n);
    h
}

fn l1(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum()
}
