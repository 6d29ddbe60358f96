//! The pruned search for the exact `k`-key optimum (steps 1–3 of the [module docs](super)): an
//! upper bound from short segments, lower bounds of the rest of a path, then the programme column
//! by column, dropping segments that cannot be on an optimal path; and [`OptimalMemo`], what one
//! search leaves for the next on the same clip.

use super::frames::{AngleFrames, FrameObjective, ModelFrames};
use super::path::backtrack;
use super::simd::{lower_to_go, min_of_sums};
use crate::metrics::{ErrorMeasure, SegmentModel};
use crate::representation::SphericalMotion;
use crate::select::check_k;
use crate::{MocapError, Result};
use inbetween_core::cancel::Cancel;
use inbetween_core::KeyframeSet;

/// What [`optimal_spherical_memo`] learnt about one clip's segments, for the next search on the same
/// clip with another `k` (a studio's K slider): the cost of every segment costed in full, and for
/// every other segment a lower bound of its cost (its middle frames, or the partial sum that
/// exceeded its room in an earlier search). Known costs are not recomputed, the bounds prune more,
/// and a search whose `k` is near an earlier one takes its upper bound from known costs alone.
/// About `20·n²` bytes (costs, bounds and their reach); a search without a memo makes a temporary one.
#[derive(Clone, Debug)]
pub struct OptimalMemo {
    pub(super) n: usize,
    pub(super) objective: ErrorMeasure,
    /// `exact[b * n + a]`: the cost of segment `(a, b)`, NaN while unknown (column-major: the
    /// programme reads the segments into one frame).
    pub(super) exact: Vec<f64>,
    /// `lower[b * n + a]`: a lower bound of that cost (its cost once known), NaN while nothing is
    /// known: the sum of the frames within `reach[b * n + a]` of its middle (see [`Reach`]).
    pub(super) lower: Vec<f64>,
    pub(super) reach: Vec<u32>,
    /// Some cost or bound came out NaN: searches prune nothing.
    pub(super) nan: bool,
    /// Every segment has a lower bound.
    pub(super) bounded: bool,
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

    pub(super) fn exact(&self, a: usize, b: usize) -> Option<f64> {
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

/// The programme of [`optimal`] over the segments [`optimal_spherical`] keeps, run column by column
/// as they are costed.
pub(super) struct PrunedCosts {
    pub(super) n: usize,
    pub(super) k: usize,
    /// `dp[j * k + c]` (frame-major: a frame's states together), `from[c * n + j]`: as in
    /// [`shortest_path`].
    pub(super) dp: Vec<f64>,
    pub(super) from: Vec<usize>,
    /// A column's predecessors while it is computed.
    pub(super) best_from: Vec<usize>,
    /// Every kept segment and its cost (tests).
    #[cfg(test)]
    pub(super) kept: Vec<(usize, usize, f64)>,
}

/// Relative slack on every bound, far above the rounding of sums of at most a few hundred terms.
const SLACK: f64 = 1e-9;

impl PrunedCosts {
    pub(super) fn build(
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
    pub(super) fn solution(&self) -> Result<(KeyframeSet, f64)> {
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
pub(super) fn banded_total(n: usize, g0: usize, k: usize, costs: &[f64], avx2: bool) -> f64 {
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

/// The middle frames of segment `(a, b)` (at most three), as a range.
fn middle(a: usize, b: usize) -> (usize, usize) {
    let mid = (a + b) / 2;
    ((mid - 1).max(a + 1), (mid + 2).min(b))
}

/// The frames of segment `(a, b)` within `reach` frames of its middle ones, as a range.
pub(super) fn within(a: usize, b: usize, reach: usize) -> (usize, usize) {
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
