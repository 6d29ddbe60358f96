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
    optimal_spherical_memo(rep, k, objective, cancel, &mut OptimalMemo::new(n, objective), &mut |_| {})
}

/// What [`optimal_spherical_memo`] learnt about one clip's segments, for the next search on the same
/// clip with another `k` (a studio's K slider): the cost of every segment costed in full, and for
/// every other segment a lower bound of its cost (its middle frames, or the partial sum that
/// exceeded its room in an earlier search). Known costs are not recomputed, the bounds prune more,
/// and a search whose `k` is near an earlier one takes its upper bound from known costs alone.
/// About `20·n²` bytes (costs, bounds and their reach); a search without a memo makes a temporary one.
#[derive(Clone, Debug)]
pub struct OptimalMemo {
    n: usize,
    objective: ErrorMeasure,
    /// `exact[b * n + a]`: the cost of segment `(a, b)`, NaN while unknown (column-major: the
    /// programme reads the segments into one frame).
    exact: Vec<f64>,
    /// `lower[b * n + a]`: a lower bound of that cost (its cost once known), NaN while nothing is
    /// known: the sum of the frames within `reach[b * n + a]` of its middle (see [`Reach`]).
    lower: Vec<f64>,
    reach: Vec<u32>,
    /// Some cost or bound came out NaN: searches prune nothing.
    nan: bool,
    /// Every segment has a lower bound.
    bounded: bool,
}

impl OptimalMemo {
    /// An empty memo for a clip of `n` frames and one objective.
    pub fn new(n: usize, objective: ErrorMeasure) -> OptimalMemo {
        OptimalMemo {
            n,
            objective,
            exact: vec![f64::NAN; n * n],
            lower: vec![f64::NAN; n * n],
            reach: vec![0; n * n],
            nan: false,
            bounded: false,
        }
    }

    fn exact(&self, a: usize, b: usize) -> Option<f64> {
        let c = self.exact[b * self.n + a];
        (!c.is_nan()).then_some(c)
    }

    fn set_exact(&mut self, a: usize, b: usize, cost: f64) {
        self.nan |= cost.is_nan();
        self.exact[b * self.n + a] = cost;
        self.lower[b * self.n + a] = cost;
    }

    /// The frames within `reach` of the middle of `(a, b)` sum to `bound`.
    fn set_lower(&mut self, a: usize, b: usize, reach: usize, bound: f64) {
        self.nan |= bound.is_nan();
        self.lower[b * self.n + a] = bound;
        self.reach[b * self.n + a] = u32::try_from(reach).unwrap_or(u32::MAX);
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
        ErrorMeasure::Angle => PrunedCosts::build(n, k, &mut AngleFrames::new(rep), cancel, memo, progress)?.solution(),
        ErrorMeasure::Position => {
            let mut frames = ModelFrames { model: rep, objective, scratch: rep.scratch() };
            PrunedCosts::build(n, k, &mut frames, cancel, memo, progress)?.solution()
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

/// The programme of [`optimal`] over the segments [`optimal_spherical`] keeps, run column by column
/// as they are costed.
struct PrunedCosts {
    n: usize,
    k: usize,
    /// `dp[j * k + c]` (frame-major: a frame's states together), `from[c * n + j]`: as in
    /// [`shortest_path`].
    dp: Vec<f64>,
    from: Vec<usize>,
    /// A column's predecessors while it is computed.
    best_from: Vec<usize>,
    /// Every kept segment and its cost (tests).
    #[cfg(test)]
    kept: Vec<(usize, usize, f64)>,
}

/// Relative slack on every bound, far above the rounding of sums of at most a few hundred terms.
const SLACK: f64 = 1e-9;

impl PrunedCosts {
    fn build(
        n: usize,
        k: usize,
        frames: &mut impl FrameObjective,
        cancel: &Cancel,
        memo: &mut OptimalMemo,
        progress: &mut dyn FnMut(f64),
    ) -> Result<PrunedCosts> {
        let inf = f64::INFINITY;
        let mut terms = vec![0.0; n];
        // 1. An upper bound U of the optimum: the best path over segments up to
        // g0 = ⌈1.5 · ⌈(n−1)/(k−1)⌉⌉ frames long (k − 1 of them cover the clip). Those the memo knows
        // give it when they cover the clip (floating-point addition is monotone, so the full
        // programme's value is at most the banded one's); otherwise every such segment is costed.
        let span = (n - 1).div_ceil(k - 1);
        let g0 = (span + span.div_ceil(2)).min(n - 1);
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        let banded = |memo: &OptimalMemo| banded_total(n, g0, k, &memo.exact, avx2);
        let mut bound = if memo.nan { inf } else { banded(memo) };
        if !bound.is_finite() {
            for b in 1..n {
                cancel.check()?;
                for a in b.saturating_sub(g0)..b {
                    if memo.exact(a, b).is_none() {
                        frames.frames(a, b, a + 1, b, &mut terms);
                        memo.set_exact(a, b, terms[..b - a - 1].iter().fold(0.0, |s, t| s + t));
                    }
                }
            }
            bound = banded(memo);
        }
        // Not finite, or NaN costs: no pruning.
        let exact = !bound.is_finite() || memo.nan;
        progress(0.1);
        // 2. A lower bound of every segment nothing is known of: its middle frames.
        let unbounded = if memo.bounded { 0 } else { n };
        for b in 1..unbounded {
            cancel.check()?;
            for a in 0..b {
                if memo.lower[b * n + a].is_nan() {
                    if b == a + 1 {
                        memo.set_exact(a, b, 0.0);
                    } else {
                        let (lo, hi) = middle(a, b);
                        frames.frames(a, b, lo, hi, &mut terms[lo..hi]);
                        memo.set_lower(a, b, 0, terms[lo..hi].iter().sum::<f64>());
                    }
                }
            }
        }
        memo.bounded = true;
        // 3. after[r * n + j]: a lower bound of the cost from a key at j to the last frame in r
        // segments (min over b of lower(j, b) + after[r − 1][b], taken segment column by column).
        let scale = 1.0 - SLACK;
        let mut after = vec![inf; k * n];
        after[n - 1] = 0.0;
        if !exact {
            lower_to_go(&memo.lower, &mut after, n, scale, avx2);
        }
        // 4. The programme column by column. Before column j, every state of an earlier column is
        // final, so a segment (i, j) can only lie on a path of total
        // ≥ min_c dp[c][i] + cost(i, j) + after[k−2−c][j]; it is dropped once that exceeds U. The
        // states of the optimal path are exact (their segments are never dropped), and dropping a
        // segment only raises other candidates, so every state of that path keeps its predecessor
        // (the first i of its minimum: a segment of another path as good is not dropped either).
        let mut table = PrunedCosts {
            n,
            k,
            dp: vec![inf; k * n],
            from: vec![usize::MAX; k * n],
            best_from: Vec::with_capacity(k),
            #[cfg(test)]
            kept: Vec::new(),
        };
        table.dp[0] = 0.0;
        let room_total = bound * (1.0 + SLACK);
        // The least dp of each finished column and the least `after` of each frame over the c of
        // the bound: a segment whose lower bound passes even the room they leave is dropped without
        // the minimum over c (floating-point addition is monotone, so that room is never smaller).
        let mut least_dp = vec![inf; n];
        least_dp[0] = 0.0;
        let least_after: Vec<f64> = (0..n).map(|j| (0..k - 1).map(|r| after[r * n + j]).fold(inf, f64::min)).collect();
        // after_of[j * (k − 1) + c] = after[(k − 2 − c) * n + j]: the rest after a segment into j
        // that ends the c + 1-th segment, beside dp's states of a frame.
        let after_of: Vec<f64> =
            (0..n).flat_map(|j| (0..k - 1).map(move |c| (k - 2 - c) * n + j)).map(|x| after[x]).collect();
        // The predecessors with a cost into column j, in frame order, and their costs.
        let mut into = Vec::with_capacity(n);
        progress(0.2);
        let every = (n / 50).max(1);
        for j in 1..n {
            cancel.check()?;
            if j % every == 0 {
                progress(0.2 + 0.8 * j as f64 / n as f64);
            }
            into.clear();
            for (i, &least) in least_dp[..j].iter().enumerate() {
                let room = if exact {
                    inf
                } else {
                    let low = memo.lower[j * n + i] * scale;
                    if low > room_total - (least + least_after[j]) * scale {
                        continue;
                    }
                    let states = &table.dp[i * k..i * k + k - 1];
                    let rests = &after_of[j * (k - 1)..(j + 1) * (k - 1)];
                    let base = min_of_sums(states, rests, avx2);
                    let room = room_total - base * scale;
                    if low > room {
                        continue;
                    }
                    room
                };
                if let Some(cost) = memo.exact(i, j) {
                    into.push((i, cost));
                    continue;
                }
                let seen = (memo.reach[j * n + i] as usize, memo.lower[j * n + i]);
                match segment_within(frames, i, j, room / scale, seen, &mut terms) {
                    Ok(cost) => {
                        memo.set_exact(i, j, cost);
                        into.push((i, cost));
                    }
                    Err((reach, partial)) => memo.set_lower(i, j, reach, partial),
                }
            }
            table.column(j, &into);
            least_dp[j] = table.dp[j * k..j * k + k - 1].iter().copied().fold(inf, f64::min);
        }
        Ok(table)
    }

    /// `dp[c][j]` and its predecessor for every c, exactly as [`shortest_path`] computes them, over
    /// the predecessors `into` (every `i` whose cost into `j` is kept, in frame order: an infinite
    /// or NaN cost never wins the strict minimum).
    fn column(&mut self, j: usize, into: &[(usize, f64)]) {
        let (n, k) = (self.n, self.k);
        let (done, rest) = self.dp.split_at_mut(j * k);
        let best = &mut rest[1..k];
        let from = &mut self.best_from;
        from.clear();
        from.resize(k - 1, usize::MAX);
        // Predecessors in frame order for every c at once: the same first minimum as one c at a time.
        for &(i, cost) in into {
            for ((b, f), &prev) in best.iter_mut().zip(from.iter_mut()).zip(&done[i * k..i * k + k - 1]) {
                if prev == f64::INFINITY {
                    continue;
                }
                let v = prev + cost;
                if v < *b {
                    (*b, *f) = (v, i);
                }
            }
        }
        for (c, &f) in (1..k).zip(from.iter()) {
            self.from[c * n + j] = f;
        }
        #[cfg(test)]
        self.kept.extend(into.iter().map(|&(i, c)| (i, j, c)));
    }

    /// The optimal keys and total, as [`shortest_path`] gives them over these costs.
    fn solution(&self) -> Result<(KeyframeSet, f64)> {
        let (n, k) = (self.n, self.k);
        let total = self.dp[(n - 1) * k + k - 1];
        if total == f64::INFINITY {
            return Err(MocapError::Invalid(format!("{k} keys cannot cover {n} frames")));
        }
        Ok((KeyframeSet::new(backtrack(&self.from, n, k - 1, n - 1), n)?, total))
    }
}

/// The total of [`shortest_path`]`(n, g0, k, cost)` with `cost(a, b) = costs[b·n + a]` (NaN: no
/// such segment), ∞ when no path exists: the same minima, taken by value only.
fn banded_total(n: usize, g0: usize, k: usize, costs: &[f64], avx2: bool) -> f64 {
    let inf = f64::INFINITY;
    let (mut prev, mut row) = (vec![inf; n], vec![inf; n]);
    prev[0] = 0.0;
    for _ in 1..k {
        row[0] = inf;
        for j in 1..n {
            let lo = j.saturating_sub(g0);
            row[j] = min_of_sums(&prev[lo..j], &costs[j * n + lo..j * n + j], avx2);
        }
        std::mem::swap(&mut prev, &mut row);
    }
    prev[n - 1]
}

/// The least `a[x] + b[x]` (∞ for none; a NaN sum never wins, as with `<`). Any order of a minimum
/// gives the same number, so AVX2 (`avx2`: the CPU has it) takes four at a time.
#[inline]
fn min_of_sums(a: &[f64], b: &[f64], avx2: bool) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller checked that the CPU supports AVX2.
        return unsafe { min_of_sums_avx2(a, b) };
    }
    let _ = avx2;
    a.iter().zip(b).fold(f64::INFINITY, |m, (x, y)| {
        let v = x + y;
        if v < m {
            v
        } else {
            m
        }
    })
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn min_of_sums_avx2(a: &[f64], b: &[f64]) -> f64 {
    use std::arch::x86_64::*;
    let len = a.len().min(b.len());
    let mut acc = _mm256_set1_pd(f64::INFINITY);
    let mut x = 0;
    while x + 4 <= len {
        // SAFETY: x + 4 ≤ the length of both slices; unaligned loads. min_pd(v, acc) is `v < acc ? v : acc`.
        unsafe {
            let v = _mm256_add_pd(_mm256_loadu_pd(a.as_ptr().add(x)), _mm256_loadu_pd(b.as_ptr().add(x)));
            acc = _mm256_min_pd(v, acc);
        }
        x += 4;
    }
    let mut lanes = [0.0; 4];
    // SAFETY: four f64 lanes into a four-element array.
    unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), acc) };
    lanes.into_iter().chain((x..len).map(|x| a[x] + b[x])).fold(f64::INFINITY, |m, v| if v < m { v } else { m })
}

/// `after[r·n + j] = min over b > j of lower[b·n + j]·scale + after[(r − 1)·n + b]` for every row
/// r ≥ 1 (row 0 given). Segment columns from the last frame back: a row's value at b is final once
/// every later column is in, and each column is read once (the order of a minimum does not change
/// it). `avx2`: the CPU has it.
fn lower_to_go(lower: &[f64], after: &mut [f64], n: usize, scale: f64, avx2: bool) {
    let rows = after.len() / n;
    for b in (1..n).rev() {
        let column = &lower[b * n..b * n + b];
        for r in 1..rows {
            let (done, rest) = after.split_at_mut(r * n);
            let to_go = done[(r - 1) * n + b];
            if to_go == f64::INFINITY {
                continue;
            }
            let row = &mut rest[..b];
            #[cfg(target_arch = "x86_64")]
            if avx2 {
                // SAFETY: the caller checked that the CPU supports AVX2.
                unsafe { min_sums_avx2(row, column, scale, to_go) };
                continue;
            }
            let _ = avx2;
            for (o, &l) in row.iter_mut().zip(column) {
                let v = l * scale + to_go;
                *o = if v < *o { v } else { *o };
            }
        }
    }
}

/// `row[x] = min(column[x]·scale + to_go, row[x])` (as `<` picks), four at a time: plain stores of
/// `vminpd` (the compiler's own vectorisation chose masked stores, three times slower here).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn min_sums_avx2(row: &mut [f64], column: &[f64], scale: f64, to_go: f64) {
    use std::arch::x86_64::*;
    let len = row.len().min(column.len());
    let (s, t) = (_mm256_set1_pd(scale), _mm256_set1_pd(to_go));
    let mut x = 0;
    while x + 4 <= len {
        // SAFETY: x + 4 ≤ the length of both slices; unaligned loads and stores.
        unsafe {
            let l = _mm256_loadu_pd(column.as_ptr().add(x));
            let o = _mm256_loadu_pd(row.as_ptr().add(x));
            // min_pd(v, o) is `v < o ? v : o`.
            _mm256_storeu_pd(row.as_mut_ptr().add(x), _mm256_min_pd(_mm256_add_pd(_mm256_mul_pd(l, s), t), o));
        }
        x += 4;
    }
    for (o, &l) in row[x..len].iter_mut().zip(&column[x..len]) {
        let v = l * scale + to_go;
        *o = if v < *o { v } else { *o };
    }
}

/// The middle frames of segment `(a, b)` (at most three), as a range.
fn middle(a: usize, b: usize) -> (usize, usize) {
    let mid = (a + b) / 2;
    ((mid - 1).max(a + 1), (mid + 2).min(b))
}

/// The frames of segment `(a, b)` within `reach` frames of its middle ones, as a range.
fn within(a: usize, b: usize, reach: usize) -> (usize, usize) {
    let (lo, hi) = middle(a, b);
    (lo.saturating_sub(reach).max(a + 1), (hi + reach).min(b))
}

/// The cost of segment `(a, b)` (its frame terms summed in frame order), or, as soon as the terms
/// seen, from the middle outwards in growing steps, sum past `room`, how far they reach and that
/// partial sum (a lower bound of the cost). `seen`: the reach and sum of an earlier call that gave
/// up, to go on from.
fn segment_within(
    frames: &mut impl FrameObjective,
    a: usize,
    b: usize,
    room: f64,
    seen: (usize, f64),
    terms: &mut [f64],
) -> std::result::Result<f64, (usize, f64)> {
    let (mut reach, mut partial) = seen;
    let (first_lo, first_hi) = within(a, b, reach);
    let (mut lo, mut hi) = (first_lo, first_hi);
    let mut step = 2;
    while lo > a + 1 || hi < b {
        if partial > room {
            return Err((reach, partial));
        }
        reach += step;
        let (l, h) = within(a, b, reach);
        frames.frames(a, b, l, lo, &mut terms[l..lo]);
        frames.frames(a, b, hi, h, &mut terms[hi..h]);
        partial += terms[l..lo].iter().chain(&terms[hi..h]).sum::<f64>();
        (lo, hi, step) = (l, h, 2 * step);
    }
    if partial > room {
        return Err((reach, partial));
    }
    // The frames an earlier call summed, again for the sum in frame order.
    frames.frames(a, b, first_lo, first_hi, &mut terms[first_lo..first_hi]);
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
                let mut memo = OptimalMemo::new(n, ErrorMeasure::Angle);
                let built =
                    PrunedCosts::build(n, k, &mut AngleFrames::new(rep), &Cancel::new(), &mut memo, &mut |_| {})
                        .unwrap();
                let mut kept = vec![f64::INFINITY; n * n];
                for &(a, b, c) in &built.kept {
                    kept[a * n + b] = c;
                }
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
                        let got = kept[a * n + b];
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

    /// Random costs with ∞ and NaN among them, for the vector helpers.
    fn odd_costs(len: usize, seed: u64) -> Vec<f64> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..len)
            .map(|_| match rng.random_range(0..20) {
                0 => f64::INFINITY,
                1 => f64::NAN,
                2 => 0.0,
                _ => rng.random_range(0.0..10.0),
            })
            .collect()
    }

    #[test]
    fn vector_helpers_give_the_plain_loops_numbers_bit_for_bit() {
        #[cfg(target_arch = "x86_64")]
        let paths = [false, std::arch::is_x86_feature_detected!("avx2")];
        #[cfg(not(target_arch = "x86_64"))]
        let paths = [false, false];
        let inf = f64::INFINITY;
        for seed in 0..20u64 {
            let n = 3 + (seed as usize * 7) % 40;
            let costs = odd_costs(n * n, seed);
            let (a, b) = (odd_costs(n, seed + 100), odd_costs(n, seed + 200));
            // The least sum: as a fold with `<`.
            let plain = a.iter().zip(&b).fold(inf, |m, (x, y)| if x + y < m { x + y } else { m });
            for avx2 in paths {
                assert_eq!(min_of_sums(&a, &b, avx2).to_bits(), plain.to_bits(), "seed {seed}");
                for len in 0..n {
                    let p = a[..len].iter().zip(&b).fold(inf, |m, (x, y)| if x + y < m { x + y } else { m });
                    assert_eq!(min_of_sums(&a[..len], &b[..len], avx2).to_bits(), p.to_bits());
                }
            }
            // The banded programme's total: shortest_path's.
            for (g0, k) in [(2, n), (n - 1, 2), (n / 2 + 1, 3), (5, n / 2 + 1)] {
                let want = shortest_path(n, g0, k, |a, b| costs[b * n + a]).map_or(inf, |(_, u)| u);
                for avx2 in paths {
                    assert_eq!(
                        banded_total(n, g0, k, &costs, avx2).to_bits(),
                        want.to_bits(),
                        "seed {seed}, g0 {g0}, k {k}"
                    );
                }
            }
            // Rows of lower bounds to go (no NaN there: a NaN cost turns pruning off).
            let lower: Vec<f64> = costs.iter().map(|c| if c.is_nan() { 1.0 } else { *c }).collect();
            let rows = 4;
            let mut want = vec![inf; rows * n];
            want[n - 1] = 0.0;
            for r in 1..rows {
                for j in 0..n {
                    want[r * n + j] =
                        (j + 1..n).map(|b| lower[b * n + j] * 0.5 + want[(r - 1) * n + b]).fold(inf, f64::min);
                }
            }
            for avx2 in paths {
                let mut got = vec![inf; rows * n];
                got[n - 1] = 0.0;
                lower_to_go(&lower, &mut got, n, 0.5, avx2);
                assert_eq!(
                    got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    want.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    "seed {seed}"
                );
            }
        }
    }

    #[test]
    fn a_memo_resumes_given_up_segments_and_answers_near_k_from_known_costs() {
        let rep = &varied_windows()[0];
        let n = rep.num_frames;
        let table = SegmentTable::full_serial(rep);
        let mut memo = OptimalMemo::new(n, ErrorMeasure::Angle);
        // Every K from 12 down to 3 and back: each answer the table's.
        for k in (3..=12).rev().chain(3..=12) {
            let (want, total) = reference_optimal(&table, k, ErrorMeasure::Angle).unwrap();
            let got =
                optimal_spherical_memo(rep, k, ErrorMeasure::Angle, &Cancel::new(), &mut memo, &mut |_| {}).unwrap();
            assert_eq!((got.0, got.1.to_bits()), (want, total.to_bits()), "k={k}");
        }
        // What the memo holds: known costs are the table's, every bound is below the cost, and a
        // bound's reach stays inside its segment.
        for b in 1..n {
            for a in 0..b {
                let cost = table.get(a, b).unwrap().angle_sum;
                if let Some(c) = memo.exact(a, b) {
                    assert_eq!(c.to_bits(), cost.to_bits(), "({a}, {b})");
                } else {
                    let low = memo.lower[b * n + a];
                    assert!(low <= cost * (1.0 + 1e-12), "({a}, {b}): bound {low} above cost {cost}");
                    let (lo, hi) = within(a, b, memo.reach[b * n + a] as usize);
                    assert!(a < lo && hi <= b);
                }
            }
        }
        assert!(memo.bounded && !memo.nan);
    }

    #[test]
    fn a_nan_frame_turns_pruning_off_and_answers_as_the_table() {
        // A NaN angle on a frame makes the segments that key or span it NaN (never chosen).
        let mut rep = varied_windows()[1].clone();
        let n = rep.num_frames;
        rep.theta[3 * n + n / 2] = f64::NAN;
        let table = SegmentTable::full_serial(&rep);
        let mut memo = OptimalMemo::new(n, ErrorMeasure::Angle);
        let mut answered = [0, 0];
        for k in [6, 4, 8, 3, 2, 12] {
            let got = optimal_spherical_memo(&rep, k, ErrorMeasure::Angle, &Cancel::new(), &mut memo, &mut |_| {});
            match reference_optimal(&table, k, ErrorMeasure::Angle) {
                Ok((want, total)) => {
                    let got = got.unwrap();
                    assert_eq!((got.0, got.1.to_bits()), (want, total.to_bits()), "k={k}");
                    answered[0] += 1;
                }
                Err(_) => {
                    assert!(got.unwrap_err().to_string().contains("cannot cover"), "k={k}");
                    answered[1] += 1;
                }
            }
        }
        assert!(memo.nan);
        assert!(answered[0] > 0, "{answered:?}");
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
