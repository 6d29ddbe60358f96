//! The domain of a curve: a closed interval of time (after `bevy_math::curve::Interval`).

use crate::CoreError;
use serde::{Deserialize, Serialize};

/// A closed interval `[start, end]` of time in seconds (or of any curve parameter), with
/// `start ≤ end`; either end may be infinite ([`Interval::EVERYWHERE`] is the whole line), neither
/// is NaN. A single point (`start == end`) is a valid interval of length 0.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    start: f64,
    end: f64,
}

impl Interval {
    /// The whole real line: the domain of a curve defined at every time (a looped clip).
    pub const EVERYWHERE: Interval = Interval { start: f64::NEG_INFINITY, end: f64::INFINITY };

    /// `[0, 1]`, the domain of a weight or a normalised parameter.
    pub const UNIT: Interval = Interval { start: 0.0, end: 1.0 };

    /// Fails when either end is NaN or `start > end`.
    pub fn new(start: f64, end: f64) -> Result<Interval, CoreError> {
        if start.is_nan() || end.is_nan() || start > end {
            return Err(CoreError::InvalidCurve(format!(
                "interval [{start}, {end}]: start must be a number no greater than end"
            )));
        }
        Ok(Interval { start, end })
    }

    pub fn start(&self) -> f64 {
        self.start
    }

    pub fn end(&self) -> f64 {
        self.end
    }

    /// `end − start` (infinite for an unbounded interval).
    pub fn length(&self) -> f64 {
        self.end - self.start
    }

    /// Both ends finite.
    pub fn is_bounded(&self) -> bool {
        self.start.is_finite() && self.end.is_finite()
    }

    /// `start ≤ t ≤ end` (false for NaN).
    pub fn contains(&self, t: f64) -> bool {
        self.start <= t && t <= self.end
    }

    /// Whether `other` lies inside this interval.
    pub fn contains_interval(&self, other: Interval) -> bool {
        self.start <= other.start && other.end <= self.end
    }

    /// The nearest time inside the interval (NaN stays NaN).
    pub fn clamp(&self, t: f64) -> f64 {
        t.clamp(self.start, self.end)
    }

    /// The times both intervals contain, if any.
    pub fn intersect(&self, other: Interval) -> Option<Interval> {
        let (start, end) = (self.start.max(other.start), self.end.min(other.end));
        (start <= end).then_some(Interval { start, end })
    }

    /// The smallest interval holding both.
    pub fn union(&self, other: Interval) -> Interval {
        Interval { start: self.start.min(other.start), end: self.end.max(other.end) }
    }

    /// Times `start + i / rate` for `i = 0, 1, …` up to `end`, e.g. one per frame at `rate` fps. A
    /// last time within `1e-9` frames of `end` counts as inside (so `[0, 1]` at 3 fps gives 4 times
    /// although `3 · (1/3)` may round above 1), and it is clamped onto `end`. Fails on an unbounded
    /// interval or a rate that is not finite and positive.
    pub fn uniform_times(&self, rate: f64) -> Result<impl ExactSizeIterator<Item = f64> + Clone, CoreError> {
        if !(self.is_bounded() && rate.is_finite() && rate > 0.0) {
            return Err(CoreError::InvalidCurve(format!(
                "uniform times need a bounded interval and a positive rate (got [{}, {}] at {rate} per second)",
                self.start, self.end
            )));
        }
        let n = (self.length() * rate + 1e-9).floor() as usize + 1;
        let (start, end) = (self.start, self.end);
        Ok((0..n).map(move |i| (start + i as f64 / rate).min(end)))
    }
}

impl std::fmt::Display for Interval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{} s, {} s]", self.start, self.end)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_reversed_or_nan_ends_and_accepts_points_and_infinities() {
        assert!(Interval::new(1.0, 0.0).is_err());
        assert!(Interval::new(f64::NAN, 0.0).is_err());
        assert!(Interval::new(0.0, f64::NAN).is_err());
        let p = Interval::new(2.0, 2.0).unwrap();
        assert_eq!(p.length(), 0.0);
        assert!(p.contains(2.0) && !p.contains(2.0 + 1e-12));
        let half = Interval::new(0.0, f64::INFINITY).unwrap();
        assert!(!half.is_bounded() && half.contains(1e300));
        assert!(Interval::EVERYWHERE.contains(-1e300));
    }

    #[test]
    fn contains_clamps_and_combines() {
        let i = Interval::new(-1.0, 3.0).unwrap();
        assert_eq!(i.length(), 4.0);
        assert!(i.contains(-1.0) && i.contains(3.0) && !i.contains(3.5) && !i.contains(f64::NAN));
        assert_eq!(i.clamp(9.0), 3.0);
        assert_eq!(i.clamp(-9.0), -1.0);
        assert_eq!(i.clamp(0.5), 0.5);
        let j = Interval::new(2.0, 5.0).unwrap();
        assert_eq!(i.intersect(j), Some(Interval::new(2.0, 3.0).unwrap()));
        assert_eq!(i.intersect(Interval::new(4.0, 5.0).unwrap()), None);
        assert_eq!(i.union(j), Interval::new(-1.0, 5.0).unwrap());
        assert!(i.contains_interval(Interval::new(0.0, 1.0).unwrap()) && !i.contains_interval(j));
        assert_eq!(i.to_string(), "[-1 s, 3 s]");
    }

    #[test]
    fn uniform_times_cover_the_interval_and_never_leave_it() {
        let i = Interval::new(0.0, 1.0).unwrap();
        let t: Vec<f64> = i.uniform_times(3.0).unwrap().collect();
        assert_eq!(t.len(), 4);
        assert_eq!(t[0], 0.0);
        assert_eq!(t[3], 1.0);
        assert!(t.iter().all(|&x| i.contains(x)));
        let t: Vec<f64> = Interval::new(10.0, 10.7).unwrap().uniform_times(2.0).unwrap().collect();
        assert_eq!(t, vec![10.0, 10.5]);
        assert!(Interval::EVERYWHERE.uniform_times(30.0).is_err());
        assert!(i.uniform_times(0.0).is_err());
        assert!(i.uniform_times(f64::NAN).is_err());
    }
}
