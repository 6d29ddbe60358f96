//! Blinks: a renewal process with a refractory period (no blink within [`REFRACTORY_S`] of the last),
//! exponential waiting times beyond it, occasional double blinks, a fast close and a slower reopening
//! (calibrated so the time above the measuring threshold matches the real captures' 106 ms), both eyes together with a small
//! amplitude and timing asymmetry.

use super::random::Rand;
use inbetween_core::interp::smoothstep;

/// Minimum time between two blink onsets, seconds.
pub const REFRACTORY_S: f64 = 0.4;
/// Probability that a blink is followed by a second one 0.25–0.45 s later.
const DOUBLE_BLINK: f64 = 0.08;
/// Probability of a partial blink (peak 0.3–0.6).
const PARTIAL_BLINK: f64 = 0.12;

/// One blink: onset time, closing and reopening durations, hold at the peak, peak amplitudes of the
/// left and right eyelids and the right eye's delay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blink {
    pub t0: f64,
    pub close_s: f64,
    pub hold_s: f64,
    pub open_s: f64,
    pub amp_left: f64,
    pub amp_right: f64,
    pub delay_right: f64,
}

impl Blink {
    /// End of the blink, seconds.
    pub fn end(&self) -> f64 {
        self.t0 + self.close_s + self.hold_s + self.open_s + self.delay_right.max(0.0)
    }

    /// Eyelid closure of one eye at time `t` (0 open, `amp` at the peak).
    fn closure(&self, t: f64, amp: f64) -> f64 {
        let x = t - self.t0;
        if x <= 0.0 {
            0.0
        } else if x < self.close_s {
            amp * smoothstep(x / self.close_s)
        } else if x < self.close_s + self.hold_s {
            amp
        } else {
            let y = (x - self.close_s - self.hold_s) / self.open_s;
            if y >= 1.0 {
                0.0
            } else {
                amp * (1.0 - smoothstep(y))
            }
        }
    }

    /// Left and right eyelid closure at time `t`.
    pub fn at(&self, t: f64) -> (f64, f64) {
        (self.closure(t, self.amp_left), self.closure(t - self.delay_right, self.amp_right))
    }
}

/// Blinks over `[0, duration)` at about `rate_per_min` onsets per minute (the mean waiting time beyond
/// the refractory period is chosen so the mean interval is 60 / rate).
pub fn schedule(rng: &mut Rand, duration: f64, rate_per_min: f64) -> Vec<Blink> {
    let mut out = Vec::new();
    if rate_per_min <= 0.0 || !rate_per_min.is_finite() {
        return out;
    }
    let mean_interval = 60.0 / rate_per_min;
    let beyond = (mean_interval - REFRACTORY_S).max(0.05);
    let mut t = rng.range(0.0, mean_interval);
    while t < duration {
        let b = one(rng, t);
        out.push(b);
        if rng.chance(DOUBLE_BLINK) {
            let t2 = b.end() + rng.range(0.03, 0.15);
            if t2 < duration {
                out.push(one(rng, t2));
                t = t2;
            }
        }
        t += REFRACTORY_S + rng.exp(beyond);
    }
    out
}

/// One blink starting at `t0`.
fn one(rng: &mut Rand, t0: f64) -> Blink {
    let amp = if rng.chance(PARTIAL_BLINK) { rng.range(0.3, 0.6) } else { rng.range(0.65, 1.0) };
    let asym = 0.05 * rng.normal();
    Blink {
        t0,
        close_s: rng.range(0.04, 0.07),
        hold_s: rng.range(0.0, 0.02),
        open_s: rng.range(0.09, 0.15),
        amp_left: (amp * (1.0 + asym)).min(1.0),
        amp_right: (amp * (1.0 - asym)).min(1.0),
        delay_right: rng.range(-0.006, 0.006),
    }
}

/// Left and right eyelid closure at each of `times` (maximum over overlapping blinks).
pub fn render(blinks: &[Blink], times: &[f64]) -> Vec<(f32, f32)> {
    let mut out = vec![(0.0f32, 0.0f32); times.len()];
    let mut first = 0usize;
    for (o, &t) in out.iter_mut().zip(times) {
        while first < blinks.len() && blinks[first].end() < t {
            first += 1;
        }
        for b in &blinks[first..] {
            if b.t0 - 0.01 > t {
                break;
            }
            let (l, r) = b.at(t);
            o.0 = o.0.max(l as f32);
            o.1 = o.1.max(r as f32);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_and_shape_are_as_asked() {
        let mut rng = Rand::new(11, 0);
        let b = schedule(&mut rng, 600.0, 20.0);
        let rate = b.len() as f64 / 10.0;
        assert!((rate - 20.0).abs() < 4.0, "{rate} blinks per minute");
        for w in b.windows(2) {
            // Double blinks follow the end of the first; other blinks respect the refractory period.
            assert!(w[1].t0 > w[0].end(), "blink at {} starts before the one at {} ends", w[1].t0, w[0].t0);
        }
        let doubles = b.windows(2).filter(|w| w[1].t0 - w[0].t0 < REFRACTORY_S).count();
        assert!(doubles > 0 && doubles < b.len() / 5, "{doubles} double blinks of {}", b.len());
        let one = b[0];
        let peak = one.t0 + one.close_s + 0.5 * one.hold_s;
        assert!((one.at(peak).0 - one.amp_left).abs() < 1e-9);
        assert_eq!(one.at(one.t0 - 0.1), (0.0, 0.0));
        assert!(one.at(one.end() + 0.01).0 == 0.0);
    }
}
