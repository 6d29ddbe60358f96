//! Tests of the exact selectors (the pruned search against the plain programme, bit for bit).

use super::frames::*;
use super::path::*;
use super::pruned::*;
use super::simd::*;
use super::*;
use crate::metrics::{spherical_error, SegmentModel};
use crate::reconstruct::reconstruct_spherical;
use crate::representation::{JointFilter, SphericalMotion};
use crate::select::error_bounded;
use crate::select::greedy;
use crate::MocapError;
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
                assert_eq!((memo.0, memo.1.to_bits()), (want.clone(), want_total.to_bits()), "up, window {w}, k={k}");
                wants.push((k, want, want_total));
                cases += 1;
            }
            for (k, want, want_total) in wants.into_iter().rev() {
                let memo = optimal_spherical_memo(rep, k, objective, &Cancel::new(), &mut down, &mut |_| {}).unwrap();
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
        let e =
            optimal_spherical_memo(rep, 3, ErrorMeasure::Angle, &Cancel::new(), &mut memo, &mut |_| {}).unwrap_err();
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
                PrunedCosts::build(n, k, &mut AngleFrames::new(rep), &Cancel::new(), &mut memo, &mut |_| {}).unwrap();
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
        let got = optimal_spherical_memo(rep, k, ErrorMeasure::Angle, &Cancel::new(), &mut memo, &mut |_| {}).unwrap();
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
