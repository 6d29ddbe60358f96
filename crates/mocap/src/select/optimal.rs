//! Exact selectors over a [`SegmentTable`] (beyond the paper). Each segment's error depends only on
//! its two keyframes, so:
//! - the minimum total error with exactly `k` keys is a shortest path with `k − 1` edges through the
//!   frames, solved by `dp[c][j] = min_i dp[c−1][i] + cost(i, j)` in O(k·n·gap);
//! - the fewest keys keeping every frame under an error bound is a shortest path over the segments
//!   whose own maximum error is within the bound (ties broken by the lower total error).

use super::check_k;
use crate::error::{Objective, SegmentTable};
use crate::{MocapError, Result};
use inbetween_core::KeyframeSet;

/// The keyframe set of exactly `k` keys with the lowest total `objective` error.
pub fn optimal(table: &SegmentTable, k: usize, objective: Objective) -> Result<KeyframeSet> {
    let n = table.num_frames;
    check_k(n, k)?;
    let inf = f64::INFINITY;
    // dp[c * n + j]: best cost of a chain of c+1 keys from frame 0 ending at key j.
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
    if dp[(k - 1) * n + n - 1] == inf {
        return Err(MocapError::Invalid(format!(
            "{k} keys cannot cover {n} frames with segments of at most {} frames",
            table.max_gap
        )));
    }
    Ok(KeyframeSet::new(backtrack(&from, n, k - 1, n - 1), n)?)
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

/// The fewest keys such that no frame's position error exceeds `max_cm` (ties: lowest total
/// `objective` error). Always feasible: neighbouring keys leave no frame in between.
pub fn error_bounded(table: &SegmentTable, max_cm: f64, objective: Objective) -> Result<KeyframeSet> {
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
    use crate::error::{spherical_error, SegmentModel};
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
                for objective in [Objective::Angle, Objective::Position] {
                    let score = |e: crate::ReconstructionError| match objective {
                        Objective::Angle => e.mean_angle,
                        Objective::Position => e.mean_cm,
                    };
                    let brute = subsets(12, k - 2)
                        .iter()
                        .map(|keys| score(spherical_error(&rep, &reconstruct_spherical(&rep, keys))))
                        .fold(f64::INFINITY, f64::min);
                    let opt = optimal(&table, k, objective).unwrap();
                    assert_eq!(opt.len(), k);
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
                let keys = error_bounded(&table, bound, Objective::Position).unwrap();
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

    #[test]
    fn banded_optimum_reports_infeasible_k() {
        let rep = &short_clips()[0];
        let table = SegmentTable::banded(rep, 3);
        assert!(optimal(&table, 3, Objective::Angle).is_err());
        let keys = optimal(&table, 5, Objective::Angle).unwrap();
        assert!(keys.segments().all(|(a, b)| b - a <= 3));
    }
}
