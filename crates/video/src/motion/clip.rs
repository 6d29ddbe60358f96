//! Motion of a whole clip: the backward flows FC used by PMSM (§5.2.2) and the per-frame tendency
//! and LMS flags of §5.2.1 (Eq. 10–11).

use super::farneback::{farneback, flow_between, FlowParams, Prepared};
use super::tendency::{lms_frames, motion_tendency, DELTA, LMS_MIN_LEN, SIGMA};
use super::Flow;
use image::GrayImage;
use rayon::prelude::*;
use std::time::Instant;

/// Motion features of every frame of a clip.
#[derive(Clone, Debug)]
pub struct ClipMotion {
    /// `backward[c]`: flow from frame c to frame c − 1 (the paper's FC: "the optical flow of
    /// frame x_c to its backward adjacent frame"); for c = 0, the negated flow 0 → 1.
    pub backward: Vec<Flow>,
    /// Eq. 10 per frame, from its forward motion (flow c → c + 1; the last frame: its backward
    /// flow negated), with σ = [`SIGMA`].
    pub tendency: Vec<Option<f32>>,
    /// Eq. 11 per frame with δ = [`DELTA`] and runs of ≥ [`LMS_MIN_LEN`] frames.
    pub lms: Vec<bool>,
    /// Wall time of the analysis, seconds.
    pub seconds: f64,
}

/// Flows, tendencies and LMS flags of `gray` (frames of one size; a frame of another size is
/// resampled by [`farneback`]). Each frame is expanded once (pyramid and polynomial expansion)
/// and reused by its up to four flows; all 2(n − 1) flows run in parallel (rayon). An empty clip gives
/// empty vectors; a single frame gets a zero flow and no tendency.
pub fn analyse_clip(gray: &[GrayImage], p: &FlowParams) -> ClipMotion {
    let start = Instant::now();
    let (forward, backward) = clip_flows(gray, p);
    let tendency: Vec<Option<f32>> = forward.iter().map(|f| motion_tendency(f, SIGMA)).collect();
    let lms = lms_frames(&tendency, DELTA, LMS_MIN_LEN);
    ClipMotion { backward, tendency, lms, seconds: start.elapsed().as_secs_f64() }
}

/// Per frame: (forward motion, backward flow FC), both n long.
fn clip_flows(gray: &[GrayImage], p: &FlowParams) -> (Vec<Flow>, Vec<Flow>) {
    let n = gray.len();
    if n < 2 {
        let still: Vec<Flow> = gray.iter().map(|g| Flow::zeros(g.width() as usize, g.height() as usize)).collect();
        return (still.clone(), still);
    }
    let frames: Vec<Prepared> = gray.par_iter().map(|g| Prepared::from_image(g, p)).collect();
    let pair = |c: usize, d: usize| {
        let (a, b) = (&frames[c], &frames[d]);
        // A pair of different sizes: the public path resamples frame d to frame c's grid.
        if gray[c].dimensions() == gray[d].dimensions() {
            flow_between(a, b, p)
        } else {
            farneback(&gray[c], &gray[d], p)
        }
    };
    // Jobs 0..n−1: forward c → c+1; jobs n−1..2(n−1): backward c → c−1 for c = 1..n.
    let flows: Vec<Flow> = (0..2 * (n - 1))
        .into_par_iter()
        .map(|j| if j < n - 1 { pair(j, j + 1) } else { pair(j + 2 - n, j + 1 - n) })
        .collect();
    let (fwd, bwd) = flows.split_at(n - 1);
    let mut forward = fwd.to_vec();
    forward.push(bwd[n - 2].negated());
    let mut backward = vec![fwd[0].negated()];
    backward.extend_from_slice(bwd);
    (forward, backward)
}
