//! The interpolation baselines (linear and cubic Hermite, as the paper compares against in §4.2) and
//! the post-processing of a generated edit: keyframes hit exactly, C1 joins at the mask borders,
//! weights in [0, 1] (the paper's §6 names exact hits as its limitation).
//!
//! Both work per channel on each erased run of that channel, with a curve through knots
//! ([`knot_curve`]: a core [`ScalarTrack`], the codebase's one Hermite): the baseline interpolates
//! the known values around the gap (and the keys inside it); the correction interpolates the
//! *residual* `known − generated` at the same places and adds it to the generated curve, so the
//! network's motion survives and only drifts at keys and borders are bent away.

use inbetween_core::curve::{Animatable, Curve, Interpolation, Key, ScalarTrack};

use crate::data::NUM_ARKIT;

use super::mask::{Mask, Segment};
use super::Frame;

/// Interpolation of a baseline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interp {
    /// Straight lines between the known values.
    Linear,
    /// Cubic Hermite matching the values and slopes at the gap's borders.
    Cubic,
}

/// A knot at frame (or time) `t` with value `v` and, when the curve must match a known derivative
/// there, `slope` (per unit of `t`). Knots without a slope get a Catmull–Rom slope from their
/// neighbours (central difference, one-sided at the ends).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knot {
    /// Frame or time (may be fractional).
    pub t: f64,
    /// Value.
    pub v: f64,
    /// Derivative per unit of `t`, if fixed.
    pub slope: Option<f64>,
}

/// The curve through `knots` (sorted by `t`, distinct): cubic Hermite (C1, matching the given
/// slopes) or linear, as a core [`ScalarTrack`], held flat outside the knots (a blendshape should not
/// drift away from its last known value; sample it with [`Curve::sample_clamped`]). `None` without
/// knots or with times that do not increase.
pub fn knot_curve(knots: &[Knot], interp: Interp) -> Option<ScalarTrack> {
    let last = knots.len().checked_sub(1)?;
    let keys = (0..knots.len())
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(last));
            let slope = knots[i].slope.unwrap_or_else(|| match a == b {
                true => 0.0,
                false => f64::finite_tangent((knots[a].t, knots[a].v), (knots[b].t, knots[b].v)),
            });
            Key { time: knots[i].t, value: knots[i].v, tangent: slope }
        })
        .collect();
    let interpolation = match interp {
        Interp::Cubic => Interpolation::Hermite,
        Interp::Linear => Interpolation::Linear,
    };
    ScalarTrack::new(keys, interpolation).ok()
}

/// Erased runs of channel `c`.
fn channel_runs(mask: &Mask, c: usize) -> Vec<Segment> {
    let mut runs = Vec::new();
    let mut start = None;
    for f in 0..=mask.frames() {
        let on = f < mask.frames() && mask.erased(f, c);
        match (on, start) {
            (true, None) => start = Some(f),
            (false, Some(s)) => {
                runs.push(Segment { start: s, end: f });
                start = None;
            }
            _ => {}
        }
    }
    runs
}

/// Knots of `residual(f)` for a run: the frame before and after it (with slopes from one-sided
/// differences when `slopes`), and the keys inside it.
fn run_knots(
    run: Segment,
    frames: usize,
    residual: impl Fn(usize) -> f64,
    keys: &[(usize, f64)],
    slopes: bool,
) -> Vec<Knot> {
    let mut knots = Vec::new();
    if run.start > 0 {
        let f = run.start - 1;
        let slope = (slopes && f > 0).then(|| residual(f) - residual(f - 1));
        knots.push(Knot { t: f as f64, v: residual(f), slope });
    }
    for (f, v) in keys.iter().filter(|(f, _)| run.contains(*f)) {
        knots.push(Knot { t: *f as f64, v: *v, slope: None });
    }
    if run.end < frames {
        let f = run.end;
        let slope = (slopes && f + 1 < frames).then(|| residual(f + 1) - residual(f));
        knots.push(Knot { t: f as f64, v: residual(f), slope });
    }
    knots
}

/// Keys of channel `c`, sorted by frame, the last one winning on duplicates.
fn channel_keys(keys: &[(usize, Frame)], c: usize) -> Vec<(usize, f32)> {
    let mut k: Vec<(usize, f32)> = keys.iter().map(|(f, v)| (*f, v[c])).collect();
    k.sort_by_key(|(f, _)| *f);
    k.dedup_by(|later, earlier| {
        let same = later.0 == earlier.0;
        if same {
            earlier.1 = later.1;
        }
        same
    });
    k
}

/// Fill every erased entry by interpolating the kept values around it and the keys inside it.
/// Entries with nothing to interpolate (the whole clip erased, no keys) become 0, the neutral face.
pub fn interpolate(anim: &[Frame], mask: &Mask, keys: &[(usize, Frame)], interp: Interp) -> Vec<Frame> {
    let zeros = vec![[0.0f32; NUM_ARKIT]; anim.len()];
    apply_residual(&zeros, anim, mask, keys, interp)
}

/// Post-process a generated animation: outside the mask the input exactly; inside, the generated
/// curves bent by a C1 residual curve so that every key is hit exactly and values and slopes join the
/// input at each border; then clamped to [0, 1].
pub fn correct(generated: &[Frame], anim: &[Frame], mask: &Mask, keys: &[(usize, Frame)]) -> Vec<Frame> {
    apply_residual(generated, anim, mask, keys, Interp::Cubic)
}

fn apply_residual(base: &[Frame], anim: &[Frame], mask: &Mask, keys: &[(usize, Frame)], interp: Interp) -> Vec<Frame> {
    let frames = anim.len();
    assert_eq!(base.len(), frames, "generated and input lengths differ");
    assert_eq!(mask.frames(), frames, "mask and input lengths differ");
    let mut out = anim.to_vec();
    for c in 0..NUM_ARKIT {
        let ck = channel_keys(keys, c);
        for run in channel_runs(mask, c) {
            let residual = |f: usize| f64::from(anim[f][c]) - f64::from(base[f][c]);
            let key_residuals: Vec<(usize, f64)> =
                ck.iter().map(|(f, v)| (*f, f64::from(*v) - f64::from(base[*f][c]))).collect();
            let knots = run_knots(run, frames, residual, &key_residuals, interp == Interp::Cubic);
            let curve = knot_curve(&knots, interp);
            for (f, row) in out.iter_mut().enumerate().take(run.end).skip(run.start) {
                let r = curve.as_ref().map_or(0.0, |k| k.sample_clamped(f as f64));
                row[c] = (f64::from(base[f][c]) + r).clamp(0.0, 1.0) as f32;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubic(knots: &[Knot], t: f64) -> f64 {
        knot_curve(knots, Interp::Cubic).map_or(0.0, |c| c.sample_clamped(t))
    }

    fn linear(knots: &[Knot], t: f64) -> f64 {
        knot_curve(knots, Interp::Linear).map_or(0.0, |c| c.sample_clamped(t))
    }

    fn k(t: f64, v: f64, slope: Option<f64>) -> Knot {
        Knot { t, v, slope }
    }

    #[test]
    fn passes_through_knots_and_matches_given_slopes() {
        let knots = [k(0.0, 1.0, Some(0.5)), k(4.0, 2.0, None), k(10.0, 0.0, Some(-1.0))];
        for kn in &knots {
            assert!((cubic(&knots, kn.t) - kn.v).abs() < 1e-12);
        }
        let eps = 1e-6;
        let d0 = (cubic(&knots, eps) - cubic(&knots, 0.0)) / eps;
        assert!((d0 - 0.5).abs() < 1e-4, "{d0}");
        let d1 = (cubic(&knots, 10.0) - cubic(&knots, 10.0 - eps)) / eps;
        assert!((d1 + 1.0).abs() < 1e-4, "{d1}");
        // C1 at the interior knot: left and right derivatives agree.
        let l = (cubic(&knots, 4.0) - cubic(&knots, 4.0 - eps)) / eps;
        let r = (cubic(&knots, 4.0 + eps) - cubic(&knots, 4.0)) / eps;
        assert!((l - r).abs() < 1e-4, "{l} {r}");
    }

    #[test]
    fn reproduces_a_cubic_given_its_end_slopes() {
        let f = |t: f64| 0.01 * t * t * t - 0.1 * t * t + 0.3 * t + 1.0;
        let df = |t: f64| 0.03 * t * t - 0.2 * t + 0.3;
        let knots = [k(0.0, f(0.0), Some(df(0.0))), k(7.0, f(7.0), Some(df(7.0)))];
        for i in 0..=70 {
            let t = i as f64 / 10.0;
            assert!((cubic(&knots, t) - f(t)).abs() < 1e-9);
        }
        assert_eq!(linear(&knots, 3.5), (f(0.0) + f(7.0)) / 2.0);
        assert_eq!(cubic(&knots, -1.0), f(0.0));
        assert_eq!(cubic(&[], 1.0), 0.0);
    }

    fn wave(n: usize, phase: f32) -> Vec<Frame> {
        (0..n).map(|f| [0.5 + 0.3 * ((f as f32) * 0.15 + phase).sin(); NUM_ARKIT]).collect()
    }

    fn gap(n: usize, a: usize, b: usize) -> Mask {
        Mask::span(n, a, b)
    }

    #[test]
    fn cubic_baseline_recovers_a_smooth_curve_better_than_linear() {
        let truth = wave(100, 0.0);
        let mask = gap(100, 40, 52);
        let err = |fill: &[Frame]| (40..52).map(|f| (fill[f][0] - truth[f][0]).abs()).fold(0.0f32, f32::max);
        let lin = interpolate(&truth, &mask, &[], Interp::Linear);
        let cub = interpolate(&truth, &mask, &[], Interp::Cubic);
        assert!(err(&cub) < 0.5 * err(&lin), "cubic {} linear {}", err(&cub), err(&lin));
        assert_eq!(lin[39], truth[39]);
        assert_eq!(cub[52], truth[52]);
    }

    #[test]
    fn correction_hits_keys_exactly_and_keeps_the_outside() {
        let truth = wave(80, 0.0);
        let generated = wave(80, 0.7);
        let mask = gap(80, 20, 60);
        let mut key = [0.0; NUM_ARKIT];
        key.iter_mut().enumerate().for_each(|(c, v)| *v = c as f32 / 60.0);
        let keys = vec![(30, key), (45, truth[45])];
        let out = correct(&generated, &truth, &mask, &keys);
        assert_eq!(out[30], key);
        assert_eq!(out[45], truth[45]);
        assert_eq!(&out[..20], &truth[..20]);
        assert_eq!(&out[60..], &truth[60..]);
    }

    /// Second difference at the borders: a C1 join has one as small as the curve's own; pasting the
    /// generated values in (plain recomposition) leaves a step.
    #[test]
    fn joins_are_c1_at_the_mask_borders() {
        let truth = wave(100, 0.0);
        let generated: Vec<Frame> = wave(100, 0.9).iter().map(|f| f.map(|v| v * 0.8 + 0.1)).collect();
        let mask = gap(100, 30, 70);
        let out = correct(&generated, &truth, &mask, &[]);
        let second = |x: &[Frame], f: usize| (x[f + 1][0] - 2.0 * x[f][0] + x[f - 1][0]).abs();
        let own = (2..98).map(|f| second(&truth, f)).fold(0.0f32, f32::max);
        let pasted = crate::model::input::recompose(&truth, &mask, &generated);
        for border in [29, 30, 69, 70] {
            assert!(second(&out, border) <= 1.5 * own, "border {border}: {} vs own {own}", second(&out, border));
        }
        assert!(second(&pasted, 30) > 3.0 * own);
    }

    #[test]
    fn only_masked_channels_change_and_values_stay_in_range() {
        let truth = wave(50, 0.0);
        let generated = vec![[1.4f32; NUM_ARKIT]; 50];
        let mut ch = [false; NUM_ARKIT];
        ch[17] = true;
        let mask = Mask::from_segments(50, &[Segment { start: 10, end: 40 }], &ch);
        let out = correct(&generated, &truth, &mask, &[]);
        for f in 0..50 {
            for c in 0..NUM_ARKIT {
                if c != 17 || !(10..40).contains(&f) {
                    assert_eq!(out[f][c], truth[f][c]);
                }
                assert!((0.0..=1.0).contains(&out[f][c]));
            }
        }
        assert!(interpolate(&truth, &Mask::all(50), &[], Interp::Cubic).iter().flatten().all(|v| *v == 0.0));
    }
}
