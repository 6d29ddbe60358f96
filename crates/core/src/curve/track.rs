//! Keyed and sampled curves: [`Track`] (keys with step / linear / Hermite interpolation, and the
//! Catmull-Rom spline through samples) and [`Samples`] (values at evenly spaced times).

use super::{Curve, Interval};
use crate::interp::{hermite, hermite_quat, hermite_vec3};
use crate::CoreError;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// Values at `start, start + 1/rate, …` (e.g. one per frame), linear in between; a sampled
/// track that the adapters here can bend.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples<T> {
    start: f64,
    rate: f64,
    values: Vec<T>,
}

impl<T: Animatable> Samples<T> {
    /// Fails on no values or a rate that is not finite and positive.
    pub fn new(start: f64, rate: f64, values: Vec<T>) -> Result<Self, CoreError> {
        if values.is_empty() || !(rate.is_finite() && rate > 0.0) || !start.is_finite() {
            return Err(CoreError::InvalidCurve(format!(
                "samples need values and a positive rate (got {} values at rate {rate})",
                values.len()
            )));
        }
        Ok(Samples { start, rate, values })
    }

    pub fn values(&self) -> &[T] {
        &self.values
    }
}

impl<T: Animatable> Curve<T> for Samples<T> {
    fn domain(&self) -> Interval {
        Interval::new(self.start, self.start + (self.values.len() - 1) as f64 / self.rate)
            .expect("a finite start and a positive rate give an ordered interval")
    }
    /// Linear between the two samples around `t`; outside the domain, the nearest end sample.
    fn sample_unchecked(&self, t: f64) -> T {
        let x = ((t - self.start) * self.rate).clamp(0.0, (self.values.len() - 1) as f64);
        let i = x.floor() as usize;
        let u = x - i as f64;
        if u == 0.0 || i + 1 >= self.values.len() {
            return self.values[i];
        }
        T::linear(self.values[i], self.values[i + 1], u)
    }
}

/// How a track fills the time between two keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    /// Hold the earlier key's value.
    Step,
    /// Straight line (slerp for rotations).
    Linear,
    /// Cubic Hermite through values with the keys' tangents (per second).
    Hermite,
}

/// Values a track can interpolate. The tangent of a rotation is its body-frame angular velocity.
pub trait Animatable: Copy + std::fmt::Debug + PartialEq {
    type Tangent: Copy + std::fmt::Debug + PartialEq;
    fn linear(a: Self, b: Self, u: f64) -> Self;
    fn hermite(a: Self, ta: Self::Tangent, b: Self, tb: Self::Tangent, h: f64, u: f64) -> Self;
    /// Tangent by finite difference of three neighbours at times `t0 < t1 < t2` (one-sided at ends).
    fn finite_tangent(prev: (f64, Self), next: (f64, Self)) -> Self::Tangent;
}

impl Animatable for f64 {
    type Tangent = f64;
    fn linear(a: f64, b: f64, u: f64) -> f64 {
        a + (b - a) * u
    }
    fn hermite(a: f64, ta: f64, b: f64, tb: f64, h: f64, u: f64) -> f64 {
        hermite(a, ta, b, tb, h, u)
    }
    fn finite_tangent(prev: (f64, f64), next: (f64, f64)) -> f64 {
        (next.1 - prev.1) / (next.0 - prev.0)
    }
}

impl Animatable for DVec3 {
    type Tangent = DVec3;
    fn linear(a: DVec3, b: DVec3, u: f64) -> DVec3 {
        a.lerp(b, u)
    }
    fn hermite(a: DVec3, ta: DVec3, b: DVec3, tb: DVec3, h: f64, u: f64) -> DVec3 {
        hermite_vec3(a, ta, b, tb, h, u)
    }
    fn finite_tangent(prev: (f64, DVec3), next: (f64, DVec3)) -> DVec3 {
        (next.1 - prev.1) / (next.0 - prev.0)
    }
}

impl Animatable for DQuat {
    type Tangent = DVec3;
    fn linear(a: DQuat, b: DQuat, u: f64) -> DQuat {
        a.slerp(b, u)
    }
    fn hermite(a: DQuat, ta: DVec3, b: DQuat, tb: DVec3, h: f64, u: f64) -> DQuat {
        hermite_quat(a, ta, b, tb, h, u)
    }
    fn finite_tangent(prev: (f64, DQuat), next: (f64, DQuat)) -> DVec3 {
        crate::interp::angular_velocity(prev.1, next.1, next.0 - prev.0)
    }
}

impl<const N: usize> Animatable for [f64; N] {
    type Tangent = [f64; N];
    fn linear(a: Self, b: Self, u: f64) -> Self {
        std::array::from_fn(|i| f64::linear(a[i], b[i], u))
    }
    fn hermite(a: Self, ta: Self, b: Self, tb: Self, h: f64, u: f64) -> Self {
        std::array::from_fn(|i| hermite(a[i], ta[i], b[i], tb[i], h, u))
    }
    fn finite_tangent(prev: (f64, Self), next: (f64, Self)) -> Self {
        std::array::from_fn(|i| (next.1[i] - prev.1[i]) / (next.0 - prev.0))
    }
}

/// One key: a time, a value and the tangent used by Hermite interpolation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key<T: Animatable> {
    pub time: f64,
    pub value: T,
    pub tangent: T::Tangent,
}

/// Keys at strictly increasing times, interpolated one way.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T: Animatable> {
    keys: Vec<Key<T>>,
    pub interpolation: Interpolation,
}

/// A scalar curve (blendshape weight, focal length, …).
pub type ScalarTrack = Track<f64>;

impl<T: Animatable> Track<T> {
    /// Fails on no keys or on times that are not finite and strictly increasing.
    pub fn new(keys: Vec<Key<T>>, interpolation: Interpolation) -> Result<Self, CoreError> {
        if keys.is_empty() {
            return Err(CoreError::InvalidCurve("a track needs at least one key".into()));
        }
        for (i, w) in keys.windows(2).enumerate() {
            if !(w[0].time.is_finite() && w[1].time.is_finite() && w[0].time < w[1].time) {
                return Err(CoreError::InvalidCurve(format!(
                    "key {} at t={} does not come after key {} at t={}",
                    i + 1,
                    w[1].time,
                    i,
                    w[0].time
                )));
            }
        }
        Ok(Track { keys, interpolation })
    }

    /// Keys at `times` with tangents from finite differences of the neighbours (Catmull-Rom style).
    pub fn from_samples(times: &[f64], values: &[T], interpolation: Interpolation) -> Result<Self, CoreError> {
        if times.len() != values.len() {
            return Err(CoreError::InvalidCurve(format!("{} times but {} values", times.len(), values.len())));
        }
        let n = times.len();
        let keys = (0..n)
            .map(|i| {
                let tangent = if n < 2 {
                    T::finite_tangent((0.0, values[i]), (1.0, values[i]))
                } else {
                    let (p, q) = (i.saturating_sub(1), (i + 1).min(n - 1));
                    T::finite_tangent((times[p], values[p]), (times[q], values[q]))
                };
                Key { time: times[i], value: values[i], tangent }
            })
            .collect();
        Track::new(keys, interpolation)
    }

    /// The Catmull-Rom spline through `values` at `times`: Hermite with tangents from the
    /// neighbouring samples ((x_{i+1} − x_{i−1}) / (t_{i+1} − t_{i−1}), one-sided at the ends).
    pub fn catmull_rom(times: &[f64], values: &[T]) -> Result<Self, CoreError> {
        Track::from_samples(times, values, Interpolation::Hermite)
    }

    pub fn keys(&self) -> &[Key<T>] {
        &self.keys
    }

    /// Index of the key segment containing `t` (clamped).
    fn segment(&self, t: f64) -> usize {
        let i = self.keys.partition_point(|k| k.time <= t);
        i.saturating_sub(1).min(self.keys.len().saturating_sub(2))
    }
}

impl<T: Animatable> Curve<T> for Track<T> {
    fn domain(&self) -> Interval {
        Interval::new(self.keys[0].time, self.keys[self.keys.len() - 1].time)
            .expect("a track's key times are finite and increasing")
    }

    /// Interpolated between the two keys around `t`; outside the domain, the nearest end key.
    fn sample_unchecked(&self, t: f64) -> T {
        let (start, end) = (self.keys[0].time, self.keys[self.keys.len() - 1].time);
        if self.keys.len() == 1 || t <= start {
            return self.keys[0].value;
        }
        if t >= end {
            return self.keys[self.keys.len() - 1].value;
        }
        let i = self.segment(t);
        let (a, b) = (&self.keys[i], &self.keys[i + 1]);
        let h = b.time - a.time;
        let u = (t - a.time) / h;
        match self.interpolation {
            Interpolation::Step => a.value,
            Interpolation::Linear => T::linear(a.value, b.value, u),
            Interpolation::Hermite => T::hermite(a.value, a.tangent, b.value, b.tangent, h, u),
        }
    }
}
