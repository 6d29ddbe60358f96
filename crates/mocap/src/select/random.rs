//! RC: the first and last frame plus `k − 2` distinct interior frames drawn uniformly.

use super::check_k;
use crate::Result;
use inbetween_core::KeyframeSet;
use rand::seq::index::sample;
use rand::Rng;

pub fn random(n: usize, k: usize, rng: &mut impl Rng) -> Result<KeyframeSet> {
    check_k(n, k)?;
    let interior: Vec<usize> =
        if n > 2 { sample(rng, n - 2, k - 2).into_iter().map(|i| i + 1).collect() } else { Vec::new() };
    Ok(KeyframeSet::new(interior, n)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn seeded_and_exactly_k() {
        let a = random(60, 10, &mut ChaCha8Rng::seed_from_u64(3)).unwrap();
        let b = random(60, 10, &mut ChaCha8Rng::seed_from_u64(3)).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.len(), 10);
        assert_eq!((a.frames()[0], a.frames()[9]), (0, 59));
        assert!(random(5, 6, &mut ChaCha8Rng::seed_from_u64(3)).is_err());
    }
}
