//! Key refinement (beyond the paper): coordinate descent on the positions of a key set. Each
//! interior key in turn moves to the frame between its two neighbouring keys that gives the two
//! segments around it the lowest summed cost; sweeps repeat until no key moves.
//!
//! The total error is a sum of segment costs (module docs of [`super::optimal`]), so moving one key
//! changes only its two segments and every move lowers the total: the result is never worse than
//! the keys it starts from. It is not the optimum (a key cannot jump past its neighbour), but it
//! mends the usual fault of top-down insertion, a first split that suited one key and not `k`. The
//! SIDQL policy finishes its keys with it (`crate::dqn::SidqlPolicy::select`).

/// Sweeps over every key before giving up on a fixed point (each sweep lowers the total, so this
/// only bounds the time; on the CMU windows 2–3 sweeps reach a fixed point).
pub const MAX_SWEEPS: usize = 8;

/// Refines `keys` (sorted, first frame 0 and last frame `n − 1`, both kept) in place, reading segment
/// costs from `cost(a, b)`. Returns the number of moves made.
pub fn refine_keys(keys: &mut [usize], mut cost: impl FnMut(usize, usize) -> f64) -> usize {
    let mut moves = 0;
    for _ in 0..MAX_SWEEPS {
        let mut moved = false;
        for i in 1..keys.len().saturating_sub(1) {
            let (prev, here, next) = (keys[i - 1], keys[i], keys[i + 1]);
            let now = cost(prev, here) + cost(here, next);
            let mut best = (now, here);
            for f in prev + 1..next {
                if f == here {
                    continue;
                }
                let c = cost(prev, f) + cost(f, next);
                // Only a strict improvement beyond rounding moves a key: sweeps cannot cycle.
                if c < best.0 - 1e-12 * now.abs() {
                    best = (c, f);
                }
            }
            if best.1 != here {
                keys[i] = best.1;
                moved = true;
                moves += 1;
            }
        }
        if !moved {
            break;
        }
    }
    moves
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn total(keys: &[usize], c: &[f64], n: usize) -> f64 {
        keys.windows(2).map(|w| c[w[0] * n + w[1]]).sum()
    }

    /// A random table of segment costs that grow with length, like reconstruction errors.
    fn table(n: usize, rng: &mut impl Rng) -> Vec<f64> {
        let noise: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let mut c = vec![0.0; n * n];
        for a in 0..n {
            for b in a + 1..n {
                let inner: f64 = noise[a..b].iter().sum();
                c[a * n + b] = inner * (b - a) as f64 * rng.random_range(0.5..1.5);
            }
        }
        c
    }

    /// Every key set of size k (brute force) for the oracle.
    fn best_total(n: usize, k: usize, c: &[f64]) -> f64 {
        let mut best = f64::INFINITY;
        for m in 0u64..1 << (n - 2) {
            if m.count_ones() as usize == k - 2 {
                let mut keys = vec![0];
                keys.extend((0..n - 2).filter(|&i| m >> i & 1 == 1).map(|i| i + 1));
                keys.push(n - 1);
                best = best.min(total(&keys, c, n));
            }
        }
        best
    }

    /// Against brute force: never worse than the start, never better than the optimum, and at a
    /// fixed point no single key can move to lower the total.
    #[test]
    fn refinement_only_lowers_the_total_and_ends_at_a_fixed_point() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut improved = 0;
        for trial in 0..60 {
            let n = rng.random_range(5..13);
            let k = rng.random_range(3..n.min(7));
            let c = table(n, &mut rng);
            let mut keys: Vec<usize> =
                rand::seq::index::sample(&mut rng, n - 2, k - 2).into_iter().map(|i| i + 1).collect();
            keys.push(0);
            keys.push(n - 1);
            keys.sort_unstable();
            let before = total(&keys, &c, n);
            refine_keys(&mut keys, |a, b| c[a * n + b]);
            let after = total(&keys, &c, n);
            assert!(after <= before, "trial {trial}: {after} > {before}");
            assert!(after >= best_total(n, k, &c) - 1e-9, "trial {trial}: below the optimum");
            assert!(keys.windows(2).all(|w| w[0] < w[1]) && keys[0] == 0 && keys[k - 1] == n - 1);
            for i in 1..k - 1 {
                for f in keys[i - 1] + 1..keys[i + 1] {
                    let mut moved = keys.clone();
                    moved[i] = f;
                    assert!(total(&moved, &c, n) >= after - 1e-9 * after, "trial {trial}: key {i} could move to {f}");
                }
            }
            improved += usize::from(after < before);
        }
        assert!(improved > 30, "random key sets should usually improve ({improved} of 60)");
    }

    #[test]
    fn end_keys_and_tiny_sets_stay_put() {
        let mut keys = vec![0, 9];
        assert_eq!(refine_keys(&mut keys, |a, b| (b - a) as f64), 0);
        assert_eq!(keys, [0, 9]);
        let mut keys = vec![0, 1, 2];
        refine_keys(&mut keys, |a, b| (b - a) as f64);
        assert_eq!(keys, [0, 1, 2]);
    }
}
