//! Exact cost-to-go of keyframe selection (beyond the paper): given the keys chosen so far (a mask)
//! and how many keys may still be added, the least total error any completion reaches. SIDQL is
//! pretrained on these values (`crate::dqn::train`): they are the undiscounted optimal Q-values of
//! the keyframe MDP of §4.1.
//!
//! The total error is a sum of segment costs (module docs of [`super::optimal`]), so the optimum
//! is a shortest path again, now through every key of the mask: a segment `(i, j)` may be used only
//! if no key of the mask lies strictly inside it. Counting the added keys before (forward pass) and
//! after (backward pass) each frame gives, for every candidate frame at once, the best completion
//! that adds it: `O(extra · n · gap)` for all candidates together.
//!
//! Costs are a full `n × n` table, row-major, `costs[a * n + b]` for `a < b` (see
//! [`angle_segment_costs`]).

use super::optimal::AngleFrames;
use crate::representation::SphericalMotion;

const INF: f64 = f64::INFINITY;

/// Every segment's mean-angle cost (the `angle_sum` of [`crate::metrics::SegmentModel::segment_cost`],
/// the same numbers) of a window of at most 64 frames, as an `n × n` table (0 below the diagonal).
pub fn angle_segment_costs(rep: &SphericalMotion) -> Vec<f64> {
    let n = rep.num_frames;
    let frames = AngleFrames::new(rep);
    let (mut buf, mut term) = (vec![0.0; n], vec![0.0; frames.joints()]);
    let mut costs = vec![0.0; n * n];
    for a in 0..n {
        for b in a + 1..n {
            costs[a * n + b] = frames.segment(a, b, &mut buf, &mut term);
        }
    }
    costs
}

/// The forward and backward passes for one mask and budget.
struct Passes {
    n: usize,
    /// `fwd[e * n + j]`: least cost from frame 0 to a key at `j`, through every mask key before
    /// `j`, with `e` added keys strictly before `j`.
    fwd: Vec<f64>,
    /// `bwd[e * n + j]`: least cost from a key at `j` to the last frame, through every mask key
    /// after `j`, with `e` added keys strictly after `j`.
    bwd: Vec<f64>,
}

fn is_key(mask: u64, f: usize) -> bool {
    mask >> f & 1 == 1
}

impl Passes {
    fn new(costs: &[f64], n: usize, mask: u64, extra: usize) -> Passes {
        let c = |i: usize, j: usize| costs[i * n + j];
        let rows = extra + 1;
        let (mut fwd, mut bwd) = (vec![INF; rows * n], vec![INF; rows * n]);
        fwd[0] = 0.0;
        bwd[n - 1] = 0.0;
        // Forward: segment (i, j) needs no mask key strictly inside, so i ≥ the last key before j.
        let mut last_key = 0;
        for j in 1..n {
            for i in last_key..j {
                let add = usize::from(!is_key(mask, i));
                for e in add..rows {
                    let v = fwd[(e - add) * n + i] + c(i, j);
                    if v < fwd[e * n + j] {
                        fwd[e * n + j] = v;
                    }
                }
            }
            if is_key(mask, j) {
                last_key = j;
            }
        }
        let mut next_key = n - 1;
        for j in (0..n - 1).rev() {
            for k in j + 1..=next_key {
                let add = usize::from(!is_key(mask, k));
                for e in add..rows {
                    let v = bwd[(e - add) * n + k] + c(j, k);
                    if v < bwd[e * n + j] {
                        bwd[e * n + j] = v;
                    }
                }
            }
            if is_key(mask, j) {
                next_key = j;
            }
        }
        Passes { n, fwd, bwd }
    }
}

fn check(n: usize, costs: &[f64], mask: u64) {
    assert!((2..=64).contains(&n) && costs.len() == n * n, "a cost table of {n} × {n} frames (at most 64)");
    assert!(is_key(mask, 0) && is_key(mask, n - 1), "the mask keeps the first and last frame");
}

/// The least total error reachable from the keys in `mask` (bit `f` set: frame `f` is a key; the
/// first and last frame must be keys) by adding exactly `extra` keys; ∞ when fewer than `extra`
/// frames are free.
pub fn cost_to_go(costs: &[f64], n: usize, mask: u64, extra: usize) -> f64 {
    check(n, costs, mask);
    Passes::new(costs, n, mask, extra).fwd[extra * n + n - 1]
}

/// For every frame `a` that is not a key: the least total error after adding `a` and then
/// `extra − 1` more keys (the optimal value of action `a` with `extra` keys to add); ∞ for keys,
/// and for every frame when `extra` is 0 or too few frames are free. Written to `out[..n]`.
pub fn completion_values(costs: &[f64], n: usize, mask: u64, extra: usize, out: &mut [f64]) {
    check(n, costs, mask);
    out[..n].iter_mut().for_each(|v| *v = INF);
    if extra == 0 {
        return;
    }
    let p = Passes::new(costs, n, mask, extra - 1);
    for (a, slot) in out.iter_mut().enumerate().take(n) {
        if is_key(mask, a) {
            continue;
        }
        *slot = (0..extra).map(|e| p.fwd[e * p.n + a] + p.bwd[(extra - 1 - e) * p.n + a]).fold(INF, f64::min);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::{ErrorMeasure, SegmentModel};
    use crate::representation::JointFilter;
    use inbetween_core::procedural::gait_library;
    use inbetween_core::KeyframeSet;
    use rand::{Rng, SeedableRng};

    fn windows(frames: usize) -> Vec<SphericalMotion> {
        gait_library(21, 3, frames, 30.0)
            .iter()
            .map(|m| SphericalMotion::from_motion(&JointFilter::paper().apply(m)).unwrap())
            .collect()
    }

    /// The least total over every way of adding `extra` keys to `mask`, by enumeration.
    fn brute(costs: &[f64], n: usize, mask: u64, extra: usize) -> f64 {
        let free: Vec<usize> = (0..n).filter(|&f| !is_key(mask, f)).collect();
        let mut best = INF;
        for pick in 0u32..(1 << free.len()) {
            if pick.count_ones() as usize != extra {
                continue;
            }
            let mut m = mask;
            for (i, &f) in free.iter().enumerate() {
                if pick >> i & 1 == 1 {
                    m |= 1 << f;
                }
            }
            let keys: Vec<usize> = (0..n).filter(|&f| is_key(m, f)).collect();
            best = best.min(keys.windows(2).map(|w| costs[w[0] * n + w[1]]).sum());
        }
        best
    }

    fn close(a: f64, b: f64) -> bool {
        a == b || (a - b).abs() <= 1e-12 * b.abs().max(1e-9)
    }

    #[test]
    fn the_table_holds_the_models_segment_costs() {
        let rep = &windows(14)[0];
        let costs = angle_segment_costs(rep);
        let mut s = rep.scratch();
        for a in 0..14 {
            for b in a + 1..14 {
                assert_eq!(
                    costs[a * 14 + b].to_bits(),
                    rep.segment_cost(a, b, &mut s).angle_sum.to_bits(),
                    "({a}, {b})"
                );
            }
        }
    }

    #[test]
    fn cost_to_go_and_completion_values_equal_brute_force() {
        let n = 12;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut checked = 0;
        for rep in windows(n) {
            let costs = angle_segment_costs(&rep);
            for _ in 0..12 {
                // A random mask with the end keys and 0–3 interior keys.
                let mut mask: u64 = 1 | 1 << (n - 1);
                for _ in 0..rng.random_range(0..4) {
                    mask |= 1 << rng.random_range(1..n - 1);
                }
                let free = n - mask.count_ones() as usize;
                for extra in 0..=4.min(free) {
                    let want = brute(&costs, n, mask, extra);
                    let got = cost_to_go(&costs, n, mask, extra);
                    assert!(close(got, want), "mask {mask:b}, extra {extra}: {got} vs brute force {want}");
                    let mut values = vec![0.0; n];
                    completion_values(&costs, n, mask, extra, &mut values);
                    for (a, &value) in values.iter().enumerate() {
                        if is_key(mask, a) || extra == 0 {
                            assert_eq!(value, INF);
                        } else {
                            let want = brute(&costs, n, mask | 1 << a, extra - 1);
                            assert!(close(value, want), "mask {mask:b}, extra {extra}, action {a}: {value} vs {want}");
                            checked += 1;
                        }
                    }
                }
                assert_eq!(cost_to_go(&costs, n, mask, free + 1), INF, "more keys than free frames");
            }
        }
        assert!(checked > 500, "{checked}");
    }

    #[test]
    fn from_the_end_keys_it_is_the_optimum() {
        for rep in windows(40) {
            let costs = angle_segment_costs(&rep);
            for k in [3, 5, 10, 15] {
                let (_, total) =
                    super::super::optimal::optimal_spherical_with_total(&rep, k, ErrorMeasure::Angle).unwrap();
                let ctg = cost_to_go(&costs, 40, 1 | 1 << 39, k - 2);
                assert!(close(ctg, total), "K={k}: {ctg} vs {total}");
                let uniform = KeyframeSet::uniform(40, k).unwrap();
                assert!(ctg <= rep.error(&uniform).mean_angle * (40 * rep.angle_terms_per_frame()) as f64 + 1e-12);
            }
        }
    }
}
