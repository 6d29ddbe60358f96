//! The programme of the exact selector over any segment costs: `dp[c][j] = min_i dp[c−1][i] +
//! cost(i, j)`, and the walk back along its predecessors.

use crate::{MocapError, Result};
use inbetween_core::KeyframeSet;

/// The programme of [`optimal`](super::optimal) over segment costs `cost(i, j)` (∞: no such segment), for segments
/// up to `max_gap` frames long; the keys and the total of the optimal path.
pub(super) fn shortest_path(
    n: usize,
    max_gap: usize,
    k: usize,
    cost: impl Fn(usize, usize) -> f64,
) -> Result<(KeyframeSet, f64)> {
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

pub(super) fn backtrack(from: &[usize], n: usize, mut c: usize, mut j: usize) -> Vec<usize> {
    let mut keys = vec![j];
    while c > 0 {
        j = from[c * n + j];
        keys.push(j);
        c -= 1;
    }
    keys
}
