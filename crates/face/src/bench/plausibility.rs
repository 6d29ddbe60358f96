//! Does a fill look like a face? Two measures that reward plausibility rather than the mean (issue 25):
//!
//! * **Two-sample test.** A logistic regression, trained fresh by the bench and independent of our critic,
//!   tries to tell real windows from filled ones on per-window statistics ([`window_features`]: per channel
//!   group mean, spread, velocity, acceleration, energy in three frequency bands, and blinks per second). Its
//!   k-fold cross-validated AUC is reported ([`two_sample_auc`]): 0.5 means the two are indistinguishable, 1.0
//!   that every filled window is told apart.
//! * **Gap statistics** ([`GapStats`]): blinks per second, the fraction of time with either eye more than half
//!   closed and the mean absolute velocity of the mouth and jaw channels, inside a gap and in the rest of the
//!   same capture, so the ratio inside/outside of a fill can be set beside the real data's ratio in the same
//!   spans.

use crate::data::{arkit_index, MODEL_FPS};
use crate::edit::Frame;
use inbetween_core::seed::rng;
use rand::seq::SliceRandom;

/// A blink starts when the mean of the two eyeBlink channels rises above this …
pub const BLINK_CLOSED: f32 = 0.5;
/// … and ends when it falls below this (hysteresis, so noise around 0.5 is one blink, not many).
pub const BLINK_OPEN: f32 = 0.35;

/// Channel groups whose statistics are features of the two-sample test.
const GROUPS: [(&str, &[&str]); 7] = [
    ("blink", &["EyeBlinkLeft", "EyeBlinkRight"]),
    (
        "gaze",
        &[
            "EyeLookDownLeft",
            "EyeLookInLeft",
            "EyeLookOutLeft",
            "EyeLookUpLeft",
            "EyeLookDownRight",
            "EyeLookInRight",
            "EyeLookOutRight",
            "EyeLookUpRight",
        ],
    ),
    ("lids", &["EyeSquintLeft", "EyeWideLeft", "EyeSquintRight", "EyeWideRight"]),
    ("jaw", &["JawForward", "JawRight", "JawLeft", "JawOpen"]),
    (
        "mouth",
        &[
            "MouthClose",
            "MouthFunnel",
            "MouthPucker",
            "MouthRight",
            "MouthLeft",
            "MouthSmileLeft",
            "MouthSmileRight",
            "MouthFrownLeft",
            "MouthFrownRight",
            "MouthStretchLeft",
            "MouthStretchRight",
            "MouthRollLower",
            "MouthRollUpper",
            "MouthShrugLower",
            "MouthShrugUpper",
            "MouthPressLeft",
            "MouthPressRight",
            "MouthLowerDownLeft",
            "MouthLowerDownRight",
            "MouthUpperUpLeft",
            "MouthUpperUpRight",
        ],
    ),
    ("brows", &["BrowDownLeft", "BrowDownRight", "BrowInnerUp", "BrowOuterUpLeft", "BrowOuterUpRight"]),
    ("cheeks", &["CheekPuff", "CheekSquintLeft", "CheekSquintRight", "NoseSneerLeft", "NoseSneerRight"]),
];

/// Frequency bands (Hz) whose share of each group's motion energy is a feature; the model rate is 25 fps,
/// so 12.5 Hz is the top.
const BANDS_HZ: [(f64, f64); 3] = [(0.0, 1.5), (1.5, 4.0), (4.0, 12.5)];

fn index(name: &str) -> usize {
    arkit_index(name).expect("group names are ARKit names")
}

/// Mean of the two eyeBlink channels of each frame.
fn blink_signal(frames: &[Frame]) -> Vec<f32> {
    let (l, r) = (index("EyeBlinkLeft"), index("EyeBlinkRight"));
    frames.iter().map(|f| 0.5 * (f[l] + f[r])).collect()
}

/// Number of blinks that start in `frames` (mean eyeBlink rises above [`BLINK_CLOSED`], with
/// hysteresis down to [`BLINK_OPEN`]). An eye already closed at the first frame does not count.
pub fn count_blinks(frames: &[Frame]) -> usize {
    let s = blink_signal(frames);
    let mut closed = s.first().is_some_and(|&v| v > BLINK_CLOSED);
    let mut n = 0;
    for &v in &s {
        if !closed && v > BLINK_CLOSED {
            closed = true;
            n += 1;
        } else if closed && v < BLINK_OPEN {
            closed = false;
        }
    }
    n
}

/// Per-window features of the two-sample test, in a fixed order: for every channel group the mean, the
/// spread (standard deviation over frames, averaged over the group's channels), the mean absolute velocity
/// and acceleration (per second), the share of the group's velocity energy in each of [`BANDS_HZ`]; then
/// blinks per second. Windows of at least three frames.
pub fn window_features(frames: &[Frame]) -> Vec<f64> {
    let n = frames.len();
    assert!(n >= 3, "a window needs at least three frames");
    let fps = MODEL_FPS;
    let mut out = Vec::with_capacity(GROUPS.len() * (4 + BANDS_HZ.len()) + 1);
    for (_, names) in GROUPS {
        let (mut mean, mut spread, mut vel, mut acc) = (0.0, 0.0, 0.0, 0.0);
        let mut band = [0.0; BANDS_HZ.len()];
        for name in names {
            let c = index(name);
            let x: Vec<f64> = frames.iter().map(|f| f64::from(f[c])).collect();
            let m = x.iter().sum::<f64>() / n as f64;
            mean += m;
            spread += (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n as f64).sqrt();
            let v: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]) * fps).collect();
            vel += v.iter().map(|d| d.abs()).sum::<f64>() / v.len() as f64;
            acc += v.windows(2).map(|w| ((w[1] - w[0]) * fps).abs()).sum::<f64>() / (v.len() - 1) as f64;
            // Energy of the velocity by frequency (a plain DFT: windows are at most a few hundred frames).
            let len = v.len();
            for k in 1..=len / 2 {
                let hz = k as f64 * fps / len as f64;
                let (mut re, mut im) = (0.0, 0.0);
                for (t, d) in v.iter().enumerate() {
                    let a = std::f64::consts::TAU * (k * t) as f64 / len as f64;
                    re += d * a.cos();
                    im -= d * a.sin();
                }
                if let Some(b) = BANDS_HZ.iter().position(|&(lo, hi)| hz > lo && hz <= hi) {
                    band[b] += re * re + im * im;
                }
            }
        }
        let g = names.len() as f64;
        out.extend([mean / g, spread / g, vel / g, acc / g]);
        let total: f64 = band.iter().sum();
        out.extend(band.iter().map(|e| if total > 0.0 { e / total } else { 0.0 }));
    }
    out.push(count_blinks(frames) as f64 * fps / n as f64);
    out
}

/// Area under the ROC curve of `scores` for positives (label true) against negatives, ties counted half
/// (the Mann–Whitney U statistic over the product of the class sizes).
pub fn auc(scores: &[(f64, bool)]) -> f64 {
    let pos: Vec<f64> = scores.iter().filter(|s| s.1).map(|s| s.0).collect();
    let neg: Vec<f64> = scores.iter().filter(|s| !s.1).map(|s| s.0).collect();
    if pos.is_empty() || neg.is_empty() {
        return f64::NAN;
    }
    let mut u = 0.0;
    for p in &pos {
        for q in &neg {
            u += if p > q {
                1.0
            } else if p == q {
                0.5
            } else {
                0.0
            };
        }
    }
    u / (pos.len() * neg.len()) as f64
}

/// L2-regularised logistic regression on standardised features, fitted by full-batch gradient descent.
struct Logistic {
    mean: Vec<f64>,
    scale: Vec<f64>,
    w: Vec<f64>,
    b: f64,
}

impl Logistic {
    const STEPS: usize = 400;
    const RATE: f64 = 0.5;
    const L2: f64 = 0.01;

    fn fit(x: &[&[f64]], y: &[bool]) -> Logistic {
        let d = x[0].len();
        let n = x.len() as f64;
        let mean: Vec<f64> = (0..d).map(|j| x.iter().map(|r| r[j]).sum::<f64>() / n).collect();
        let scale: Vec<f64> = (0..d)
            .map(|j| {
                let s = (x.iter().map(|r| (r[j] - mean[j]).powi(2)).sum::<f64>() / n).sqrt();
                if s > 1e-12 {
                    s
                } else {
                    1.0
                }
            })
            .collect();
        let z: Vec<Vec<f64>> = x.iter().map(|r| (0..d).map(|j| (r[j] - mean[j]) / scale[j]).collect()).collect();
        let mut w = vec![0.0; d];
        let mut b = 0.0;
        for _ in 0..Self::STEPS {
            let mut gw = vec![0.0; d];
            let mut gb = 0.0;
            for (r, &t) in z.iter().zip(y) {
                let p = sigmoid(b + dot(&w, r));
                let e = p - if t { 1.0 } else { 0.0 };
                gb += e;
                for j in 0..d {
                    gw[j] += e * r[j];
                }
            }
            for j in 0..d {
                w[j] -= Self::RATE * (gw[j] / n + Self::L2 * w[j]);
            }
            b -= Self::RATE * gb / n;
        }
        Logistic { mean, scale, w, b }
    }

    fn score(&self, r: &[f64]) -> f64 {
        let z: Vec<f64> = r.iter().enumerate().map(|(j, v)| (v - self.mean[j]) / self.scale[j]).collect();
        self.b + dot(&self.w, &z)
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

/// Held-out AUC of a classifier telling `real` windows' features from `filled` ones: the windows are shuffled
/// (seeded) into `folds` folds; each fold is scored by a logistic regression fitted on the others, and the AUC
/// is taken over all held-out scores together. `NaN` when either side has fewer than `folds` windows.
pub fn two_sample_auc(real: &[Vec<f64>], filled: &[Vec<f64>], folds: usize, seed: u64) -> f64 {
    if real.len() < folds || filled.len() < folds || folds < 2 {
        return f64::NAN;
    }
    let mut rows: Vec<(&[f64], bool)> =
        real.iter().map(|r| (r.as_slice(), false)).chain(filled.iter().map(|r| (r.as_slice(), true))).collect();
    rows.shuffle(&mut rng(seed));
    let mut scores = Vec::with_capacity(rows.len());
    for k in 0..folds {
        let (x, y): (Vec<&[f64]>, Vec<bool>) =
            rows.iter().enumerate().filter(|(i, _)| i % folds != k).map(|(_, r)| *r).unzip();
        if !(y.iter().any(|&t| t) && y.iter().any(|&t| !t)) {
            return f64::NAN;
        }
        let model = Logistic::fit(&x, &y);
        scores.extend(rows.iter().enumerate().filter(|(i, _)| i % folds == k).map(|(_, r)| (model.score(r.0), r.1)));
    }
    auc(&scores)
}

/// Sums of the gap statistics over frames (so spans pool by adding).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GapStats {
    /// Frames counted.
    pub frames: usize,
    /// Blinks that start in those frames.
    pub blinks: usize,
    /// Frames with either eye more than half closed.
    pub closed_frames: usize,
    /// Sum over frame steps of the mean absolute velocity (per second) of the mouth and jaw channels.
    pub mouth_speed_sum: f64,
    /// Frame steps counted in `mouth_speed_sum`.
    pub steps: usize,
}

impl GapStats {
    /// The statistics of `frames` outside `seg` (the frames before it and after it, each run on its own).
    pub fn outside(frames: &[Frame], seg: crate::edit::Segment) -> GapStats {
        let mut o = GapStats::of(&frames[..seg.start]);
        o.add(&GapStats::of(&frames[seg.end..]));
        o
    }

    /// The statistics of consecutive frames `frames`.
    pub fn of(frames: &[Frame]) -> GapStats {
        let (l, r) = (index("EyeBlinkLeft"), index("EyeBlinkRight"));
        let mouth: Vec<usize> = GROUPS
            .iter()
            .filter(|(g, _)| *g == "jaw" || *g == "mouth")
            .flat_map(|(_, n)| n.iter().map(|c| index(c)))
            .collect();
        let mouth_speed_sum = frames
            .windows(2)
            .map(|w| {
                mouth.iter().map(|&c| f64::from((w[1][c] - w[0][c]).abs())).sum::<f64>() / mouth.len() as f64
                    * MODEL_FPS
            })
            .sum();
        GapStats {
            frames: frames.len(),
            blinks: count_blinks(frames),
            closed_frames: frames.iter().filter(|f| f[l] > 0.5 || f[r] > 0.5).count(),
            mouth_speed_sum,
            steps: frames.len().saturating_sub(1),
        }
    }

    /// Adds another span's sums.
    pub fn add(&mut self, o: &GapStats) {
        self.frames += o.frames;
        self.blinks += o.blinks;
        self.closed_frames += o.closed_frames;
        self.mouth_speed_sum += o.mouth_speed_sum;
        self.steps += o.steps;
    }

    /// Blinks per second.
    pub fn blinks_per_s(&self) -> f64 {
        self.blinks as f64 * MODEL_FPS / self.frames.max(1) as f64
    }

    /// Fraction of frames with either eye more than half closed.
    pub fn closed_fraction(&self) -> f64 {
        self.closed_frames as f64 / self.frames.max(1) as f64
    }

    /// Mean absolute velocity of the mouth and jaw channels, weight units per second.
    pub fn mouth_speed(&self) -> f64 {
        self.mouth_speed_sum / self.steps.max(1) as f64
    }

    /// The three statistics in the order of [`STAT_NAMES`].
    pub fn values(&self) -> [f64; 3] {
        [self.blinks_per_s(), self.closed_fraction(), self.mouth_speed()]
    }
}

/// Names of [`GapStats::values`].
pub const STAT_NAMES: [&str; 3] = ["blinks_per_s", "eye_closed_fraction", "mouth_jaw_speed_per_s"];

/// Inside/outside ratio of one statistic (`NaN` when the outside value is zero).
pub fn ratio(inside: f64, outside: f64) -> f64 {
    if outside > 0.0 {
        inside / outside
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::NUM_ARKIT;
    use rand::Rng;

    fn blinky(n: usize, period: usize, seed: u64) -> Vec<Frame> {
        let mut r = rng(seed);
        let (l, rr, jaw) = (index("EyeBlinkLeft"), index("EyeBlinkRight"), index("JawOpen"));
        (0..n)
            .map(|t| {
                let mut f = [0.0f32; NUM_ARKIT];
                let phase = t % period;
                let b = if phase < 4 { [0.3, 0.9, 0.9, 0.3][phase] } else { 0.05 };
                f[l] = b + r.random_range(-0.02..0.02);
                f[rr] = b + r.random_range(-0.02..0.02);
                f[jaw] = 0.3 + 0.2 * ((t as f32) * 0.7).sin() + r.random_range(-0.05..0.05);
                f
            })
            .collect()
    }

    #[test]
    fn blinks_are_counted_once_each_with_hysteresis() {
        let frames = blinky(100, 25, 1);
        assert_eq!(count_blinks(&frames), 4);
        // A held half-closed eye is not a blink.
        let mut held = frames.clone();
        for f in &mut held {
            f[index("EyeBlinkLeft")] = 0.75;
            f[index("EyeBlinkRight")] = 0.75;
        }
        assert_eq!(count_blinks(&held), 0);
        let s = GapStats::of(&held);
        assert_eq!(s.closed_fraction(), 1.0);
        assert!((GapStats::of(&frames).blinks_per_s() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn auc_orders_and_ties() {
        assert_eq!(auc(&[(1.0, true), (0.0, false)]), 1.0);
        assert_eq!(auc(&[(0.0, true), (1.0, false)]), 0.0);
        assert_eq!(auc(&[(0.5, true), (0.5, false)]), 0.5);
    }

    #[test]
    fn the_test_tells_straight_lines_from_motion_and_not_motion_from_motion() {
        let real: Vec<Vec<f64>> = (0..30).map(|i| window_features(&blinky(50, 20 + i % 7, i as u64))).collect();
        let same: Vec<Vec<f64>> = (0..30).map(|i| window_features(&blinky(50, 20 + i % 7, 100 + i as u64))).collect();
        let linear: Vec<Vec<f64>> = (0..30)
            .map(|i| {
                let w = blinky(50, 20 + i % 7, 200 + i as u64);
                let (a, b) = (w[0], w[49]);
                let lin: Vec<Frame> = (0..50)
                    .map(|t| {
                        let s = t as f32 / 49.0;
                        std::array::from_fn(|c| a[c] + s * (b[c] - a[c]))
                    })
                    .collect();
                window_features(&lin)
            })
            .collect();
        let fake = two_sample_auc(&real, &linear, 5, 3);
        let twin = two_sample_auc(&real, &same, 5, 3);
        assert!(fake > 0.95, "straight lines must be told apart: AUC {fake}");
        assert!(twin < 0.75, "the same process must not be: AUC {twin}");
        assert_eq!(two_sample_auc(&real, &same, 5, 3), twin, "seeded");
    }
}
