//! The fewest keys keeping every frame's position error under a bound (beyond the paper): a
//! shortest path over the segments whose own largest error is within the bound, ties broken by the
//! lower total error; exact, like [`crate::select::optimal`].

use crate::metrics::{ErrorMeasure, SegmentTable};
use crate::{MocapError, Result};
use inbetween_core::KeyframeSet;

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
