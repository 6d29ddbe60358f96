//! Replay memory (§4.2): a ring buffer of transitions; when full, the oldest is replaced. States are
//! stored compactly (window index + keyframe mask) and rebuilt when sampled, since the state is a
//! function of the two.

use rand::Rng;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Transition {
    pub window: usize,
    pub mask: u64,
    pub action: usize,
    /// Saved as its bit pattern, so a checkpointed memory reads back exactly.
    #[serde(with = "f32_bits")]
    pub reward: f32,
    pub next_mask: u64,
    pub done: bool,
    /// The episode's K (keys at its end): the budget left is `k − |mask|`.
    #[serde(default)]
    pub k: usize,
}

mod f32_bits {
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(x: &f32, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u32(x.to_bits())
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
        u32::deserialize(d).map(f32::from_bits)
    }
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Replay {
    items: Vec<Transition>,
    capacity: usize,
    next: usize,
}

impl Replay {
    pub fn new(capacity: usize) -> Replay {
        Replay { items: Vec::with_capacity(capacity.min(1 << 20)), capacity: capacity.max(1), next: 0 }
    }

    pub fn push(&mut self, t: Transition) {
        if self.items.len() < self.capacity {
            self.items.push(t);
        } else {
            self.items[self.next] = t;
        }
        self.next = (self.next + 1) % self.capacity;
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// `n` transitions drawn uniformly with replacement.
    pub fn sample(&self, n: usize, rng: &mut impl Rng) -> Vec<Transition> {
        (0..n).map(|_| self.items[rng.random_range(0..self.items.len())]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn oldest_is_replaced_when_full() {
        let t = |w| Transition { window: w, mask: 0, action: 0, reward: 0.0, next_mask: 0, done: false, k: 5 };
        let mut r = Replay::new(3);
        for w in 0..5 {
            r.push(t(w));
        }
        assert_eq!(r.len(), 3);
        let mut ws: Vec<usize> = r.items.iter().map(|t| t.window).collect();
        ws.sort();
        assert_eq!(ws, vec![2, 3, 4]);
        let s = r.sample(10, &mut rand_chacha::ChaCha8Rng::seed_from_u64(1));
        assert!(s.iter().all(|t| t.window >= 2));
        // A checkpointed memory reads back exactly, rewards bit for bit.
        r.push(Transition { reward: 0.1 + 0.2, ..t(9) });
        let back: Replay = serde_json::from_slice(&serde_json::to_vec(&r).unwrap()).unwrap();
        assert_eq!(back, r);
    }
}
