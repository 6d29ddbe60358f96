//! The paper's Greedy baseline (§5.4): start from the first and last frame and repeatedly add the
//! frame whose insertion gives the lowest total error. Adding frame `f` inside segment `(a, b)` only
//! changes that segment's error, so each candidate costs two segment evaluations, memoised.

use super::check_k;
use crate::metrics::{ErrorMeasure, SegmentCost, SegmentModel};
use crate::Result;
use inbetween_core::KeyframeSet;
use std::collections::HashMap;

pub fn greedy(model: &dyn SegmentModel, k: usize, objective: ErrorMeasure) -> Result<KeyframeSet> {
    greedy_cancellable(model, k, objective, &inbetween_core::cancel::Cancel::new())
}

/// [`greedy`] that checks `cancel` before each key it adds and returns
/// [`crate::MocapError::Cancelled`] once it is cancelled.
pub fn greedy_cancellable(
    model: &dyn SegmentModel,
    k: usize,
    objective: ErrorMeasure,
    cancel: &inbetween_core::cancel::Cancel,
) -> Result<KeyframeSet> {
    let n = model.num_frames();
    check_k(n, k)?;
    let mut keys = KeyframeSet::new(vec![], n)?;
    let mut memo: HashMap<(usize, usize), SegmentCost> = HashMap::new();
    let mut scratch = model.scratch();
    let mut cost = |a: usize, b: usize| -> f64 {
        objective.of(memo.entry((a, b)).or_insert_with(|| model.segment_cost(a, b, &mut scratch)))
    };
    while keys.len() < k {
        cancel.check()?;
        let mut best: Option<(f64, usize)> = None;
        for (a, b) in keys.segments().collect::<Vec<_>>() {
            let whole = cost(a, b);
            for f in a + 1..b {
                let delta = cost(a, f) + cost(f, b) - whole;
                if best.is_none_or(|(d, _)| delta < d) {
                    best = Some((delta, f));
                }
            }
        }
        let (_, f) = best.expect("k ≤ n leaves a frame to add");
        keys.insert(f);
    }
    Ok(keys)
}
