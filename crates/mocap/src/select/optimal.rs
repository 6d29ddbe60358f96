//! Exact selectors over segment costs (beyond the paper). Each segment's error depends only on its
//! two keyframes, so:
//! - the minimum total error with exactly `k` keys is a shortest path with `k − 1` edges through the
//!   frames, solved by `dp[c][j] = min_i dp[c−1][i] + cost(i, j)` in O(k·n·gap);
//! - the fewest keys keeping every frame under an error bound is a shortest path over the segments
//!   whose own maximum error is within the bound (ties broken by the lower total error).
//!
//! [`optimal`] runs the programme over a ready [`SegmentTable`] (every cost of every segment).
//! [`optimal_spherical`] gives the same keys on one clip without that table, in about a millisecond
//! for a 60-frame window. It tabulates only the objective (for the mean angle error, θ and φ by
//! their Hermite cubics: no position, no trigonometry), vectorised over joints, and costs in full
//! only the segments that may lie on an optimal path:
//! 1. every segment up to `g₀ = ⌈1.5·⌈(n−1)/(k−1)⌉⌉` frames long is costed in full; the best path
//!    over them gives an upper bound `U` of the optimum;
//! 2. every longer segment gets a lower bound (its middle frames), and a backward pass over these
//!    bounds gives, for each frame and number of segments left, a lower bound of the rest of a path;
//! 3. the programme then runs column by column: a longer segment `(i, j)` is costed from its middle
//!    outwards and dropped once `dp[c][i] + (its frames so far) + (rest from j)` exceeds `U` for
//!    every `c` (costs are sums of non-negative frame terms).
//!
//! Every cost it keeps is the same floating-point number as the table's (same operations in the
//! same order), the segments of the optimal path are never dropped, and dropping a segment only
//! raises the other candidates of a state, so every state on the optimal path keeps its value and
//! its predecessor (the first `i` of the minimum): the keys and the total are those of [`optimal`]
//! over [`SegmentTable::full_serial`], bit for bit (tested on procedural and noisy windows).

use super::check_k;
use crate::metrics::{ErrorMeasure, SegmentModel, SegmentTable};
use crate::representation::SphericalMotion;
use crate::{MocapError, Result};
use inbetween_core::cancel::Cancel;
use inbetween_core::interp::hermite_basis;
use inbetween_core::KeyframeSet;
use std::f64::consts::TAU;

/// The keyframe set of exactly `k` keys with the lowest total `objective` error.
pub fn optimal(table: &SegmentTable, k: usize, objective: ErrorMeasure) -> Result<KeyframeSet> {
    let n = table.num_frames;
    check_k(n, k)?;
    let cost = |i: usize, j: usize| table.get(i, j).map_or(f64::INFINITY, |s| objective.of(s));
    Ok(shortest_path(n, table.max_gap, k, cost)?.0)
}

/// The same keys as [`optimal`] over [`SegmentTable::full_serial`]`(rep)`, much faster: only the
/// objective is tabulated, and segments that cannot be on an optimal path are dropped early (module
/// docs). For [`ErrorMeasure::Angle`] no position is rebuilt; [`ErrorMeasure::Position`] rebuilds them
/// through [`SegmentModel::frame_cost`] and gains only from the dropped segments.
pub fn optimal_spherical(rep: &SphericalMotion, k: usize, objective: ErrorMeasure) -> Result<KeyframeSet> {
    Ok(optimal_spherical_with_total(rep, k, objective)?.0)
}

/// [`optimal_spherical`] and the minimum total (the sum of the chosen segments' costs).
pub fn optimal_spherical_with_total(
    rep: &SphericalMotion,
    k: usize,
    objective: ErrorMeasure,
) -> Result<(KeyframeSet, f64)> {
    optimal_spherical_cancellable(rep, k, objective, &Cancel::new())
}

/// [`optimal_spherical_with_total`] that checks `cancel` once per frame of each pass (a studio's
/// cancel button, a time limit) and returns [`crate::MocapError::Cancelled`] once it is cancelled.
pub fn optimal_spherical_cancellable(
    rep: &SphericalMotion,
    k: usize,
    objective: ErrorMeasure,
    cancel: &Cancel,
) -> Result<(KeyframeSet, f64)> {
    let n = rep.num_frames;
    check_k(n, k)?;
    match objective {
        ErrorMeasure::Angle => {
            PrunedCosts::build(n, k, &mut AngleFrames::new(rep), cancel, None, &mut |_| {})?.solution()
        }
        ErrorMeasure::Position => {
            let mut frames = ModelFrames { model: rep, objective, scratch: rep.scratch() };
            PrunedCosts::build(n, k, &mut frames, cancel, None, &mut |_| {})?.solution()
        }
    }
}

/// What [`optimal_spherical_memo`] learnt about one clip's segments, for the next search on the same
/// clip with another `k` (a studio's K slider): the cost of every segment costed in full, and for a
/// segment given up on, the partial sum that exceeded its room (a lower bound of its cost). Known
/// costs are not recomputed, and the bounds prune more. About `16·n²` bytes.
#[derive(Clone, Debug)]
pub struct OptimalMemo {
    n: usize,
    objective: ErrorMeasure,
    /// `exact[a * n + b]`: the cost of segment `(a, b)`, NaN while unknown.
    exact: Vec<f64>,
    /// `lower[a * n + b]`: a lower bound of that cost (0 while nothing is known).
    lower: Vec<f64>,
}

impl OptimalMemo {
    /// An empty memo for a clip of `n` frames and one objective.
    pub fn new(n: usize, objective: ErrorMeasure) -> OptimalMemo {
        OptimalMemo { n, objective, exact: vec![f64::NAN; n * n], lower: vec![0.0; n * n] }
    }

    fn exact(&self, a: usize, b: usize) -> Option<f64> {
        let c = self.exact[a * self.n + b];
        (!c.is_nan()).then_some(c)
    }
}

/// [`optimal_spherical_cancellable`] that reuses and extends `memo` (made for this clip and
/// objective; another is refused): the same keys and total, bit for bit, whatever the memo holds.
/// `progress` hears the share of the search done (0 to 1, about fifty times).
pub fn optimal_spherical_memo(
    rep: &SphericalMotion,
    k: usize,
    objective: ErrorMeasure,
    cancel: &Cancel,
    memo: &mut OptimalMemo,
    progress: &mut dyn FnMut(f64),
) -> Result<(KeyframeSet, f64)> {
    let n = rep.num_frames;
    check_k(n, k)?;
    if memo.n != n || memo.objective != objective {
        return Err(MocapError::Invalid(format!(
            "the optimal-keys memo was made for {} frames and {:?} error, not {n} frames and {objective:?}",
            memo.n, memo.objective
        )));
    }
    match objective {
        ErrorMeasure::Angle => {
            PrunedCosts::build(n, k, &mut AngleFrames::new(rep), cancel, Some(memo), progress)?.solution()
        }
        ErrorMeasure::Position => {
            let mut frames = ModelFrames { model: rep, objective, scratch: rep.scratch() };
            PrunedCosts::build(n, k, &mut frames, cancel, Some(memo), progress)?.solution()
        }
    }
}

/// The programme of [`optimal`] over segment costs `cost(i, j)` (∞: no such segment), for segments
/// up to `max_gap` frames long; the keys and the total of the optimal path.
fn shortest_path(n: usize, max_gap: usize, k: usize, cost: impl Fn(usize, usize) -> f64) -> Result<(KeyframeSet, f64)> {
    let inf = f64::INFINITY;
    // dp[c * n + j]: best cost of a chain of c+1 keys from frame 0 ending at key j.
    let mut dp = vec![inf; k * n];
    let mut from = vec![usize::MAX; k * n];
    dp[0] = 0.0;
    for c in 1..k {
        let (done, rest) = dp.split_at_mut(c * n);
        let prev_row = &done[(c - 1) * n..];
        for j in 1..n {
            let lo = j.saturating_sub(max_gap);
            let mut best = (inf, usize::MAX);
            for (i, &prev) in prev_row.iter().enumerate().take(j).skip(lo) {
                if prev == inf {
                    continue;
                }
                let v = prev + cost(i, j);
                if v < best.0 {
                    best = (v, i);
                }
            }
            rest[j] = best.0;
            from[c * n + j] = best.1;
        }
    }
    let total = dp[(k - 1) * n + n - 1];
    if total == inf {
        return Err(MocapError::Invalid(format!(
            "{k} keys cannot cover {n} frames with segments of at most {max_gap} frames"
        )));
    }
    Ok((KeyframeSet::new(backtrack(&from, n, k - 1, n - 1), n)?, total))
}

fn backtrack(from: &[usize], n: usize, mut c: usize, mut j: usize) -> Vec<usize> {
    let mut keys = vec![j];
    while c > 0 {
        j = from[c * n + j];
        keys.push(j);
        c -= 1;
    }
    keys
}

/// One objective's error of the frames reconstructed from keys `a < b`, frame by frame: a segment's
/// cost is `0.0 + frame(a+1) + … + frame(b−1)` in this order.
trait FrameObjective {
    /// Writes the error of frame `f` to `out[f − lo]` for every `f` in `lo..hi` (`a < lo ≤ hi ≤ b`).
    fn frames(&mut self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64]);
}

/// Any model's frame cost through [`SegmentModel::frame_cost`] (the position objective).
struct ModelFrames<'m> {
    model: &'m dyn SegmentModel,
    objective: ErrorMeasure,
    scratch: crate::metrics::Scratch,
}

impl FrameObjective for ModelFrames<'_> {
    fn frames(&mut self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64]) {
        for (f, o) in (lo..hi).zip(out) {
            *o = self.objective.of(&self.model.frame_cost(a, b, f, &mut self.scratch));
        }
    }
}

/// The angle term of [`SphericalMotion`]'s frame cost alone: θ and φ of every angle-carrying joint
/// by the Hermite cubic of `reconstruct::segment_frame`, against the source, with the same
/// floating-point operations in the same order (each frame sums its joints in joint order). Joints
/// are the vector lanes: the source is copied frame-major.
#[derive(Clone, Debug)]
pub(crate) struct AngleFrames {
    /// Angle-carrying joints.
    m: usize,
    /// θ, θ̇, φ, φ̇ of the angle-carrying joints, frame-major (`[frame * m + joint]`).
    theta: Vec<f64>,
    dtheta: Vec<f64>,
    phi: Vec<f64>,
    dphi: Vec<f64>,
    frame_time: f64,
    term: Vec<f64>,
}

impl AngleFrames {
    pub(crate) fn new(rep: &SphericalMotion) -> AngleFrames {
        let n = rep.num_frames;
        let angled: Vec<usize> = (0..rep.num_joints).filter(|&j| rep.has_angles[j]).collect();
        let pick = |v: &[f64]| (0..n).flat_map(|f| angled.iter().map(move |&j| v[j * n + f])).collect();
        AngleFrames {
            m: angled.len(),
            theta: pick(&rep.theta),
            dtheta: pick(&rep.dtheta),
            phi: pick(&rep.phi),
            dphi: pick(&rep.dphi),
            frame_time: rep.frame_time,
            term: vec![0.0; angled.len()],
        }
    }
}

impl FrameObjective for AngleFrames {
    fn frames(&mut self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64]) {
        let mut term = std::mem::take(&mut self.term);
        self.eval(a, b, lo, hi, out, &mut term);
        self.term = term;
    }
}

impl AngleFrames {
    /// Angle-carrying joints: the length of the `term` buffer [`AngleFrames::eval`] needs.
    pub(crate) fn joints(&self) -> usize {
        self.m
    }

    /// The angle error of frames `lo..hi` reconstructed from keys `a < lo ≤ hi ≤ b`, into
    /// `out[f − lo]`, with `term` (at least [`AngleFrames::joints`] long) as scratch. Uses AVX2
    /// where the CPU has it (checked at run time): the same operations on wider vectors, so the
    /// same numbers.
    pub(crate) fn eval(&self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64], term: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { self.frames_avx2(a, b, lo, hi, out, term) };
            return;
        }
        self.frames_with(a, b, lo, hi, out, term);
    }

    /// The cost of segment `(a, b)`: its frames' errors summed in frame order (the same number as
    /// [`SegmentModel::segment_cost`]'s `angle_sum`). `buf` holds at least `b − a` values.
    pub(crate) fn segment(&self, a: usize, b: usize, buf: &mut [f64], term: &mut [f64]) -> f64 {
        self.eval(a, b, a + 1, b, &mut buf[..b - a - 1], term);
        buf[..b - a - 1].iter().fold(0.0, |s, t| s + t)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn frames_avx2(&self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64], term: &mut [f64]) {
        self.frames_with(a, b, lo, hi, out, term);
    }

    #[inline(always)]
    fn frames_with(&self, a: usize, b: usize, lo: usize, hi: usize, out: &mut [f64], term: &mut [f64]) {
        let m = self.m;
        fn row(v: &[f64], m: usize, f: usize) -> &[f64] {
            &v[f * m..][..m]
        }
        let at = |v, f| row(v, m, f);
        let (ta, tva, tb, tvb) = (at(&self.theta, a), at(&self.dtheta, a), at(&self.theta, b), at(&self.dtheta, b));
        let (pa, pva, pb, pvb) = (at(&self.phi, a), at(&self.dphi, a), at(&self.phi, b), at(&self.dphi, b));
        let term = &mut term[..m];
        // As `segment_frame` computes them.
        let h = (b - a) as f64 * self.frame_time;
        for (f, o) in (lo..hi).zip(out.iter_mut()) {
            let (h00, h10, h01, h11) = hermite_basis((f - a) as f64 / (b - a) as f64);
            let (h10, h11) = (h10 * h, h11 * h);
            let (tf, pf) = (at(&self.theta, f), at(&self.phi, f));
            // Core `hermite`: h00·p0 + h10·h·v0 + h01·p1 + h11·h·v1, left to right.
            let mut wide = false;
            for j in 0..m {
                let theta = h00 * ta[j] + h10 * tva[j] + h01 * tb[j] + h11 * tvb[j];
                let phi = h00 * pa[j] + h10 * pva[j] + h01 * pb[j] + h11 * pvb[j];
                let d = phi - pf[j];
                let within = d.abs() < TAU; // false for NaN too
                wide |= !within;
                let r = if d < 0.0 { d + TAU } else { d };
                term[j] = (theta - tf[j]).abs() + r.min(TAU - r);
            }
            if wide {
                // Some φ difference is a turn or more (or not a number): core's formula in full.
                for j in 0..m {
                    let theta = h00 * ta[j] + h10 * tva[j] + h01 * tb[j] + h11 * tvb[j];
                    let phi = h00 * pa[j] + h10 * pva[j] + h01 * pb[j] + h11 * pvb[j];
                    term[j] = (theta - tf[j]).abs() + wrapped_angle_difference(phi, pf[j]);
                }
            }
            *o = term.iter().fold(0.0, |s, t| s + t);
        }
    }
}

/// `inbetween_core::metrics::wrapped_angle_difference`, bit for bit, without the `fmod` call for
/// differences within a turn (where `d % τ` is `d` exactly).
#[inline]
fn wrapped_angle_difference(a: f64, b: f64) -> f64 {
    let d = a - b;
    let r = if d.abs() < TAU {
        if d < 0.0 {
            d + TAU
        } else {
            d
        }
    } else {
        d.rem_euclid(TAU)
    };
    r.min(TAU - r)
}

/// The segment costs [`optimal_spherical`] computes (`n × n`, ∞ where a segment was dropped) and
/// the programme of [`optimal`] run over them, column by column as they are computed.
struct PrunedCosts {
    n: usize,
    k: usize,
    costs: Vec<f64>,
    /// `dp[c * n + j]`, `from[c * n + j]`: as in [`shortest_path`].
    dp: Vec<f64>,
    from: Vec<usize>,
}

/// Relative slack on every bound, far above the rounding of sums of at most a few hundred terms.
const SLACK: f64 = 1e-9;

impl PrunedCosts {
    fn build(
        n: usize,
        k: usize,
        frames: &mut impl FrameObjective,
        cancel: &Cancel,
        mut memo: Option<&mut OptimalMemo>,
        progress: &mut dyn FnMut(f64),
    ) -> Result<PrunedCosts> {
        let known = |memo: &Option<&mut OptimalMemo>, a: usize, b: usize| memo.as_ref().and_then(|m| m.exact(a, b));
        let inf = f64::INFINITY;
        let mut costs = vec![inf; n * n];
        let mut terms = vec![0.0; n];
        // 1. Every segment up to g0 = ⌈1.5 · ⌈(n−1)/(k−1)⌉⌉ frames long, in full (k − 1 of them cover
        // the clip).
        let span = (n - 1).div_ceil(k - 1);
        let g0 = (span + span.div_ceil(2)).min(n - 1);
        for a in 0..n {
            cancel.check()?;
            for b in a + 1..=(a + g0).min(n - 1) {
                costs[a * n + b] = match known(&memo, a, b) {
                    Some(c) => c,
                    None => {
                        frames.frames(a, b, a + 1, b, &mut terms);
                        let c = terms[..b - a - 1].iter().fold(0.0, |s, t| s + t);
                        if let Some(m) = memo.as_deref_mut() {
                            m.exact[a * n + b] = c;
                        }
                        c
                    }
                };
            }
        }
        // The best path over them bounds the optimum U (floating-point addition is monotone, so the
        // full programme's value is at most the banded one's). Not finite, or NaN costs: no pruning.
        let short = |a: usize, b: usize| costs[a * n + b];
        let bound = shortest_path(n, g0, k, short).map_or(inf, |(_, u)| u);
        let exact = !bound.is_finite() || costs.iter().any(|c| c.is_nan());
        progress(0.1);
        // 2. A lower bound of every longer segment: its middle frames, or what the memo knows.
        let mut lower = costs.clone();
        for a in 0..n {
            cancel.check()?;
            for b in a + g0 + 1..n {
                let known = memo.as_ref().map_or(0.0, |m| m.exact(a, b).unwrap_or(m.lower[a * n + b]));
                let (lo, hi) = middle(a, b);
                let mid = if known > 0.0 {
                    0.0
                } else {
                    frames.frames(a, b, lo, hi, &mut terms[lo..hi]);
                    terms[lo..hi].iter().sum::<f64>()
                };
                lower[a * n + b] = mid.max(known) * (1.0 - SLACK);
            }
        }
        // 3. after[r * n + j]: a lower bound of the cost from a key at j to the last frame in r segments.
        let mut after = vec![inf; k * n];
        after[n - 1] = 0.0;
        for r in 1..k {
            for j in 0..n - 1 {
                let next = &after[(r - 1) * n..r * n];
                after[r * n + j] = (j + 1..n).map(|b| lower[j * n + b] + next[b]).fold(inf, f64::min);
            }
        }
        // 4. The programme column by column. Before column j, every state of an earlier column is
        // final, so a longer segment (i, j) can only lie on a path of total
        // ≥ min_c dp[c][i] + cost(i, j) + after[k−2−c][j]; it is dropped once that exceeds U. The
        // states of the optimal path are exact (their segments are never dropped), and dropping a
        // segment only raises other candidates, so every state of that path keeps its predecessor.
        let mut table = PrunedCosts { n, k, costs, dp: vec![inf; k * n], from: vec![usize::MAX; k * n] };
        table.dp[0] = 0.0;
        let room_total = bound * (1.0 + SLACK);
        // The least dp of each finished column and the least `after` of each frame over the c of
        // the bound: a segment whose lower bound passes even the room they leave is dropped without
        // the minimum over c (floating-point addition is monotone, so that room is never smaller).
        let mut least_dp = vec![inf; n];
        least_dp[0] = 0.0;
        let least_after: Vec<f64> = (0..n).map(|j| (0..k - 1).map(|r| after[r * n + j]).fold(inf, f64::min)).collect();
        // The predecessors with a cost into column j, in frame order.
        let mut into = Vec::with_capacity(n);
        progress(0.2);
        let every = (n / 50).max(1);
        for j in 1..n {
            cancel.check()?;
            if j % every == 0 {
                progress(0.2 + 0.8 * j as f64 / n as f64);
            }
            into.clear();
            for i in 0..j.saturating_sub(g0) {
                let low = lower[i * n + j];
                let room = if exact {
                    inf
                } else {
                    if low > room_total - (least_dp[i] + least_after[j]) * (1.0 - SLACK) {
                        continue;
                    }
                    let base = (0..k - 1).map(|c| table.dp[c * n + i] + after[(k - 2 - c) * n + j]).fold(inf, f64::min);
                    room_total - base * (1.0 - SLACK)
                };
                if low > room {
                    continue;
                }
                if let Some(cost) = known(&memo, i, j) {
                    table.costs[i * n + j] = cost;
                    into.push(i);
                    continue;
                }
                match segment_within(frames, i, j, room / (1.0 - SLACK), &mut terms) {
                    Ok(cost) => {
                        table.costs[i * n + j] = cost;
                        into.push(i);
                        if let Some(m) = memo.as_deref_mut() {
                            m.exact[i * n + j] = cost;
                        }
                    }
                    Err(partial) => {
                        if let Some(m) = memo.as_deref_mut() {
                            m.lower[i * n + j] = m.lower[i * n + j].max(partial);
                        }
                    }
                }
            }
            into.extend((j.saturating_sub(g0)..j).filter(|&i| table.costs[i * n + j].is_finite()));
            table.column(j, &into);
            least_dp[j] = (0..k - 1).map(|c| table.dp[c * n + j]).fold(inf, f64::min);
        }
        Ok(table)
    }

    /// `dp[c][j]` and its predecessor for every c, exactly as [`shortest_path`] computes them, over
    /// the predecessors `into` (every `i` whose cost into `j` is finite, in frame order: an infinite
    /// or NaN cost never wins the strict minimum).
    fn column(&mut self, j: usize, into: &[usize]) {
        let n = self.n;
        for c in 1..self.k {
            let mut best = (f64::INFINITY, usize::MAX);
            for &i in into {
                let prev = self.dp[(c - 1) * n + i];
                if prev == f64::INFINITY {
                    continue;
                }
                let v = prev + self.costs[i * n + j];
                if v < best.0 {
                    best = (v, i);
                }
            }
            (self.dp[c * n + j], self.from[c * n + j]) = best;
        }
    }

    /// The optimal keys and total, as [`shortest_path`] gives them over these costs.
    fn solution(&self) -> Result<(KeyframeSet, f64)> {
        let (n, k) = (self.n, self.k);
        let total = self.dp[(k - 1) * n + n - 1];
        if total == f64::INFINITY {
            return Err(MocapError::Invalid(format!("{k} keys cannot cover {n} frames")));
        }
        Ok((KeyframeSet::new(backtrack(&self.from, n, k - 1, n - 1), n)?, total))
    }

    #[cfg(test)]
    fn get(&self, a: usize, b: usize) -> f64 {
        self.costs[a * self.n + b]
    }
}

/// The middle frames of segment `(a, b)` (at most three), as a range.
fn middle(a: usize, b: usize) -> (usize, usize) {
    let mid = (a + b) / 2;
    ((mid - 1).max(a + 1), (mid + 2).min(b))
}

/// The cost of segment `(a, b)` (its frame terms summed in frame order), or, as soon as the terms
/// seen, from the middle outwards in growing blocks, sum past `room`, that partial sum (a lower bound
/// of the cost).
fn segment_within(
    frames: &mut impl FrameObjective,
    a: usize,
    b: usize,
    room: f64,
    terms: &mut [f64],
) -> std::result::Result<f64, f64> {
    let (mut lo, mut hi) = middle(a, b);
    frames.frames(a, b, lo, hi, &mut terms[lo..hi]);
    let mut partial = terms[lo..hi].iter().sum::<f64>();
    let mut step = 2;
    while lo > a + 1 || hi < b {
        if partial > room {
            return Err(partial);
        }
        let (l, h) = (lo.saturating_sub(step).max(a + 1), (hi + step).min(b));
        frames.frames(a, b, l, lo, &mut terms[l..lo]);
        frames.frames(a, b, hi, h, &mut terms[hi..h]);
        partial += terms[l..lo].iter().chain(&terms[hi..h]).sum::<f64>();
        (lo, hi, step) = (l, h, 2 * step);
    }
    if partial > room {
        return Err(partial);
    }
    Ok(terms[a + 1..b].iter().fold(0.0, |s, t| s + t))
}

/// The fewest keys such that no frame's position error exceeds `max_cm` (ties: lowest total
/// `objective` error). Always feasible: neighbouring keys leave no frame in between.
pub fn error_bounded(table: &SegmentTable, max_cm: f64, objective: ErrorMeasure) -> Result<KeyframeSet> {
    let n = table.num_frames;
    if n < 2 {
        return Err(MocapError::Invalid(format!("a clip of {n} frames has no segments")));
    }
    // (keys used, total error) to reach frame j, compared lexicographically.
    let mut best = vec![(usize::MAX, f64::INFINITY); n];
    let mut from = vec![usize::MAX; n];
    best[0] = (1, 0.0);
    for j in 1..n {
        for i in j.saturating_sub(table.max_gap)..j {
            let Some(seg) = table.get(i, j) else { continue };
            if seg.cm_max > max_cm || best[i].0 == usize::MAX {
                continue;
            }
            let cand = (best[i].0 + 1, best[i].1 + objective.of(seg));
            if cand.0 < best[j].0 || cand.0 == best[j].0 && cand.1 < best[j].1 {
                best[j] = cand;
                from[j] = i;
            }
        }
    }
    let mut keys = vec![n - 1];
    let mut j = n - 1;
    while j != 0 {
        j = from[j];
        keys.push(j);
    }
    Ok(KeyframeSet::new(keys, n)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::{spherical_error, SegmentModel};
    use crate::reconstruct::reconstruct_spherical;
    use crate::representation::{JointFilter, SphericalMotion};
    use crate::select::greedy;
    use inbetween_core::procedural::gait_library;

    /// Every subset of interior frames of a given size, as keyframe sets.
    fn subsets(n: usize, interior: usize) -> Vec<KeyframeSet> {
        let mut out = Vec::new();
        for mask in 0u32..(1 << (n - 2)) {
            if mask.count_ones() as usize == interior {
                let frames = (0..n - 2).filter(|i| mask >> i & 1 == 1).map(|i| i + 1).collect();
                out.push(KeyframeSet::new(frames, n).unwrap());
            }
        }
        out
    }

    fn short_clips() -> Vec<SphericalMotion> {
        // 12 frames at 30 fps of varied walks and runs, 23 joints.
        gait_library(11, 3, 12, 30.0)
            .iter()
            .map(|m| SphericalMotion::from_motion(&JointFilter::paper().apply(m)).unwrap())
            .collect()
    }

    #[test]
    fn optimal_equals_brute_force_and_beats_greedy() {
        for rep in short_clips() {
            let table = SegmentTable::full(&rep);
            for k in [3, 4, 5] {
                for objective in [ErrorMeasure::Angle, ErrorMeasure::Position] {
                    let score = |e: crate::ReconstructionError| match objective {
                        ErrorMeasure::Angle => e.mean_angle,
                        ErrorMeasure::Position => e.mean_cm,
                    };
                    let brute = subsets(12, k - 2)
                        .iter()
                        .map(|keys| score(spherical_error(&rep, &reconstruct_spherical(&rep, keys))))
                        .fold(f64::INFINITY, f64::min);
                    let opt = optimal(&table, k, objective).unwrap();
                    assert_eq!(opt.len(), k);
                    assert_eq!(optimal_spherical(&rep, k, objective).unwrap(), opt);
                    let got = score(spherical_error(&rep, &reconstruct_spherical(&rep, &opt)));
                    assert!((got - brute).abs() < 1e-12, "k={k} {objective:?}: optimal {got} vs brute force {brute}");
                    let g = greedy(&rep, k, objective).unwrap();
                    assert_eq!(g.len(), k);
                    assert!(score(rep.error(&g)) >= got - 1e-12, "greedy beat the optimum");
                }
            }
        }
    }

    #[test]
    fn error_bounded_is_the_fewest_keys_under_the_bound() {
        for rep in short_clips() {
            let table = SegmentTable::full(&rep);
            for bound in [0.5, 2.0, 8.0] {
                let keys = error_bounded(&table, bound, ErrorMeasure::Position).unwrap();
                let e = spherical_error(&rep, &reconstruct_spherical(&rep, &keys));
                assert!(e.max_cm <= bound + 1e-9);
                // No smaller set meets the bound.
                let fewest = (0..=10)
                    .find(|&m| {
                        subsets(12, m)
                            .iter()
                            .any(|s| spherical_error(&rep, &reconstruct_spherical(&rep, s)).max_cm <= bound)
                    })
                    .unwrap();
                assert_eq!(keys.len(), fewest + 2, "bound {bound}");
            }
        }
    }

    /// The selector as it was before `optimal_spherical` (a verbatim copy of the old `optimal`,
    /// returning its total too): the reference the fast path must match bit for bit.
    fn reference_optimal(table: &SegmentTable, k: usize, objective: ErrorMeasure) -> Result<(KeyframeSet, f64)> {
        let n = table.num_frames;
        check_k(n, k)?;
        let inf = f64::INFINITY;
        let mut dp = vec![inf; k * n];
        let mut from = vec![usize::MAX; k * n];
        dp[0] = 0.0;
        for c in 1..k {
            for j in 1..n {
                let lo = j.saturating_sub(table.max_gap);
                let mut best = (inf, usize::MAX);
                for i in lo..j {
                    let prev = dp[(c - 1) * n + i];
                    if prev == inf {
                        continue;
                    }
                    let Some(seg) = table.get(i, j) else { continue };
                    let v = prev + objective.of(seg);
                    if v < best.0 {
                        best = (v, i);
                    }
                }
                dp[c * n + j] = best.0;
                from[c * n + j] = best.1;
            }
        }
        let total = dp[(k - 1) * n + n - 1];
        if total == inf {
            return Err(MocapError::Invalid("infeasible".into()));
        }
        Ok((KeyframeSet::new(backtrack(&from, n, k - 1, n - 1), n)?, total))
    }

    /// Procedural windows of several lengths, and copies with seeded noise on the angles and
    /// velocities (small, large, and φ shifted by whole and odd turns so the wrap takes every path).
    fn varied_windows() -> Vec<SphericalMotion> {
        use rand::{Rng, SeedableRng};
        let mut out = Vec::new();
        for (seed, count, frames) in [(1, 4, 60), (2, 3, 60), (6, 3, 60), (3, 2, 64), (4, 2, 37), (5, 2, 12)] {
            for m in gait_library(seed, count, frames, 30.0) {
                out.push(SphericalMotion::from_motion(&JointFilter::paper().apply(&m)).unwrap());
            }
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(14);
        let base: Vec<SphericalMotion> = out.iter().step_by(3).cloned().collect();
        for (i, rep) in base.into_iter().enumerate() {
            let mut noisy = rep.clone();
            let scale = [0.01, 0.3, 2.0][i % 3];
            for v in noisy.theta.iter_mut().chain(&mut noisy.phi) {
                *v += scale * rng.random_range(-1.0..1.0);
            }
            for v in noisy.dtheta.iter_mut().chain(&mut noisy.dphi) {
                *v += 10.0 * scale * rng.random_range(-1.0..1.0);
            }
            if i % 2 == 1 {
                for v in noisy.phi.iter_mut() {
                    *v += std::f64::consts::TAU * rng.random_range(-3..=3) as f64 + rng.random_range(-4.0..4.0);
                }
            }
            out.push(noisy);
        }
        out
    }

    #[test]
    fn optimal_spherical_gives_the_keys_and_total_of_the_table_programme_bit_for_bit() {
        let windows = varied_windows();
        assert!(windows.len() >= 20);
        let mut cases = 0;
        for (w, rep) in windows.iter().enumerate() {
            let n = rep.num_frames;
            let table = SegmentTable::full_serial(rep);
            let mut ks: Vec<usize> = (2..=16).chain([20, 30, n / 2, n - 2, n - 1, n]).filter(|&k| k <= n).collect();
            ks.dedup();
            for objective in [ErrorMeasure::Angle, ErrorMeasure::Position] {
                // Position is the slow objective to tabulate: every other window.
                if objective == ErrorMeasure::Position && w % 2 == 1 {
                    continue;
                }
                // One memo carried up through the k, another down (new longer segments each time).
                let (mut up, mut down) = (OptimalMemo::new(n, objective), OptimalMemo::new(n, objective));
                let mut wants = Vec::new();
                for &k in &ks {
                    let (want, want_total) = reference_optimal(&table, k, objective).unwrap();
                    let (got, got_total) = optimal_spherical_with_total(rep, k, objective).unwrap();
                    assert_eq!(got, want, "window {w}, k={k}, {objective:?}");
                    assert_eq!(got_total.to_bits(), want_total.to_bits(), "window {w}, k={k}, {objective:?}");
                    assert_eq!(optimal(&table, k, objective).unwrap(), want);
                    let memo = optimal_spherical_memo(rep, k, objective, &Cancel::new(), &mut up, &mut |_| {}).unwrap();
                    assert_eq!(
                        (memo.0, memo.1.to_bits()),
                        (want.clone(), want_total.to_bits()),
                        "up, window {w}, k={k}"
                    );
                    wants.push((k, want, want_total));
                    cases += 1;
                }
                for (k, want, want_total) in wants.into_iter().rev() {
                    let memo =
                        optimal_spherical_memo(rep, k, objective, &Cancel::new(), &mut down, &mut |_| {}).unwrap();
                    assert_eq!((memo.0, memo.1.to_bits()), (want, want_total.to_bits()), "down, window {w}, k={k}");
                }
            }
        }
        assert!(cases > 400, "{cases}");
    }

    #[test]
    fn a_cancelled_token_stops_optimal_and_greedy_with_the_reason() {
        use inbetween_core::cancel::Cancelled;
        let windows = varied_windows();
        let rep = &windows[0];
        let stopped = Cancel::new();
        stopped.cancel();
        for e in [
            optimal_spherical_cancellable(rep, 5, ErrorMeasure::Angle, &stopped).unwrap_err(),
            super::super::greedy_cancellable(rep, 5, ErrorMeasure::Angle, &stopped).unwrap_err(),
        ] {
            assert!(matches!(e, MocapError::Cancelled(Cancelled::Requested)), "{e}");
            assert_eq!(e.to_string(), "stopped: cancelled");
        }
        // A token that never fires changes nothing.
        let free = Cancel::new();
        assert_eq!(
            optimal_spherical_cancellable(rep, 5, ErrorMeasure::Angle, &free).unwrap(),
            optimal_spherical_with_total(rep, 5, ErrorMeasure::Angle).unwrap()
        );
        assert_eq!(
            super::super::greedy_cancellable(rep, 5, ErrorMeasure::Angle, &free).unwrap(),
            super::super::greedy(rep, 5, ErrorMeasure::Angle).unwrap()
        );
    }

    #[test]
    fn the_search_reports_its_progress_in_order() {
        let rep = &varied_windows()[0];
        let mut seen = Vec::new();
        let mut memo = OptimalMemo::new(rep.num_frames, ErrorMeasure::Angle);
        optimal_spherical_memo(rep, 5, ErrorMeasure::Angle, &Cancel::new(), &mut memo, &mut |f| seen.push(f)).unwrap();
        assert!(seen.len() >= 10, "{seen:?}");
        assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
        assert!(seen[0] > 0.0 && *seen.last().unwrap() > 0.9 && *seen.last().unwrap() <= 1.0, "{seen:?}");
    }

    #[test]
    fn a_memo_of_another_clip_or_objective_is_refused() {
        let rep = &varied_windows()[0];
        let n = rep.num_frames;
        for mut memo in [OptimalMemo::new(n + 1, ErrorMeasure::Angle), OptimalMemo::new(n, ErrorMeasure::Position)] {
            let e = optimal_spherical_memo(rep, 3, ErrorMeasure::Angle, &Cancel::new(), &mut memo, &mut |_| {})
                .unwrap_err();
            assert!(e.to_string().contains("memo was made for"), "{e}");
        }
    }

    #[test]
    fn kept_costs_are_the_tables_and_dropped_ones_lie_on_no_optimal_path() {
        let mut dropped_at_15 = (0, 0);
        for rep in varied_windows().iter().step_by(2) {
            let n = rep.num_frames;
            let table = SegmentTable::full_serial(rep);
            let cost = |a: usize, b: usize| table.get(a, b).unwrap().angle_sum;
            for k in [3, 5, 10, 15].into_iter().filter(|&k| k <= n) {
                let kept =
                    PrunedCosts::build(n, k, &mut AngleFrames::new(rep), &Cancel::new(), None, &mut |_| {}).unwrap();
                let (_, best) = reference_optimal(&table, k, ErrorMeasure::Angle).unwrap();
                // The least total of any k-key path through each segment, from the full table.
                let inf = f64::INFINITY;
                let (mut before, mut after) = (vec![inf; k * n], vec![inf; k * n]);
                before[0] = 0.0;
                after[n - 1] = 0.0;
                for c in 1..k {
                    for j in 0..n {
                        before[c * n + j] = (0..j).map(|i| before[(c - 1) * n + i] + cost(i, j)).fold(inf, f64::min);
                        after[c * n + j] = (j + 1..n).map(|b| cost(j, b) + after[(c - 1) * n + b]).fold(inf, f64::min);
                    }
                }
                for a in 0..n {
                    for b in a + 1..n {
                        let got = kept.get(a, b);
                        if got.is_finite() {
                            assert_eq!(got.to_bits(), cost(a, b).to_bits(), "({a}, {b}) k={k}");
                        } else {
                            let through = (0..k - 1)
                                .map(|c| before[c * n + a] + cost(a, b) + after[(k - 2 - c) * n + b])
                                .fold(inf, f64::min);
                            assert!(through > best, "({a}, {b}) k={k}: dropped, yet a path through it costs {through}");
                            if k == 15 && n == 60 {
                                dropped_at_15.0 += 1;
                            }
                        }
                    }
                }
                if k == 15 && n == 60 {
                    dropped_at_15.1 += n * (n - 1) / 2;
                }
            }
        }
        // At K = 15 most segments are never costed in full.
        assert!(2 * dropped_at_15.0 > dropped_at_15.1, "{dropped_at_15:?}");
    }

    #[test]
    fn angle_frames_match_the_models_frame_costs_on_every_code_path() {
        let mut scratch = None;
        for rep in varied_windows().iter().step_by(4) {
            let n = rep.num_frames;
            let s = scratch.get_or_insert_with(|| rep.scratch());
            let mut frames = AngleFrames::new(rep);
            let (mut plain, mut auto) = (vec![0.0; n], vec![0.0; n]);
            for a in 0..n {
                for b in a + 2..n {
                    let mut term = vec![0.0; frames.joints()];
                    frames.frames_with(a, b, a + 1, b, &mut plain[a + 1..b], &mut term);
                    frames.frames(a, b, a + 1, b, &mut auto[a + 1..b]);
                    for f in a + 1..b {
                        let want = rep.frame_cost(a, b, f, s).angle_sum;
                        assert_eq!(plain[f].to_bits(), want.to_bits(), "({a}, {b}) frame {f}");
                        assert_eq!(auto[f].to_bits(), want.to_bits(), "({a}, {b}) frame {f}");
                    }
                }
            }
        }
    }

    #[test]
    fn fast_wrapped_difference_is_cores_bit_for_bit() {
        use inbetween_core::metrics::wrapped_angle_difference as core_wrap;
        use rand::{Rng, SeedableRng};
        let t = std::f64::consts::TAU;
        let mut pairs = vec![(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (t, 0.0), (0.0, t), (-t, 0.0), (3.0 * t, 0.1)];
        for x in [t, -t, 0.5 * t, -0.5 * t, 2.0 * t, -2.0 * t] {
            for ulps in -3i64..=3 {
                pairs.push((f64::from_bits((x.to_bits() as i64 + ulps) as u64), 0.0));
            }
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..100_000 {
            let s = [1e-3, 1.0, 6.0, 7.0, 40.0][rng.random_range(0..5)];
            pairs.push((s * rng.random_range(-1.0..1.0), s * rng.random_range(-1.0..1.0)));
        }
        for (a, b) in pairs {
            assert_eq!(wrapped_angle_difference(a, b).to_bits(), core_wrap(a, b).to_bits(), "{a} {b}");
        }
    }

    #[test]
    fn banded_optimum_reports_infeasible_k() {
        let rep = &short_clips()[0];
        let table = SegmentTable::banded(rep, 3);
        assert!(optimal(&table, 3, ErrorMeasure::Angle).is_err());
        let keys = optimal(&table, 5, ErrorMeasure::Angle).unwrap();
        assert!(keys.segments().all(|(a, b)| b - a <= 3));
    }
}
