//! The generator's random stream: SplitMix64 over [`inbetween_core::seed::mix`], seeded through
//! [`inbetween_core::seed::derive`] so each component (speech, blinks, …) of each clip draws from its
//! own uncorrelated stream. Small and allocation-free: a corpus of thousands of clips draws millions of
//! numbers. (The face crate does not depend on `rand`; this keeps it that way.)

use inbetween_core::seed::{derive, mix};

/// A seeded stream of random numbers.
#[derive(Clone, Debug)]
pub struct Rand {
    state: u64,
}

impl Rand {
    /// Sub-stream `stream` of the run seeded with `seed`.
    pub fn new(seed: u64, stream: u64) -> Rand {
        Rand { state: derive(seed, stream) }
    }

    /// Next 64 random bits (SplitMix64: a Weyl sequence through the `mix` finaliser).
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.state)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform index in 0..n (n > 0).
    pub fn index(&mut self, n: usize) -> usize {
        ((self.unit() * n as f64) as usize).min(n.saturating_sub(1))
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.unit(); // (0, 1]
        let v = self.unit();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// Exponential with the given mean.
    pub fn exp(&mut self, mean: f64) -> f64 {
        -mean * (1.0 - self.unit()).ln()
    }

    /// One element of a non-empty slice, chosen uniformly.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.index(items.len())]
    }

    /// An index drawn with probability proportional to `weights` (non-negative, not all zero).
    pub fn weighted(&mut self, weights: &[f64]) -> usize {
        let total: f64 = weights.iter().sum();
        let mut x = self.unit() * total;
        for (i, w) in weights.iter().enumerate() {
            if x < *w {
                return i;
            }
            x -= w;
        }
        weights.len() - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_repeat_differ_and_have_sane_moments() {
        let a: Vec<u64> = {
            let mut r = Rand::new(5, 1);
            (0..8).map(|_| r.next_u64()).collect()
        };
        let mut r = Rand::new(5, 1);
        assert_eq!(a, (0..8).map(|_| r.next_u64()).collect::<Vec<_>>());
        assert_ne!(Rand::new(5, 2).next_u64(), a[0]);
        let mut r = Rand::new(9, 0);
        let n = 20000;
        let (mut s, mut s2, mut e) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let x = r.normal();
            s += x;
            s2 += x * x;
            e += r.exp(2.0);
            let u = r.unit();
            assert!((0.0..1.0).contains(&u));
        }
        let n = n as f64;
        assert!((s / n).abs() < 0.05 && (s2 / n - 1.0).abs() < 0.05, "normal moments {} {}", s / n, s2 / n);
        assert!((e / n - 2.0).abs() < 0.1, "exponential mean {}", e / n);
        let mut counts = [0usize; 3];
        for _ in 0..3000 {
            counts[r.weighted(&[1.0, 0.0, 2.0])] += 1;
        }
        assert_eq!(counts[1], 0);
        assert!(counts[2] > counts[0]);
    }
}
