//! The paper's Greedy baseline (§5.4): start from the first and last frame and repeatedly add the
//! frame whose insertion gives the lowest total error. Adding frame `f` inside segment `(a, b)` only
//! changes that segment's error, so each segment's best split is found once (its candidates cost two
//! segment evaluations each, memoised) and kept until the segment is split.
//!
//! Greedy never moves a key it has added, so the keys for `k` are the first `k` of one insertion
//! order: [`GreedyOrder`] keeps that order and its state, and gives any `k` without starting over (a
//! studio's K slider; growing `k` continues from where it stopped).

use super::check_k;
use super::optimal::AngleFrames;
use crate::metrics::{ErrorMeasure, SegmentModel};
use crate::representation::SphericalMotion;
use crate::Result;
use inbetween_core::cancel::Cancel;
use inbetween_core::KeyframeSet;
use std::collections::HashMap;

/// The `k` keys Greedy picks.
pub fn greedy(model: &dyn SegmentModel, k: usize, objective: ErrorMeasure) -> Result<KeyframeSet> {
    greedy_cancellable(model, k, objective, &Cancel::new())
}

/// [`greedy`] that checks `cancel` before each key it adds (and while costing a long segment's
/// splits) and returns [`crate::MocapError::Cancelled`] once it is cancelled.
pub fn greedy_cancellable(
    model: &dyn SegmentModel,
    k: usize,
    objective: ErrorMeasure,
    cancel: &Cancel,
) -> Result<KeyframeSet> {
    GreedyOrder::new(model, objective).keys(k, cancel)
}

/// How a segment's error is computed.
enum Cost<'a> {
    /// Any model, through [`SegmentModel::segment_cost`].
    Model { model: &'a dyn SegmentModel, objective: ErrorMeasure, scratch: crate::metrics::Scratch },
    /// The mean angle error of a [`SphericalMotion`] without positions or trigonometry: the same
    /// numbers as the model's `angle_sum` (see [`AngleFrames`]).
    Angle { frames: AngleFrames, buf: Vec<f64>, term: Vec<f64> },
}

impl Cost<'_> {
    fn of(&mut self, a: usize, b: usize) -> f64 {
        match self {
            Cost::Model { model, objective, scratch } => objective.of(&model.segment_cost(a, b, scratch)),
            Cost::Angle { frames, buf, term } => frames.segment(a, b, buf, term),
        }
    }
}

/// Greedy's insertion order and the state to continue it: [`GreedyOrder::keys`] gives the keys for
/// any `k`, computing only the keys not yet added.
pub struct GreedyOrder<'a> {
    n: usize,
    cost: Cost<'a>,
    /// Keys in the order added (the first and last frame first).
    order: Vec<usize>,
    /// The keys in frame order.
    sorted: Vec<usize>,
    /// Segment costs by `(a, b)`.
    memo: HashMap<(usize, usize), f64>,
    /// The best split of each current segment by its first key: (error change, frame), or None for a
    /// segment with no frame inside.
    split: HashMap<usize, Option<(f64, usize)>>,
}

impl<'a> GreedyOrder<'a> {
    /// Greedy over any segment model.
    pub fn new(model: &'a dyn SegmentModel, objective: ErrorMeasure) -> GreedyOrder<'a> {
        let scratch = model.scratch();
        GreedyOrder::with(model.num_frames(), Cost::Model { model, objective, scratch })
    }

    /// Greedy over the mean angle error of `rep` (the studio's and the bench's objective) without
    /// rebuilding positions: the same keys as [`GreedyOrder::new`]`(rep, ErrorMeasure::Angle)`, several
    /// times faster. Owns a copy of the angles it needs, so it may outlive `rep`.
    pub fn angle(rep: &SphericalMotion) -> GreedyOrder<'static> {
        let n = rep.num_frames;
        let frames = AngleFrames::new(rep);
        let term = vec![0.0; frames.joints()];
        GreedyOrder::with(n, Cost::Angle { frames, buf: vec![0.0; n], term })
    }

    fn with(n: usize, cost: Cost<'a>) -> GreedyOrder<'a> {
        let order = if n >= 2 { vec![0, n - 1] } else { vec![] };
        GreedyOrder { n, cost, sorted: order.clone(), order, memo: HashMap::new(), split: HashMap::new() }
    }

    /// The keys added so far, in the order added.
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// The `k` keys Greedy picks (the first `k` of its order), adding keys until there are `k`.
    pub fn keys(&mut self, k: usize, cancel: &Cancel) -> Result<KeyframeSet> {
        check_k(self.n, k)?;
        while self.order.len() < k {
            cancel.check()?;
            self.add(cancel)?;
        }
        Ok(KeyframeSet::new(self.order[..k].to_vec(), self.n)?)
    }

    /// Adds the frame that lowers the total error most (ties: the earliest frame; costs are
    /// expected to be numbers).
    fn add(&mut self, cancel: &Cancel) -> Result<()> {
        let mut best: Option<(f64, usize, usize)> = None;
        for s in 0..self.sorted.len() - 1 {
            let (a, b) = (self.sorted[s], self.sorted[s + 1]);
            let split = match self.split.get(&a) {
                Some(&split) => split,
                None => {
                    let split = self.best_split(a, b, cancel)?;
                    self.split.insert(a, split);
                    split
                }
            };
            if let Some((delta, f)) = split {
                if best.is_none_or(|(d, _, _)| delta < d) {
                    best = Some((delta, f, s + 1));
                }
            }
        }
        let (_, f, at) = best.expect("k ≤ n leaves a frame to add");
        let a = self.sorted[at - 1];
        self.sorted.insert(at, f);
        self.order.push(f);
        self.split.remove(&a);
        Ok(())
    }

    /// The frame of `(a, b)` whose insertion changes the error most (lowest change, earliest frame).
    fn best_split(&mut self, a: usize, b: usize, cancel: &Cancel) -> Result<Option<(f64, usize)>> {
        let whole = self.segment(a, b);
        let mut best: Option<(f64, usize)> = None;
        for f in a + 1..b {
            if (f - a).is_multiple_of(64) {
                cancel.check()?;
            }
            let delta = self.segment(a, f) + self.segment(f, b) - whole;
            if best.is_none_or(|(d, _)| delta < d) {
                best = Some((delta, f));
            }
        }
        Ok(best)
    }

    fn segment(&mut self, a: usize, b: usize) -> f64 {
        if let Some(&c) = self.memo.get(&(a, b)) {
            return c;
        }
        let c = self.cost.of(a, b);
        self.memo.insert((a, b), c);
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams};

    /// The selector as it was before [`GreedyOrder`]: every segment's splits rescanned for each key.
    fn reference(model: &dyn SegmentModel, k: usize, objective: ErrorMeasure) -> KeyframeSet {
        let n = model.num_frames();
        let mut keys = KeyframeSet::new(vec![], n).unwrap();
        let mut memo: HashMap<(usize, usize), f64> = HashMap::new();
        let mut scratch = model.scratch();
        let mut cost = |a: usize, b: usize| -> f64 {
            *memo.entry((a, b)).or_insert_with(|| objective.of(&model.segment_cost(a, b, &mut scratch)))
        };
        while keys.len() < k {
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
            keys.insert(best.unwrap().1);
        }
        keys
    }

    fn clips() -> Vec<SphericalMotion> {
        [(37, GaitParams::walk()), (90, GaitParams::walk()), (61, GaitParams::run())]
            .into_iter()
            .map(|(frames, p)| SphericalMotion::from_motion(&gait(&GaitParams { frames, ..p })).unwrap())
            .collect()
    }

    #[test]
    fn the_order_gives_the_keys_of_rescanning_greedy_for_every_k() {
        let cancel = Cancel::new();
        for rep in clips() {
            let n = rep.num_frames;
            for objective in [ErrorMeasure::Angle, ErrorMeasure::Position] {
                let mut order = GreedyOrder::new(&rep, objective);
                // Up and down: a smaller k after a larger one is a prefix, a larger one continues.
                for k in [2, 9, 5, n.min(30), 3, n] {
                    assert_eq!(order.keys(k, &cancel).unwrap(), reference(&rep, k, objective), "n={n} k={k}");
                }
            }
            let mut fast = GreedyOrder::angle(&rep);
            for k in [n, 4, 17] {
                assert_eq!(
                    fast.keys(k, &cancel).unwrap(),
                    reference(&rep, k, ErrorMeasure::Angle),
                    "angle n={n} k={k}"
                );
            }
        }
    }

    #[test]
    fn a_k_that_does_not_fit_is_refused() {
        let rep = &clips()[0];
        let mut order = GreedyOrder::angle(rep);
        assert!(order.keys(1, &Cancel::new()).is_err());
        assert!(order.keys(rep.num_frames + 1, &Cancel::new()).is_err());
        assert_eq!(order.order(), &[0, rep.num_frames - 1]);
    }
}
