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
//!
//! Files: this one the entry points; [`pruned`](mod@pruned) the pruned search and its memo;
//! `frames` the per-frame objectives it sums; `path` the plain programme; `simd` the AVX2 kernels.
//! The fewest keys under a bound is [`crate::select::error_bounded`](mod@crate::select::error_bounded).

mod frames;
mod path;
pub mod pruned;
mod simd;
#[cfg(test)]
mod tests;

pub(crate) use frames::AngleFrames;
pub use pruned::{optimal_spherical_memo, OptimalMemo};

use crate::metrics::{ErrorMeasure, SegmentTable};
use crate::representation::SphericalMotion;
use crate::select::check_k;
use crate::Result;
use inbetween_core::cancel::Cancel;
use inbetween_core::KeyframeSet;
use path::shortest_path;

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
