//! Directional features of §5.2.1: normalised magnitude (Eq. 9), motion tendency (Eq. 10) and
//! linear-motion segments (Eq. 11).
//!
//! Angles are in image coordinates (x to the right, y downwards): 0 is motion to the right, π/2
//! motion downwards, ±π to the left.

use super::Flow;
use inbetween_core::angle::wrap_angle;

/// σ of Eq. 10: only pixels whose normalised magnitude exceeds it vote for the tendency.
pub const SIGMA: f32 = 0.5;
/// δ of Eq. 11: the largest turn (radians) allowed inside a linear-motion segment.
pub const DELTA: f32 = std::f32::consts::FRAC_PI_4;
/// Shortest LMS in frames. Eq. 11 asks for a run [j, j + k] with k > 2, i.e. k + 1 ≥ 4 frames.
pub const LMS_MIN_LEN: usize = 4;
/// A frame whose largest flow vector is shorter than this (px) is treated as static by
/// [`motion_tendency`] (beyond the paper: Eq. 9 would stretch estimator noise of a still frame to
/// [0, 1] and give it a random direction).
pub const STATIC_MAX_PX: f32 = 0.2;

/// Eq. 9: (‖F_ij‖ − min ‖F‖) / (max ‖F‖ − min ‖F‖), per pixel, in [0, 1].
///
/// The ratio is 0/0 when all magnitudes are equal; then every pixel moves as much as the largest
/// one, so all get 1, unless there is no motion at all (all 0). Non-finite vectors count as 0.
pub fn normalized_magnitude(flow: &Flow) -> Vec<f32> {
    let mags = flow.magnitudes();
    let (lo, hi) = mags.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &m| (lo.min(m), hi.max(m)));
    if hi <= 1e-12 {
        return vec![0.0; mags.len()];
    }
    let range = hi - lo;
    if range <= 1e-6 * hi {
        return vec![1.0; mags.len()];
    }
    mags.iter().map(|&m| ((m - lo) / range).clamp(0.0, 1.0)).collect()
}

/// Eq. 10 with the default static floor [`STATIC_MAX_PX`]: the angle of the mean unit flow vector
/// over the pixels whose normalised magnitude (Eq. 9) exceeds `sigma`; `None` when no pixel passes,
/// the frame is static, or the unit vectors cancel out (no dominant direction).
pub fn motion_tendency(flow: &Flow, sigma: f32) -> Option<f32> {
    motion_tendency_with_floor(flow, sigma, STATIC_MAX_PX)
}

/// Eq. 10 with an explicit static floor `min_px` (0 reproduces the paper exactly).
///
/// The paper sums the unit vectors and divides by n×m; the division does not change the angle, so
/// only the sum is kept.
pub fn motion_tendency_with_floor(flow: &Flow, sigma: f32, min_px: f32) -> Option<f32> {
    let max = flow.magnitudes().into_iter().fold(0.0f32, f32::max);
    if max < min_px || max <= 0.0 {
        return None;
    }
    let norm = normalized_magnitude(flow);
    let (mut sx, mut sy, mut count) = (0.0f64, 0.0f64, 0usize);
    for (v, &n) in flow.uv.iter().zip(&norm) {
        let m = (v[0] * v[0] + v[1] * v[1]).sqrt();
        if n > sigma && m > 0.0 && m.is_finite() {
            sx += (v[0] / m) as f64;
            sy += (v[1] / m) as f64;
            count += 1;
        }
    }
    let cancelled = (sx * sx + sy * sy).sqrt() <= 1e-6 * count as f64;
    (count > 0 && !cancelled).then(|| sy.atan2(sx) as f32)
}

/// Absolute difference of two angles, wrapped: in [0, π].
pub fn angle_between(a: f32, b: f32) -> f32 {
    wrap_angle(a as f64 - b as f64).abs() as f32
}

/// Eq. 11: frame i is an LMS-frame when it lies in a run [j, j + k] of at least `min_len`
/// consecutive frames (the paper: k > 2, so `min_len` = [`LMS_MIN_LEN`] = 4) whose tendencies all
/// stay within `delta` of the run's first tendency T_j (|T_j − T_l| ≤ δ, wrapped, for every l in
/// the run). A frame with no tendency (`None`) breaks any run.
pub fn lms_frames(tendency: &[Option<f32>], delta: f32, min_len: usize) -> Vec<bool> {
    let n = tendency.len();
    let mut lms = vec![false; n];
    for j in 0..n {
        let Some(tj) = tendency[j] else { continue };
        let end = run_end(tendency, j, tj, delta);
        if end + 1 - j >= min_len.max(1) {
            lms[j..=end].iter_mut().for_each(|f| *f = true);
        }
    }
    lms
}

/// Last index of the run that starts at `j` with anchor tendency `tj`.
fn run_end(tendency: &[Option<f32>], j: usize, tj: f32, delta: f32) -> usize {
    let mut end = j;
    while let Some(Some(tl)) = tendency.get(end + 1) {
        if angle_between(*tl, tj) > delta {
            break;
        }
        end += 1;
    }
    end
}
